#!/usr/bin/python3
"""Known-answer tests of the verdict rules (scripts/gilab_report/verdicts.py) and of their use by the
study analysis (gilab_report/study.py), `gilab report`'s HTML and scripts/findings.py (issue 44):
a compensating run flagged and kept from the headline, a borderline budget marked, a seed spread
widening a tie, the two-size cost split recovered, paper.json read for the paper rung, and the
report and the findings agreeing on every verdict. No GPU, no Chromium: a few seconds.

    PYTHONPATH=scripts /usr/bin/python3 tests/report/test_verdicts.py (ctest: CpuReportStudy.VerdictRules)
"""
from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))

import matplotlib  # noqa: E402

matplotlib.use("agg")
from gilab_report import cost as C  # noqa: E402
from gilab_report import paper_facts as PF  # noqa: E402
from gilab_report import study as S  # noqa: E402
from gilab_report import verdicts as V  # noqa: E402
from test_study import result_json, row  # noqa: E402


def entry(series, t, e, sigma=0.0, spread=0.0, seed=0.0, matched=None, bounces=1, floor=None):
    return V.Entry(key=series, series=series, time=t, error=e, error_sigma=sigma,
                   time_spread=spread, seed_sigma=seed, matched=matched, bounces=bounces,
                   floor=floor)


class Compensation(unittest.TestCase):
    def test_below_the_bounce_floor_is_flagged_and_never_wins(self):
        # The exact one-bounce image scores 0.70 against the full reference; a one-bounce run
        # at 0.50 beats a perfect image of what it claims: compensating.
        cheat = entry("cheat", 20, 0.50, sigma=0.01, floor=0.70)
        honest = entry("honest", 30, 0.75, sigma=0.01, floor=0.70)
        two = entry("two", 40, 0.60, sigma=0.01, bounces=2, floor=0.55)  # above its 2-bounce floor
        V.flag_compensation([cheat, honest, two])
        self.assertTrue(cheat.compensating)
        self.assertIn("below the 1-bounce floor", cheat.compensation[0])
        self.assertFalse(honest.compensating)
        self.assertFalse(two.compensating)
        v = V.verdict({"cheat": [cheat], "honest": [honest], "two": [two]}, 50)
        self.assertEqual(v.winners, ["two"])  # not cheat, though its error is lowest
        self.assertEqual(v.compensating, ["cheat"])

    def test_within_the_noise_of_the_floor_is_not_flagged(self):
        e = entry("a", 20, 0.69, sigma=0.02, floor=0.70)
        V.flag_compensation([e])
        self.assertFalse(e.compensating)

    def test_a_ranking_that_flips_with_the_basis_is_flagged(self):
        # Same claimed bounces: a wins on the full basis, b on the matched one, both beyond noise.
        a = entry("a", 20, 0.60, sigma=0.01, matched=0.30)
        b = entry("b", 20, 0.66, sigma=0.01, matched=0.10)
        c = entry("c", 20, 0.50, sigma=0.01, matched=0.05, bounces=2)  # other basis: no pair
        V.flag_compensation([a, b, c])
        self.assertTrue(a.compensating)
        self.assertIn("ranks 1 of 2 on the full basis but 2 on the matched one", a.compensation[0])
        self.assertFalse(b.compensating)
        self.assertFalse(c.compensating)

    def test_the_study_keeps_a_compensating_run_from_the_headline(self):
        rows = [row("s", "direct", 5, 0.9), row("s", "ssvp", 30, 0.45, sigma=0.01),
                row("s", "vct", 40, 0.62, sigma=0.01)]
        for r in rows:  # the scene's floors, as every result.json carries them
            r["floor0.flip"], r["floor1.flip"], r["floor2.flip"] = 0.9, 0.60, 0.53
        rows[1]["bounces"] = 2  # ssvp claims two bounces: 0.45 < 0.53 - noise
        st = S.analyse(rows, budgets=(50,)).scenes["s"]
        col = st.equal_time[0]
        self.assertEqual(col.winners, ["vct"])
        self.assertEqual(col.compensating, ["ssvp"])
        self.assertTrue(col.cells["ssvp"].compensating and not col.cells["ssvp"].best)
        self.assertNotIn("ssvp", [p.series for p in st.front])
        self.assertEqual(st.bounce_floors, {0: 0.9, 1: 0.60, 2: 0.53})


class Borderline(unittest.TestCase):
    def test_winner_near_the_budget_edge(self):
        a = entry("a", 48, 0.40, spread=0.10)  # 48 + 4.8 > 50
        b = entry("b", 20, 0.60, spread=0.10)
        v = V.verdict({"a": [a], "b": [b]}, 50)
        self.assertEqual(v.winners, ["a"])
        self.assertTrue(v.borderline)
        self.assertFalse(V.verdict({"a": [a], "b": [b]}, 60).borderline)  # 52.8 < 60

    def test_better_rival_just_over_the_budget(self):
        a = entry("a", 30, 0.50, spread=0.05)
        b = entry("b", 53, 0.30, spread=0.10)  # 53 - 5.3 <= 50: might fit the budget
        v = V.verdict({"a": [a], "b": [b]}, 50)
        self.assertEqual(v.winners, ["a"])
        self.assertTrue(v.borderline)
        self.assertIn("over the budget by less than its time spread", v.borderline_why[0])
        b.time_spread = 0.02  # 53 - 1.06 > 50: clearly over
        self.assertFalse(V.verdict({"a": [a], "b": [b]}, 50).borderline)

    def test_equal_error_target_edge(self):
        a = entry("a", 30, 0.49, sigma=0.02)
        v = V.verdict({"a": [a]}, 0.50, by_time=True)
        self.assertTrue(v.borderline)
        a.error = 0.40
        self.assertFalse(V.verdict({"a": [a]}, 0.50, by_time=True).borderline)


class SeedSpread(unittest.TestCase):
    def test_seed_spread_widens_a_tie(self):
        a, b = entry("a", 10, 0.40, sigma=0.01), entry("b", 10, 0.43, sigma=0.01)
        self.assertFalse(V.error_tie(a, b))  # 0.03 > sqrt(2) 0.01
        a.seed_sigma = b.seed_sigma = 0.02  # sqrt(2 (0.01^2 + 0.02^2)) = 0.0316
        self.assertTrue(V.error_tie(a, b))

    def test_pooled_spreads(self):
        self.assertAlmostEqual(V.pooled_spread([[1, 3], [10, 12, 14]]), (10 / 3) ** 0.5)
        self.assertIsNone(V.pooled_spread([[1], []]))
        self.assertAlmostEqual(V.pooled_relative_spread([[9, 11], [90, 110]]), 0.1 * 2 ** 0.5)

    def test_the_study_pools_seeds_and_widens_its_tie(self):
        # ssvp ran three seeds of one configuration: 0.40 / 0.44 / 0.48 (mean 0.44, spread 0.04);
        # vct at 0.47 is 0.03 from it: no tie on the reference's bars (0.01 each) alone.
        rows = [row("s", "ssvp", 30, e, sigma=0.01, seed=k) for k, e in
                enumerate((0.40, 0.44, 0.48))] + [row("s", "vct", 35, 0.47, sigma=0.01)]
        study = S.analyse(rows, budgets=(50,))
        self.assertAlmostEqual(study.seed_spread["ssvp"], 0.04)
        col = study.scenes["s"].equal_time[0]
        self.assertEqual(col.cells["ssvp"].point.repeats, 3)
        self.assertAlmostEqual(col.cells["ssvp"].point.y, 0.44)
        self.assertEqual(col.winners, ["ssvp", "vct"])  # |0.03| <= sqrt(2e-4 + 0.04^2)
        self.assertEqual(list(study.scenes["s"].series), ["ssvp", "vct"])  # seed: no new series


class Calibration(unittest.TestCase):
    def test_the_path_tracer_is_compared_with_the_winner_never_the_winner(self):
        rows = [row("s", "direct", 5, 0.9), row("s", "vct", 30, 0.5, sigma=0.01),
                row("s", "pathtracer", 20, 0.3, sigma=0.01, swept="spp", spp=4),
                row("s", "pathtracer", 45, 0.49, sigma=0.01, swept="spp", spp=16, key="pt16")]
        study = S.analyse(rows, budgets=(25, 50))
        t25, t50 = study.scenes["s"].equal_time
        self.assertEqual(t25.winners, ["direct"])
        self.assertEqual(t25.calibration, {"pathtracer": "beats"})
        self.assertEqual(t50.winners, ["vct"])
        self.assertEqual(t50.calibration, {"pathtracer": "beats"})
        cells = S.verdict_table(study)["pathtracer"]
        self.assertEqual([c.text() for c in cells], ["beats the winner 1"] * 2)
        self.assertIn("[pathtracer beats it]", S.scene_lines(study)[0])


class Cost(unittest.TestCase):
    def test_two_size_split_is_recovered(self):
        fixed, per_px = 2.0, 3e-5  # ms, ms per pixel
        small, large = 128 * 128, 256 * 256
        split = V.cost_split((small, fixed + per_px * small), (large, fixed + per_px * large))
        self.assertAlmostEqual(split.fixed_ms, 2.0)
        self.assertAlmostEqual(split.per_mpixel_ms, 30.0)
        self.assertAlmostEqual(split.at(1920 * 1080), 2.0 + 30.0 * 1920 * 1080 / 1e6)
        self.assertIsNone(V.cost_split((small, 1.0), (small, 2.0)))

    def test_the_study_splits_a_rung_timed_at_two_sizes(self):
        def t(px):
            return 2.0 + 3e-5 * px
        rows = []
        for label, (w, h) in (("box", (64, 64)), ("box_2x", (128, 128))):
            for tech, y in (("direct", 0.9), ("vct", 0.5)):
                r = row(label, tech, t(w * h) * (1 if tech == "vct" else 0.5), y)
                r["scene_source"], r["resolution"] = "scenes/box.json#spot", f"{w}x{h}"
                rows.append(r)
        study = S.analyse(rows, budgets=(50,))
        self.assertEqual(study.size_twins, {"box_2x": "box"})
        self.assertEqual(list(S.quality_scenes(study)), ["box"])  # the twin gives no verdict
        self.assertEqual(S.verdict_table(study)["vct"][0].wins, ["box"])
        vct = next(c for c in C.whole_cost(study) if c.series == "vct")
        self.assertAlmostEqual(vct.split.fixed_ms, 2.0)
        self.assertAlmostEqual(vct.split.per_mpixel_ms, 30.0)
        self.assertEqual(vct.scenes, 1)
        self.assertIn("box (64x64) vs box_2x (128x128)", vct.split_where)

    def test_the_light_move_frame_and_payback(self):
        r = row("orbit", "vct", 10.0, 0.5)
        r.update({"animation_frames": 9, "animation_moves": "light", "setup_ms": 500.0,
                  "dynamic_frame_gpu_ms_median": 60.0})
        r2 = row("orbit", "ssvp", 20.0, 0.4)
        r2.update({"animation_frames": 9, "animation_moves": "light", "setup_ms": 5.0,
                   "dynamic_frame_gpu_ms_median": 20.0})
        study = S.analyse([r, r2])
        costs = {c.series: c for c in C.whole_cost(study)}
        self.assertEqual(costs["vct"].light_ms, 60.0)
        self.assertAlmostEqual(costs["vct"].payback_frames, 500.0 / 50.0)
        self.assertIsNone(costs["ssvp"].payback_frames)  # the update costs nothing extra

    def test_payback(self):
        self.assertAlmostEqual(V.payback_frames(1000.0, 60.0, 10.0), 20.0)
        self.assertIsNone(V.payback_frames(1000.0, 10.0, 10.0))


class PaperFacts(unittest.TestCase):
    def test_every_technique_has_its_paper_json(self):
        facts = PF.load_all()
        # Every technique folder but the direct-light baseline's has one
        root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "techniques")
        folders = sorted(d for d in os.listdir(root)
                         if os.path.isdir(os.path.join(root, d)) and d != "direct")
        self.assertEqual(sorted(facts), folders)
        self.assertIn("ddgi", facts)
        self.assertEqual(facts["ddgi"].paper_rung["volume_scale"], 1.05)  # G3D circumscribed
        self.assertEqual(facts["vct"].paper_rung["lift"], 0)  # design choice: the paper's value
        self.assertNotIn("kmeans_metric", facts["ssvp"].paper_rung)  # erratum: ours kept

    def test_a_bad_file_is_named(self):
        with tempfile.TemporaryDirectory() as tmp:
            os.makedirs(os.path.join(tmp, "x"))
            path = os.path.join(tmp, "x", "paper.json")
            with open(path, "w") as f:
                json.dump({"technique": "x", "citation": "c", "paper_settings": {},
                           "choices": [{"param": "p", "ours": 1, "paper": 0, "kind": "taste"}]}, f)
            with self.assertRaises(PF.PaperFactsError) as e:
                PF.load_all(tmp)
            self.assertIn(path, str(e.exception))
            self.assertIn("choices[0].kind", str(e.exception))

    def test_a_series_at_our_lift_is_not_the_paper_rung(self):
        rows = [row("s", "vct", 40, 0.5, voxel_resolution=256, diffuse_cones=3, lift=1.5),
                row("s", "vct", 40, 0.6, voxel_resolution=256, diffuse_cones=3, lift=0)]
        st = S.analyse(rows).scenes["s"]
        paper = {p.series: p.paper for p in st.points}
        self.assertEqual(paper, {"vct (lift=1.5)": False, "vct (lift=0)": True})


def _md_winners(md: str, scene: str) -> list[list[str]]:
    """The 'best (and ties)' cells of the scene's equal-time and equal-error tables."""
    part = md.split(f"## {scene}\n", 1)[1].split("\n## ", 1)[0]
    return [[c.strip() for c in line.strip().strip("|").split("|")[1:]]
            for line in part.splitlines() if line.startswith("| best (and ties) |")]


def _html_winners(html: str) -> list[list[str]]:
    """Every 'best (and ties)' row of the report's study tables."""
    rows = re.findall(r'<tr class="winners"><td>best \(and ties\)</td>(.*?)</tr>', html)
    return [[re.sub(r"<[^>]+>", "", c) for c in re.findall(r"<td[^>]*>(.*?)</td>", r)]
            for r in rows]


class ReportAndFindingsAgree(unittest.TestCase):
    def test_every_verdict_is_the_same(self):
        with tempfile.TemporaryDirectory() as tmp:
            results = os.path.join(tmp, "results", "study")
            runs = [result_json("k1", "box", "direct", 10.0, 0.8),
                    result_json("k2", "box", "vct", 30.0, 0.5, params={"voxel_resolution": 64},
                                swept=("voxel_resolution",)),
                    result_json("k3", "box", "vct", 150.0, 0.46,
                                params={"voxel_resolution": 128}, swept=("voxel_resolution",)),
                    result_json("k4", "box", "ssvp", 45.0, 0.3),  # compensating (below floor)
                    result_json("k5", "box", "dvs", 48.0, 0.49)]
            for r in runs:
                r["metrics"]["bounce_floors"] = {"0": {"flip": {"mean": 0.8}},
                                                 "1": {"flip": {"mean": 0.45}}}
                os.makedirs(os.path.join(results, "runs", r["key"]))
                with open(os.path.join(results, "runs", r["key"], "result.json"), "w") as f:
                    json.dump(r, f)
            with open(os.path.join(results, "experiment.json"), "w") as f:
                json.dump({"name": "t", "runs_total": 5}, f)
            out = os.path.join(tmp, "docs", "findings.md")
            p = subprocess.run([sys.executable, os.path.join(REPO, "scripts", "findings.py"), "--allow-dirty",
                                results, "--out", out],
                               capture_output=True, text=True, timeout=120)
            self.assertEqual(p.returncode, 0, p.stderr)
            with open(out, encoding="utf-8") as f:
                md_cells = _md_winners(f.read(), "box")
            report = os.path.join(tmp, "report")
            p = subprocess.run([sys.executable, "-m", "gilab_report",
                                results, "--out", report], capture_output=True, text=True,
                               timeout=300)
            self.assertEqual(p.returncode, 0, p.stderr)
            with open(os.path.join(report, "report.html"), encoding="utf-8") as f:
                html_rows = _html_winners(f.read())
        # ssvp's 0.3 is below its one-bounce floor (0.45): marked, never the winner. ≤ 50 ms: dvs
        # (0.49) over vct's 64^3 (0.5); ≤ 200 ms: vct's 128^3 (0.46). No error bars: no ties.
        self.assertEqual(md_cells[0][:2], ["dvs; compensating: ssvp", "vct; compensating: ssvp"])
        self.assertEqual(len(md_cells), 2)  # equal time, equal error
        self.assertEqual(md_cells, html_rows)


class CommonScenes(unittest.TestCase):
    def test_cross_scene_medians_use_one_scene_set(self):
        # vct ran s and t, ssvp only s: both summaries stand on s alone (t's 0.1 would flatter
        # vct against a technique that never ran t).
        rows = [row("s", "direct", 5, 1.0), row("t", "direct", 5, 1.0),
                row("s", "vct", 30, 0.6), row("t", "vct", 30, 0.1), row("s", "ssvp", 30, 0.5)]
        study = S.analyse(rows, budgets=(50,))
        self.assertEqual(S.common_scenes(study), ["s"])
        g = {x["technique"]: x for x in S.glance(study)}
        self.assertEqual(g["vct"]["median_best"], 0.6)
        self.assertEqual(g["vct"]["floor_ratio"], 0.6)
        self.assertEqual(g["ssvp"]["median_best"], 0.5)
        self.assertEqual(g["vct"]["wins"], {"t": ["≤50"]})  # wins still count on any scene


class CleanCommit(unittest.TestCase):
    def test_findings_refuse_runs_of_a_dirty_build(self):
        with tempfile.TemporaryDirectory() as tmp:
            results = os.path.join(tmp, "results", "study")
            for r in (result_json("k1", "box", "direct", 10.0, 0.8),
                      result_json("k2", "box", "vct", 30.0, 0.5)):
                r["provenance"]["git_commit"] = "abc1234-dirty"
                os.makedirs(os.path.join(results, "runs", r["key"]))
                with open(os.path.join(results, "runs", r["key"], "result.json"), "w") as f:
                    json.dump(r, f)
            out = os.path.join(tmp, "findings.md")
            cmd = [sys.executable, os.path.join(REPO, "scripts", "findings.py"), results,
                   "--out", out]
            p = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
            self.assertEqual(p.returncode, 2, p.stderr)
            self.assertIn("runs were made by a build with uncommitted changes (abc1234-dirty)",
                          p.stderr)
            self.assertFalse(os.path.exists(out))
            p = subprocess.run(cmd + ["--allow-dirty"], capture_output=True, text=True,
                               timeout=120)
            self.assertEqual(p.returncode, 0, p.stderr)
            with open(out, encoding="utf-8") as f:
                self.assertIn("**Draft (--allow-dirty):", f.read())


if __name__ == "__main__":
    unittest.main(verbosity=1)
