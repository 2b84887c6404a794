#!/usr/bin/python3
"""Tests of the cross-technique study analysis (gilab_report/study.py), its HTML and
Markdown renderings (gilab_report/study_html.py) and scripts/findings.py, on synthetic rows with known
answers. No Chromium, no GPU: a few seconds.

    PYTHONPATH=scripts /usr/bin/python3 tests/report/test_study.py (ctest: CpuReportStudy.AnalysisAndFindings)
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import unittest

REPO = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))

import matplotlib  # noqa: E402

matplotlib.use("agg")
from gilab_report import study as S  # noqa: E402
from gilab_report import study_html as H  # noqa: E402
from gilab_report import readme as R  # noqa: E402
from gilab_report import changes as CH  # noqa: E402

DEVICE = "llvmpipe (LLVM 15.0.6, 256 bits)"


def row(scene: str, tech: str, x, y, sigma=None, iqr=None, status="ok", swept="", key=None,
        **params) -> dict:
    r = {"key": key or f"{scene}-{tech}-{x}-{y}-{sorted(params.items())}", "scene": scene,
         "technique": tech, "status": status, "swept": swept,
         "frame_gpu_ms_median": x, "frame_gpu_ms_iqr": iqr, "full.flip": y,
         "full.flip_noise": sigma, "indirect.rel_mse": None if y is None else y / 10,
         "device": DEVICE, "device_type": "cpu", "host": "vm", "cpu": "AMD EPYC",
         "bounces": 0 if tech == "direct" else 1}
    for k, v in params.items():
        r[f"param.{k}"] = v
    return r


def cells(col: S.Column) -> dict[str, tuple]:
    return {s: (c.point.y if c.point else None, c.best, c.tie) for s, c in col.cells.items()}


class Pareto(unittest.TestCase):
    def test_front_membership(self):
        rows = [row("a", "direct", 10, 0.9), row("a", "vct", 20, 0.5, voxel_resolution=64),
                row("a", "vct", 40, 0.55, voxel_resolution=128),  # slower and worse than 20/0.5
                row("a", "ssvp", 30, 0.3), row("a", "ssvp", 30, 0.35, clusters=4),  # same time
                row("a", "dvs", 5, None)]  # no error: never ranked
        st = S.analyse(rows).scenes["a"]
        self.assertEqual([(p.x, p.y) for p in st.front], [(10, 0.9), (20, 0.5), (30, 0.3)])
        self.assertNotIn(0.55, [p.y for p in st.front])


class EqualTime(unittest.TestCase):
    def setUp(self):
        # best 0.40 ± 0.03; 0.44 ± 0.03 is within sqrt(2) * 0.03 = 0.0424 (tie); 0.45 ± 0.03
        # is 0.05 away (no tie); the cheap run of vct only counts at the small budget.
        self.rows = [row("s", "ssvp", 30, 0.40, sigma=0.03), row("s", "dvs", 40, 0.44, sigma=0.03),
                     row("s", "topovpl", 45, 0.45, sigma=0.03),
                     row("s", "vct", 15, 0.60, voxel_resolution=64, swept="voxel_resolution"),
                     row("s", "vct", 150, 0.20, voxel_resolution=256, swept="voxel_resolution"),
                     row("s", "direct", 5, 1.0)]
        self.study = S.analyse(self.rows, budgets=(20, 50, 200))

    def test_budgets(self):
        t20, t50, t200 = self.study.scenes["s"].equal_time
        self.assertEqual(t20.winners, ["vct"])  # only vct (15 ms) and direct (5 ms) fit
        self.assertEqual(cells(t20)["direct"], (1.0, False, False))
        self.assertEqual(t50.winners, ["ssvp", "dvs"])  # dvs tied inside the error bars
        self.assertEqual(cells(t50)["ssvp"], (0.40, True, False))
        self.assertEqual(cells(t50)["dvs"], (0.44, False, True))
        self.assertEqual(cells(t50)["topovpl"], (0.45, False, False))  # just outside: no tie
        self.assertEqual(cells(t50)["vct"], (0.60, False, False))  # its 150 ms rung is over
        self.assertEqual(t200.winners, ["vct"])
        self.assertEqual(t200.cells["vct"].point.x, 150)

    def test_no_error_bar_means_exact_ties_only(self):
        rows = [row("s", "a", 10, 0.40), row("s", "b", 10, 0.40), row("s", "c", 10, 0.4001)]
        col = S.analyse(rows, budgets=(50,)).scenes["s"].equal_time[0]
        self.assertEqual(col.winners, ["a", "b"])

    def test_rendered_ties(self):
        md = H.md_table(self.study.scenes["s"].equal_time, self.study.series,
                        lambda p: f"{p.y:.2f}")
        self.assertIn("| dvs | — | 0.44 (tie) |", md)
        self.assertIn("**0.40**", md)
        self.assertIn("| topovpl | — | 0.45 | 0.45 |", md)


class EqualError(unittest.TestCase):
    def test_least_time_and_ties(self):
        rows = [row("s", "direct", 5, 1.0),
                row("s", "a", 100, 0.45, iqr=10), row("s", "a", 300, 0.2, iqr=10, n=2),
                # No repeats: each run's IQR half-width is its time spread (verdicts.time_tie):
                # |105 - 100| = 5 <= hypot(5, 3) = 5.8: tie; |120 - 100| = 20 > hypot(5, 2)
                row("s", "b", 105, 0.48, iqr=6),
                row("s", "c", 120, 0.30, iqr=4), row("s", "c", 90, 0.7, iqr=1, n=1),
                row("s", "d", 60, 0.9)]  # never reaches 0.5
        st = S.analyse(rows, fractions=(0.5, 0.25)).scenes["s"]
        half, quarter = st.equal_error
        self.assertAlmostEqual(half.limit, 0.5)
        self.assertEqual(half.winners, ["a", "b"])
        self.assertEqual(half.cells["a"].point.x, 100)
        self.assertEqual(half.cells["c"].point.x, 120)
        self.assertFalse(half.cells["c"].tie)
        self.assertIsNone(half.cells["d"].point)
        self.assertEqual(quarter.winners, ["a"])
        self.assertEqual(quarter.cells["a"].point.x, 300)
        self.assertEqual(st.direct_floor.y, 1.0)

    def test_no_floor_no_targets(self):
        st = S.analyse([row("s", "a", 1, 0.5), row("s", "b", 2, 0.4)]).scenes["s"]
        self.assertEqual(st.equal_error, [])


class Series(unittest.TestCase):
    def test_cvgi_gather_splits(self):
        rows = [row("s", "cvgi", 30, 0.7, swept="voxel_resolution rays_per_face", gather="paper",
                    voxel_resolution=64, rays_per_face=32),
                row("s", "cvgi", 50, 0.6, swept="voxel_resolution rays_per_face", gather="paper",
                    voxel_resolution=128, rays_per_face=128),
                row("s", "cvgi", 33, 0.5, swept="voxel_resolution", gather="ray_weighted",
                    voxel_resolution=64, rays_per_face=128),
                row("s", "vct", 100, 0.55, swept="voxel_resolution", voxel_resolution=64,
                    storage="dense"),
                row("s", "vct", 200, 0.52, swept="voxel_resolution", voxel_resolution=128,
                    storage="dense"),
                row("t", "cvgi", 40, 0.8, gather="paper", voxel_resolution=64)]  # one rung
        study = S.analyse(rows, budgets=(35, 1000))
        self.assertEqual(set(study.scenes["s"].series),
                         {"cvgi (gather=paper)", "cvgi (gather=ray_weighted)", "vct"})
        self.assertEqual(list(study.scenes["t"].series), ["cvgi (gather=paper)"])
        paper = study.scenes["s"].series["cvgi (gather=paper)"]
        self.assertEqual([p.paper for p in paper], [False, True])  # 128^3, 128 rays is the paper's
        # Our gather wins at 35 ms, but at a rung (64^3, 128 rays) the paper gather never ran:
        # no our-choice claim (issue 44: compare only at matched rungs).
        words = S.findings(study)
        self.assertFalse(any("cvgi (gather=ray_weighted) wins" in w for w in words), words)
        # Once the paper gather runs that rung too, the claim is made at it.
        rows.append(row("s", "cvgi", 34, 0.65, swept="voxel_resolution rays_per_face",
                        gather="paper", voxel_resolution=64, rays_per_face=128))
        words = S.findings(S.analyse(rows, budgets=(35, 1000)))
        self.assertTrue(any("s, ≤ 35 ms: cvgi (gather=ray_weighted) wins at the rungs both "
                            "variants ran; with only cvgi (gather=paper) allowed the winner "
                            "would be cvgi (gather=paper) (the same technique still wins)" in w
                            for w in words), words)
        self.assertTrue(any("paper rung 0.6 at 50 ms" in w or "paper rung 0.600 at 50.0 ms" in w
                            for w in words) or any("the paper rung is its best" in w
                                                   for w in words), words)

    def test_our_choice_changes_the_ranking(self):
        rows = [row("s", "cvgi", 33, 0.5, gather="ray_weighted"),
                row("s", "cvgi", 30, 0.9, gather="paper"), row("s", "vct", 40, 0.6)]
        words = S.findings(S.analyse(rows, budgets=(50,)))
        self.assertTrue(any("winner would be vct (another technique: our choice changes the "
                            "ranking)" in w for w in words), words)

    def test_our_choices_pair_by_parameter_values(self):
        # vct's lift as the rows spell it ('1.5' / '0.0'); topovpl's three settings at once;
        # ssvp ran only ours, so it has no pair.
        series = ["vct (lift=0.0)", "vct (lift=1.5)", "ssvp",
                  "topovpl (cluster_merge=none, gate_placement=midpoint, gate_radius=min)",
                  "topovpl (cluster_merge=visible, gate_placement=bottleneck, gate_radius=neck)"]
        self.assertEqual(sorted(S.our_choice_pairs(series)), [
            ("topovpl (cluster_merge=visible, gate_placement=bottleneck, gate_radius=neck)",
             "topovpl (cluster_merge=none, gate_placement=midpoint, gate_radius=min)"),
            ("vct (lift=1.5)", "vct (lift=0.0)")])
        rows = [row("s", "vct", 40, 0.5, lift=1.5), row("s", "vct", 40, 0.7, lift=0.0),
                row("s", "dvs", 45, 0.6)]
        words = S.findings(S.analyse(rows, budgets=(50,)))
        self.assertTrue(any("s, ≤ 50 ms: vct (lift=1.5) wins at the rungs both variants ran; "
                            "with only vct (lift=0) allowed "
                            "the winner would be dvs" in w for w in words), words)


class Breaks(unittest.TestCase):
    def test_leak_on_rooms_closed(self):
        rows = [row("rooms_open", "vct", 50, 0.8, energy_ratio=None),
                row("rooms_closed", "vct", 50, 0.02),  # HDR-FLIP vs the black reference
                row("rooms_open", "topovpl", 60, 0.7), row("rooms_closed", "topovpl", 60, 0.0),
                row("rooms_open", "dvs", 70, 0.7), row("rooms_closed", "dvs", 70, 0.001),
                row("rooms_open", "ssvp", 80, 0.6), row("rooms_closed", "ssvp", 80, 0.001),
                row("cornell", "ssvp", 80, 0.6)]
        rows[0]["energy_ratio"] = 1.0
        for r in rows:
            if r["scene"] == "rooms_open":
                r["energy_ratio"] = 1.0
        rows[5]["leak.share"] = 0.05  # dvs: 5 % of the open room's indirect light seen
        rows[7]["energy_ratio"] = 2.5  # ssvp: closed/open 2.5 > 2
        rows[8]["energy_ratio"] = 3.0  # ssvp outside [0.5, 2] elsewhere too
        b = {x.series: x for x in S.analyse(rows).breaks}
        self.assertTrue(b["vct"].leak)  # FLIP 0.02 > 0.01
        self.assertFalse(b["topovpl"].leak)
        self.assertTrue(b["dvs"].leak)
        self.assertTrue(b["ssvp"].leak)
        self.assertIn("energy closed/open ≤ 2.50", b["ssvp"].leak_words)
        self.assertEqual((b["ssvp"].energy_min, b["ssvp"].energy_max), (1.0, 3.0))
        self.assertTrue(b["ssvp"].energy_flag)
        self.assertFalse(b["topovpl"].energy_flag)
        self.assertIn("leak (rooms_closed)", b["vct"].flags())

    def test_temporal_flag_is_relative_to_the_steadiest_gi_technique(self):
        # Matched instabilities 0.10 (vct), 0.14 (dvs: 1.4x, not flagged), 0.16 (ssvp: 1.6x,
        # flagged); direct's 0.30 is never flagged (it has no indirect light to flicker).
        rows = [row("orbit", "direct", 10, 0.8), row("orbit", "vct", 50, 0.6),
                row("orbit", "dvs", 60, 0.6), row("orbit", "ssvp", 70, 0.5)]
        for r, v in zip(rows, (0.30, 0.10, 0.14, 0.16)):
            r["sequence.temporal_matched.instability"] = v
            r["sequence.temporal_matched.noise_floor"] = 0.05
        rows[1]["energy_ratio"], rows[2]["energy_ratio"] = 0.4, 1.0
        b = {x.series: x for x in S.analyse(rows).breaks}
        self.assertEqual([s for s in b if b[s].temporal_flag], ["ssvp"])
        self.assertEqual(b["ssvp"].temporal, [("orbit", 0.16, 0.05)])
        self.assertEqual((b["vct"].energy_min, b["vct"].energy_min_scene), (0.4, "orbit"))
        self.assertTrue(b["vct"].energy_flag)
        self.assertIn("0.400 (orbit) – 0.400 (orbit)", H.md_breaks(S.analyse(rows)))

    def test_cold_set_up_apart_from_a_cached_topology(self):
        # topology_cache = off does not split the series; a cached set-up is shown apart.
        rows = [row("s", "topovpl", 100, 0.5, swept="vpls", vpls=512),
                row("s", "topovpl", 110, 0.5, vpls=1024, topology_cache="off"),
                row("s", "topovpl", 100, 0.45, swept="vpls", vpls=1024)]
        rows[0]["setup_ms"], rows[0]["topology_cache_hit"] = 900.0, 1.0
        rows[1]["setup_ms"], rows[1]["topology_cache_hit"] = 20000.0, 0.0
        rows[2]["setup_ms"], rows[2]["topology_cache_hit"] = 1000.0, 1.0
        study = S.analyse(rows)
        self.assertEqual(study.series, ["topovpl"])
        b = study.breaks[0]
        self.assertEqual((b.setup_min, b.setup_max), (20000.0, 20000.0))
        self.assertEqual((b.cached_setup_min, b.cached_setup_max), (900.0, 1000.0))
        self.assertIn("20000 – 20000 (cached: 900 – 1000)", H.md_breaks(study))

    def test_failures_and_partial_rows(self):
        rows = [row("s", "vct", 10, 0.5), row("s", "dvs", None, None, status="unsupported"),
                row("s", "dvs", 20, 0.4, status="nonfinite"), {"scene": "s"}, {}]
        rows[1]["reason"] = "too large"
        study = S.analyse(rows)
        b = {x.series: x for x in study.breaks}
        self.assertEqual(b["dvs"].unsupported, ["s: too large"])
        self.assertEqual(b["dvs"].nonfinite, ["s"])
        self.assertEqual(study.scenes["s"].equal_time[0].winners, ["vct"])  # nonfinite unranked

    def test_audit_cells(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "audit.json")
            with open(path, "w") as f:
                json.dump({"cells": [
                    {"case": "thin_wall_window", "technique": "vct", "grade": "amber",
                     "energy_ratio": 7.5, "leak": None},
                    {"case": "thin_wall_dark_room", "technique": "vct", "grade": "red",
                     "leak": 0.2},
                    {"case": "box_1m", "technique": "vct", "grade": "green"}]}, f)
            audit = S.load_audit(path)
        self.assertEqual(audit["vct"], ["thin_wall_window: amber (energy ratio 7.50)",
                                        "thin_wall_dark_room: red (leak 0.200)"])
        self.assertEqual(S.load_audit("/nonexistent/audit.json"), {})


class Html(unittest.TestCase):
    def test_section(self):
        rows = [row("s", "direct", 5, 1.0), row("s", "ssvp", 30, 0.40, sigma=0.03),
                row("s", "dvs", 40, 0.44, sigma=0.03)]
        self.assertTrue(S.is_study(rows))
        self.assertFalse(S.is_study(rows[:1]))
        study = S.analyse(rows)
        out = H.study_section_html(study, H.series_colors(study.series), {}, str,
                                   "lavapipe (CPU)")
        self.assertIn('id="study"', out)
        self.assertIn("(tie)", out)
        self.assertIn(f"timed on {DEVICE} (lavapipe, CPU); machine vm (AMD EPYC)", out)
        self.assertIn("set-up, lavapipe (CPU), ms", out)


def result_json(key: str, scene: str, tech: str, x, y, status="ok", params=None, swept=(),
                setup=100.0) -> dict:
    return {"schema": 1, "status": status, "key": key, "index": 0, "experiment": "t",
            "scene": {"label": scene}, "reason": "no area lights" if status == "unsupported"
            else None,
            "technique": {"id": tech, "indirect_bounces": 0 if tech == "direct" else 1,
                          "params": params or {}, "swept": {k: (params or {}).get(k)
                                                            for k in swept}},
            "provenance": {"git_commit": "abc1234", "date": "2026-01-01T00:00:00Z",
                           "host": "node1", "cpu": "Test CPU", "hardware_threads": 2},
            "device": {"name": DEVICE, "type": "cpu"}, "host": "node1",
            "reference": {"samples": 64},
            "timing": {"setup_ms": {"total": setup},
                       "frame_gpu_ms": {"median": x, "q1": x and x * 0.98,
                                        "q3": x and x * 1.02, "iqr": x and x * 0.04}}
            if x is not None else {},
            "metrics": {"final_vs_full": {"flip": {"mean": y}, "rel_mse": y,
                                          "error_bars": {"rel_mse_noise_floor": 1e-4}},
                        "indirect": {"rel_mse": y / 10}, "energy_ratio": 0.9,
                        "direct": {"flip": {"mean": 0.01}, "energy_ratio": 0.99,
                                   "shadow_leak": 0.001}} if y is not None else {}}


def write_runs(results: str, runs: list[dict]) -> None:
    """Each result.json under <results>/runs/<key>/."""
    for r in runs:
        os.makedirs(os.path.join(results, "runs", r["key"]))
        with open(os.path.join(results, "runs", r["key"], "result.json"), "w") as f:
            json.dump(r, f)


class Findings(unittest.TestCase):
    def test_an_unreadable_run_is_named_not_silently_dropped(self):
        with tempfile.TemporaryDirectory() as tmp:
            run = os.path.join(tmp, "results", "study", "runs", "abc")
            os.makedirs(run)
            with open(os.path.join(run, "result.json"), "w") as f:
                f.write('{"status": "ok", "scene": 3')  # truncated
            out = os.path.join(tmp, "f.md")
            p = subprocess.run([sys.executable, os.path.join(REPO, "scripts", "findings.py"), "--allow-dirty",
                                os.path.join(tmp, "results", "study"), "--out", out],
                               capture_output=True, text=True, timeout=120)
            self.assertEqual(p.returncode, 0, p.stderr)
            self.assertIn("left out an unreadable run", p.stderr)
            self.assertIn("abc/result.json", p.stderr)
            with open(out, encoding="utf-8") as f:
                md = f.read()
            self.assertIn("runs: 0 finished — none; 1 unreadable run folder(s) left out:", md)

    def test_writes_markdown_and_pngs(self):
        with tempfile.TemporaryDirectory() as tmp:
            results = os.path.join(tmp, "results", "study")
            runs = [result_json("k1", "box", "direct", 10.0, 0.8),
                    result_json("k2", "box", "vct", 50.0, 0.5, params={"voxel_resolution": 64},
                                swept=("voxel_resolution",)),
                    result_json("k3", "box", "vct", 150.0, 0.4, params={"voxel_resolution": 128},
                                swept=("voxel_resolution",)),
                    result_json("k4", "box", "ssvp", 80.0, 0.45),
                    result_json("k5", "box", "topovpl", None, None, status="unsupported")]
            for r in runs:
                os.makedirs(os.path.join(results, "runs", r["key"]))
                with open(os.path.join(results, "runs", r["key"], "result.json"), "w") as f:
                    json.dump(r, f)
            os.makedirs(os.path.join(results, "runs", ".k6"))  # in progress: ignored
            with open(os.path.join(results, "experiment.json"), "w") as f:
                json.dump({"name": "t", "runs_total": 7}, f)
            out = os.path.join(tmp, "docs", "findings.md")
            proc = subprocess.run([sys.executable, os.path.join(REPO, "scripts", "findings.py"), "--allow-dirty",
                                   results, "--out", out, "--budgets", "60,200"],
                                  capture_output=True, text=True, timeout=120)
            self.assertEqual(proc.returncode, 0, proc.stderr)
            with open(out, encoding="utf-8") as f:
                md = f.read()
            head = subprocess.run(["git", "-C", REPO, "rev-parse", "HEAD"], capture_output=True,
                                  text=True).stdout.strip()
            self.assertRegex(md, rf"- commit `{head}(-dirty)?`")
            self.assertIn("5 finished of 7 planned (2 not finished)", md)
            self.assertIn(f"device: {DEVICE} (lavapipe, CPU); machine: node1 (Test CPU, 2 "
                          "threads)", md)
            self.assertIn("/usr/bin/python3 scripts/findings.py", md)
            self.assertIn("box, frame time ≤ 60 ms: best HDR-FLIP vct (0.500 at 50.0 ms).", md)
            self.assertIn("box, frame time ≤ 200 ms: best HDR-FLIP vct (0.400 at 150 ms).", md)
            self.assertIn("unsupported: box: no area lights", md)
            self.assertIn("Not ranked: topovpl (unsupported).", md)
            self.assertIn("| box | 64 | 1.00e-04 | not recorded | not recorded | 0.800 (10.0 ms) | 0.0100 |", md)
            png = os.path.join(tmp, "docs", "findings", "box.png")
            self.assertTrue(os.path.isfile(png))
            self.assertLess(os.path.getsize(png), 60 * 1024)
            with open(png, "rb") as f:
                header = f.read(24)
            self.assertEqual(header[:8], b"\x89PNG\r\n\x1a\n")
            self.assertEqual(int.from_bytes(header[16:20], "big"), 600)
            self.assertEqual(int.from_bytes(header[20:24], "big"), 400)
            with open(os.path.join(tmp, "docs", "findings_glance.md"), encoding="utf-8") as f:
                glance = f.read()
            # topovpl has no ranked run: no common scene, so no medians (issue 44: a median
            # over other scenes than another technique's is not comparable).
            self.assertIn("(0 common scenes)", glance)
            self.assertIn("| vct | — | — | box: ≤60/≤200 | — |", glance)
            self.assertIn("| topovpl | — | — | — | unsupported |", glance)

    def test_readme_section_is_written_between_its_markers_only(self):
        # issue 47: the README's glance and headlines come from the run, nothing by hand.
        with tempfile.TemporaryDirectory() as tmp:
            results = os.path.join(tmp, "results", "study")
            runs = [result_json("k1", "box", "direct", 10.0, 0.8),
                    result_json("k2", "box", "vct", 50.0, 0.5),
                    result_json("k3", "box", "ssvp", 150.0, 0.4)]
            write_runs(results, runs)
            readme = os.path.join(tmp, "README.md")
            before = "# Tool\n\n## Findings at a glance\n\n"
            after = "\n## Next\n\nkept as written\n"
            with open(readme, "w", encoding="utf-8") as f:
                f.write(before + R.BEGIN + "\nold hand-written text\n" + R.END + after)
            out = os.path.join(tmp, "docs", "findings.md")
            args = [sys.executable, os.path.join(REPO, "scripts", "findings.py"), "--allow-dirty",
                    results, "--out", out, "--budgets", "60,200", "--readme", readme]
            proc = subprocess.run(args, capture_output=True, text=True, timeout=120)
            self.assertEqual(proc.returncode, 0, proc.stderr)
            with open(readme, encoding="utf-8") as f:
                text = f.read()
            self.assertTrue(text.startswith(before + R.BEGIN + "\n"), text[:200])
            self.assertTrue(text.endswith(R.END + after), text[-200:])
            self.assertNotIn("old hand-written text", text)
            self.assertIn("| vct | 0.500 | 0.625 | box: ≤60 | — |", text)
            self.assertIn("- **Within 60 ms a frame** the lowest error is vct 1 of 1 quality "
                          "scenes.", text)
            self.assertIn("- **Within 200 ms a frame** the lowest error is ssvp 1 of 1 quality "
                          "scenes.", text)
            self.assertIn("3 runs of `", text)
            self.assertIn("[findings.md](docs/findings.md)", text)
            with open(out, encoding="utf-8") as f:
                self.assertIn("## Headlines", f.read())
            # Run twice: the same section, not a second one.
            proc = subprocess.run(args, capture_output=True, text=True, timeout=120)
            with open(readme, encoding="utf-8") as f:
                self.assertEqual(f.read().count(R.BEGIN), 1)
            # No markers: nothing written, the file named, exit 2.
            with open(readme, "w", encoding="utf-8") as f:
                f.write("# Tool\n")
            proc = subprocess.run(args, capture_output=True, text=True, timeout=120)
            self.assertEqual(proc.returncode, 2)
            self.assertIn(f"{readme}: needs exactly one", proc.stderr)
            with open(readme, encoding="utf-8") as f:
                self.assertEqual(f.read(), "# Tool\n")

    def test_changes_read_the_current_page_format(self):
        # Marks in cells and in the winners' row (the page findings.py writes now) are not
        # part of a series name; the matched-basis row is another basis, not a series.
        old = CH.parse("\n".join([
            "## box", "Equal time: best HDR-FLIP vs full reference.", "",
            "| series | ≤ 50 ms | ≤ 200 ms |", "|---|---|---|",
            "| cvgi (gather=paper) | **0.677 (33.4 ms)** | 0.677 (33.4 ms) |",
            "| cvgi (gather=ray_weighted) | 0.495 (37.3 ms) (compensating) | 0.495 (37.3 ms) |",
            "| vct (lift=0) | — | 0.500 (90.0 ms) (tie) |",
            "| best (and ties) | cvgi (gather=paper) (borderline); compensating: cvgi "
            "(gather=ray_weighted) | cvgi (gather=ray_weighted), vct (lift=0) |",
            "| best on the matched basis | cvgi (gather=ray_weighted) (differs) | vct (lift=0) |"]))
        box = old.scenes["box"]
        self.assertEqual(box.budgets, [50.0, 200.0])
        self.assertEqual(box.winners, [["cvgi (gather=paper)"],
                                       ["cvgi (gather=ray_weighted)", "vct (lift=0)"]])
        self.assertEqual(box.cells["cvgi (gather=ray_weighted)"], [(0.495, 37.3), (0.495, 37.3)])
        self.assertEqual(box.cells["vct (lift=0)"], [None, (0.5, 90.0)])
        self.assertNotIn("best on the matched basis", box.cells)

    def test_changes_list_every_changed_winner_with_measured_notes(self):
        # issue 47: the previous page's headlines beside the new ones, with what the runs say.
        previous = "\n".join([
            "- commit `abc` (the runs: abc)", "## box", "",
            "Equal time: best HDR-FLIP vs full reference (frame time) within each budget.", "",
            "| series | ≤ 60 ms | ≤ 200 ms |", "|---|---|---|",
            "| direct | 0.800 (10.0 ms) | 0.800 (10.0 ms) |",
            "| vct | **0.500 (40.0 ms)** | 0.500 (40.0 ms) |",
            "| best (and ties) | vct | vct |", "",
            "## Findings", "",
            "- vct on rooms_closed: leaks (HDR-FLIP vs black ≤ 0.0100, seen 4.00 % of the open "
            "room's indirect)."])
        with tempfile.TemporaryDirectory() as tmp:
            results = os.path.join(tmp, "results", "study")
            runs = [result_json("k1", "box", "direct", 12.0, 0.8),
                    result_json("k2", "box", "vct", 80.0, 0.5),
                    result_json("k3", "box", "ssvp", 150.0, 0.4)]
            write_runs(results, runs)
            old = os.path.join(tmp, "old.md")
            with open(old, "w", encoding="utf-8") as f:
                f.write(previous)
            out = os.path.join(tmp, "docs", "findings.md")
            proc = subprocess.run([sys.executable, os.path.join(REPO, "scripts", "findings.py"),
                                   "--allow-dirty", results, "--out", out, "--budgets", "60,200",
                                   "--previous", old], capture_output=True, text=True,
                                  timeout=120)
            self.assertEqual(proc.returncode, 0, proc.stderr)
            with open(os.path.join(tmp, "docs", "findings_changes.md"), encoding="utf-8") as f:
                md = f.read()
            # <= 60 ms: vct (40 ms then) has no run within it now (80 ms): direct wins.
            self.assertIn("| box | ≤ 60 ms | vct 0.500 (40.0 ms) | direct 0.800 (12.0 ms) | cost: "
                          "vct had 0.500 (40.0 ms) within 60 ms; now no run within it (its "
                          "fastest: 80.0 ms); direct 0.800 (10.0 ms) → 0.800 (12.0 ms) (error "
                          "within the noise); frame times then → now: `direct` 10.0 ms → 12.0 ms "
                          "(×1.20) |", md)
            # <= 200 ms: ssvp, a series the previous study did not have, wins.
            self.assertIn("| box | ≤ 200 ms | vct 0.500 (40.0 ms) | ssvp 0.400 (150 ms) |", md)
            self.assertIn("new series: ssvp was not in the previous study", md)
            self.assertIn("| vct | leaks (HDR-FLIP vs black ≤ 0.0100, seen 4.00 % of the open "
                          "room's indirect) | **not measured** |", md)
            self.assertIn("Previous: commit `abc` (the runs: abc).", md)
            bad = subprocess.run([sys.executable, os.path.join(REPO, "scripts", "findings.py"),
                                  "--allow-dirty", results, "--out", out, "--previous",
                                  os.path.join(tmp, "missing.md")], capture_output=True,
                                 text=True, timeout=120)
            self.assertEqual(bad.returncode, 2)
            self.assertIn("missing.md: no such file", bad.stderr)

    def test_empty_folder(self):
        with tempfile.TemporaryDirectory() as tmp:
            os.makedirs(os.path.join(tmp, "r", "runs"))
            out = os.path.join(tmp, "f.md")
            proc = subprocess.run([sys.executable, os.path.join(REPO, "scripts", "findings.py"), "--allow-dirty",
                                   os.path.join(tmp, "r"), "--out", out],
                                  capture_output=True, text=True, timeout=60)
            self.assertEqual(proc.returncode, 0, proc.stderr)
            with open(out, encoding="utf-8") as f:
                self.assertIn("No finished runs yet.", f.read())
            proc = subprocess.run([sys.executable, os.path.join(REPO, "scripts", "findings.py"), "--allow-dirty",
                                   os.path.join(tmp, "missing")], capture_output=True, text=True)
            self.assertEqual(proc.returncode, 2)


class Formatting(unittest.TestCase):
    def test_sig3(self):
        self.assertEqual([S.sig3(v) for v in (0.12345, 1234.6, 0.0001234, 0, None, 45.0,
                                               0.99983)],
                         ["0.123", "1230", "1.23e-04", "0", "—", "45.0", "1.00"])


class SweepLines(unittest.TestCase):
    """A sweep's lines never join runs that differ in an unswept parameter (the study's vct
    blocks at two `lift` values drew "from diffuse_cones=3 to 3"); seeds stay one line."""

    @staticmethod
    def make_run(cones, lift, seed=0):
        from types import SimpleNamespace
        return SimpleNamespace(measured=True, technique="vct", scene="a",
                               swept={"diffuse_cones": str(cones)},
                               params={"diffuse_cones": cones, "lift": lift, "seed": seed,
                                       "voxel_resolution": 64})

    def test_unswept_parameter_splits_lines_and_seed_does_not(self):
        from gilab_report.analysis import find_sweeps
        runs = [self.make_run(3, 1.5), self.make_run(6, 1.5), self.make_run(3, 0.5), self.make_run(6, 0.5),
                self.make_run(6, 0.5, seed=2)]
        (sweep,) = find_sweeps(runs)
        self.assertEqual(sweep.key, "diffuse_cones")
        self.assertEqual(sweep.other_keys, ["lift"])
        lines = {k: [r.params["diffuse_cones"] for r in v] for k, v in sweep.series.items()}
        self.assertEqual(lines, {("0.5",): [3, 6, 6], ("1.5",): [3, 6]})


if __name__ == "__main__":
    unittest.main(verbosity=1)
