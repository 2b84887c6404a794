"""Checks of the report's content against the fixture's result.json files (issue 10): one ranking
basis named in every headline label and never mixed, the images (full reference, indirect
layers), device labels on every time axis and header, the no-op sweep note, EXR links, IQR bars,
ties and the timer-overhead rule. Used by test_report.py; each function takes its Checks object
(anything with check(ok, what, detail="")) and the dumped DOM.
"""
from __future__ import annotations

import html
import json
import math
import os
import re
from typing import Any, Optional

LAVAPIPE = "lavapipe (CPU)"
BASIS_WORDS = {"full": "vs full reference", "matched": "vs bounce-matched reference (",
               "sequence": "vs full reference, mean over the 5 measured frames"}
DYNAMIC = "dynamic frame (light/camera moved, update included)"
MS_WORD = re.compile(r"\bms\b")


def results_by_key(results_dir: str) -> dict[str, dict]:
    out = {}
    runs = os.path.join(results_dir, "runs")
    for name in os.listdir(runs):
        path = os.path.join(runs, name, "result.json")
        if name.startswith(".") or not os.path.isfile(path):
            continue
        try:
            with open(path, encoding="utf-8") as f:
                data = json.load(f)
        except ValueError:
            continue
        out[data.get("key", name)] = data
    return out


def dig(data: Any, *path: str) -> Any:
    for step in path:
        data = data.get(step) if isinstance(data, dict) else None
    return data


def basis_value(data: dict, basis: str) -> Optional[float]:
    if basis == "sequence":
        return dig(data, "metrics", "sequence", "full_flip_mean")
    metric = "final_vs_full" if basis == "full" else "final"
    return dig(data, "metrics", metric, "flip", "mean")


def animated_scenes(runs: dict[str, dict]) -> set[str]:
    """Scene labels with at least one animated run (an `animation` block)."""
    return {dig(d, "scene", "label") for d in runs.values() if isinstance(d.get("animation"), dict)}


def ranked_time(data: dict, animated: bool) -> Optional[float]:
    """The frame time a ranking uses: the dynamic frame on an animated scene."""
    name = "dynamic_frame_gpu_ms" if animated else "frame_gpu_ms"
    return dig(data, "timing", name, "median")


def close(a: Optional[float], b: Optional[float]) -> bool:
    return a is not None and b is not None and math.isclose(a, b, rel_tol=1e-9, abs_tol=1e-12)


def strip_tags(markup: str) -> str:
    return html.unescape(re.sub(r"<[^>]+>", "", markup))


def cards(dom: str) -> list[tuple[str, str]]:
    """(data-key, markup) of every image card (up to the next card)."""
    parts = re.split(r'(?=<div class="card" style="[^"]*" data-key=")', dom)
    out = []
    for part in parts[1:]:
        key = re.match(r'<div class="card" style="[^"]*" data-key="([^"]+)"', part).group(1)
        out.append((key, part))
    return out


def ranking_tables(dom: str) -> list[tuple[str, str, str]]:
    """(data-basis, data-value, markup) of every ranking table (fronts, equal time/error)."""
    return re.findall(r'<table class="data ranking" data-basis="([^"]+)" data-value="([^"]+)">'
                      r'(.*?)</table>', dom, re.S)


def check_bases(checks: Any, results_dir: str, dom: str, basis: str) -> None:
    """Every headline label names the basis (`basis` on static scenes, the mean over the measured
    frames on animated ones); every ranking number comes from that basis (times: the dynamic
    frame on animated scenes); the best card is the lowest on it; no table mixes references."""
    runs = results_by_key(results_dir)
    animated = animated_scenes(runs)

    def basis_of(data: dict) -> str:
        return "sequence" if dig(data, "scene", "label") in animated else basis

    shown = cards(dom)
    headlines = [(key, re.search(r'<div class="headline"><span class="basis">(.*?)</span> '
                                 r'<b class="v">([0-9.]+)', part)) for key, part in shown]
    unnamed = [k for k, m in headlines
               if not m or BASIS_WORDS[basis_of(runs[k])] not in html.unescape(m.group(1))
               or (basis_of(runs[k]) != "sequence" and "mean over" in m.group(1))]
    checks.check(bool(shown) and not unnamed,
                 f"{basis} basis: every image card's headline label names it "
                 f"('{BASIS_WORDS[basis]}'; '{BASIS_WORDS['sequence']}' on animated scenes)",
                 str(unnamed[:3]))
    wrong = [k for k, m in headlines if m and not close(
        round(basis_value(runs[k], basis_of(runs[k])) or -1, 4), float(m.group(2)))]
    checks.check(not wrong, f"{basis} basis: every card's headline number is the run's error "
                 "on that basis", str(wrong[:3]))
    for key, part in shown:
        if 'class="badge b-best"' not in part and "b-tie" not in part.split('card-params')[0]:
            continue
        data = runs[key]
        own = basis_of(data)
        rivals = [basis_value(d, own) for d in runs.values() if d.get("status") == "ok"
                  and dig(d, "scene", "label") == dig(data, "scene", "label")
                  and dig(d, "technique", "id") == dig(data, "technique", "id")
                  and (own != "matched" or dig(d, "reference", "matched")
                       == dig(data, "reference", "matched"))]
        if not checks.check(basis_value(data, own) is not None
                            and basis_value(data, own) <= min(v for v in rivals if v is not None),
                            f"{own} basis: best card {key[:8]} has its technique's lowest error"):
            break
    tables = ranking_tables(dom)
    wanted = {basis} | ({"sequence"} if animated else set())
    checks.check(bool(tables) and {b for b, _, _ in tables} == wanted,
                 f"{basis} basis: {len(tables)} ranking tables, all on it (animated scenes: on "
                 "the mean over the measured frames)", str({b for b, _, _ in tables}))
    problems = []
    for table_basis, value, markup in tables:
        word = BASIS_WORDS[table_basis]
        heads = " | ".join(strip_tags(h) for h in re.findall(r"<th>(.*?)</th>", markup, re.S))
        if word not in heads:
            problems.append(f"header without '{word}': {heads[:120]}")
        if (table_basis == "sequence") != (DYNAMIC in heads):
            problems.append(f"the dynamic frame named iff animated: {heads[:160]}")
        cells = re.findall(r'data-key="([^"]+)" data-basis="([^"]+)" data-v="([^"]+)"', markup)
        if not cells:
            problems.append("table without ranked cells")
        references = set()
        for key, cell_basis, v in cells:
            data = runs[key]
            references.add(dig(data, "reference", "matched"))
            expected = (basis_value(data, table_basis) if value == "error"
                        else ranked_time(data, table_basis == "sequence"))
            if cell_basis != table_basis or basis_of(data) != table_basis \
                    or not close(float(v), expected):
                problems.append(f"{key[:8]}: {cell_basis} {v} != {expected}")
        if table_basis == "matched" and len(references) > 1:
            problems.append(f"one table mixes the references {sorted(references)}")
    checks.check(not problems, f"{basis} basis: every ranked number is the run's value on its "
                 "scene's basis (or its frame time: the dynamic frame on animated scenes) and no "
                 "table mixes references", "; ".join(problems[:4]))


def check_images(checks: Any, results_dir: str, dom: str) -> None:
    """The full reference of every scene, and each card's indirect layer next to the
    reference's matching one."""
    runs = results_by_key(results_dir)
    scenes = {dig(d, "reference", "full_png").split("/")[-2] for d in runs.values()
              if dig(d, "reference", "full_png")}
    srcs = re.findall(r'<img src="([^"]+)"', dom)
    full = {s.split("/")[1] for s in srcs if s.startswith("references/") and s.endswith("/full.png")}
    checks.check(bool(scenes) and full == scenes, "the full reference image of every scene is "
                 "shown", f"{sorted(full)} vs {sorted(scenes)}")
    missing = []
    for key, part in cards(dom):
        data = runs[key]
        imgs = re.findall(r'<img src="([^"]+)"', part)
        own = f"runs/{key}/indirect.png"
        ref = dig(data, "reference", "indirect_png")
        ref_name = ref.split("/")[-1] if ref else None
        if own not in imgs or not ref_name or not any(i.endswith(
                "/" + ref_name.replace("+", "%2B")) or i.endswith("/" + ref_name) for i in imgs):
            missing.append(key[:8])
    checks.check(not missing and bool(cards(dom)), "every card shows the run's indirect layer and "
                 "the reference's matching indirect layer", str(missing[:4]))


def check_direct_line(checks: Any, results_dir: str, dom: str) -> None:
    """Every scene with metrics.direct states the shared direct light's energy and leak once."""
    runs = results_by_key(results_dir)
    expected = {}
    for d in runs.values():
        energy = dig(d, "metrics", "direct", "energy_ratio")
        if energy is not None:
            expected[d["scene"]["label"]] = (energy, dig(d, "metrics", "direct", "shadow_leak"))
    lines = re.findall(r'<p class="direct-line">(.*?)</p>', dom, re.S)
    missing = [scene for scene, (energy, leak) in expected.items()
               if not any(f"energy {energy:.4f}×" in line and f"{100 * leak:.2f} %" in line
                          for line in lines)]
    checks.check(bool(expected) and not missing and len(lines) == len(expected),
                 "every scene states the shared direct light's energy and leak (metrics.direct)",
                 f"missing {missing}, {len(lines)} lines for {len(expected)} scenes")


def svg_texts(path: str) -> list[str]:
    with open(path, encoding="utf-8") as f:
        svg = f.read()
    return [html.unescape(t).strip() for t in re.findall(r"<text[^>]*>(.*?)</text>", svg, re.S)]


def check_device(checks: Any, results_dir: str, dom: str, device: str) -> None:
    """Every time axis of every figure and every time header of the run and ranking tables
    names the device; the header explains lavapipe timings."""
    fig_dir = os.path.join(results_dir, "figures")
    bad, axes = [], 0
    for name in sorted(os.listdir(fig_dir)):
        for text in svg_texts(os.path.join(fig_dir, name)):
            if MS_WORD.search(text):
                axes += 1
                if device not in text:
                    bad.append(f"{name}: {text}")
    checks.check(axes > 0 and not bad, f"all {axes} time axes of the figures say '{device}'",
                 "; ".join(bad[:3]))
    heads = [strip_tags(h) for h in re.findall(r"<th[^>]*>(.*?)</th>", dom, re.S)]
    timed = [h for h in heads if "time" in h or re.search(r", ms\b", h) or "set-up" in h
             or h.startswith("passes")]
    checks.check(bool(timed) and all(device in h for h in timed),
                 f"all {len(timed)} time headers of the tables say '{device}'",
                 str([h for h in timed if device not in h][:3]))
    note = "CPU rasteriser" in dom and "not a GPU time" in dom
    checks.check(note == (device == LAVAPIPE), "the header explains lavapipe timings exactly "
                 "when the runs are on lavapipe")
    if device != LAVAPIPE:
        checks.check(LAVAPIPE not in dom.split("<footer")[0],
                     "GPU runs are never labelled lavapipe")


def check_no_effect(checks: Any, results_dir: str, dom: str) -> None:
    notes = re.findall(r'<li class="no-effect">(.*?)</li>', dom, re.S)
    texts = [strip_tags(n) for n in notes]
    checks.check(len(texts) == 1 and "sponza#sun" in texts[0]
                 and "shared.area_light_samples has no effect on this scene" in texts[0]
                 and "identical output images" in texts[0],
                 "the no-op sweep (area-light samples on sponza#sun) is reported as having no "
                 "effect on this scene, and only that one", str(texts))
    svgs = os.listdir(os.path.join(results_dir, "figures"))
    checks.check(any(s.startswith("sweep_direct_cornell_box_") for s in svgs)
                 and not any(s.startswith("sweep_direct_sponza") for s in svgs),
                 "the area-light sweep has a figure where it matters and none where it is a no-op")


def check_exr_links(checks: Any, results_dir: str, dom: str) -> None:
    runs = results_by_key(results_dir)
    measured = [k for k, d in runs.items() if d.get("status") in ("ok", "nonfinite", "invalid")
                and dig(d, "outputs", "exr")]
    links = set(re.findall(r'<a class="exr" href="runs/([^/"]+)/output\.exr"', dom))
    checks.check(bool(measured) and set(measured) <= links,
                 f"every run with an EXR links it ({len(links)} runs linked)",
                 str(sorted(set(measured) - links)[:3]))


def check_iqr_bars(checks: Any, results_dir: str) -> None:
    fig_dir = os.path.join(results_dir, "figures")
    wanted = [n for n in os.listdir(fig_dir) if n.startswith(("sweep_", "pareto_"))]
    without = []
    for name in wanted:
        with open(os.path.join(fig_dir, name), encoding="utf-8") as f:
            if 'id="iqr-bars' not in f.read():
                without.append(name)
    checks.check(bool(wanted) and not without, f"every sweep and error-vs-time figure draws "
                 f"frame-time IQR bars ({len(wanted)} figures)", str(without))


def check_ties(checks: Any, dom: str) -> None:
    """The two identical direct runs on sponza#sun: one on the front, the other a tie."""
    rows = [strip_tags(r) for _, _, t in ranking_tables(dom) for r in re.findall(
        r"<tr data-key=[^>]*>(.*?)</tr>", t, re.S)]
    ties = [r for r in rows if "tie with" in r]
    checks.check(len(ties) == 1 and "shared.area_light_samples" in ties[0],
                 "a run inseparable from a front run (IQR and error bars overlap) is listed as a "
                 "tie, not as beaten", str(ties))


def check_overhead(checks: Any, dom: str, measurable: bool) -> None:
    row = re.search(r"<td>timer overhead</td><td>(.*?)</td>", dom, re.S)
    body = strip_tags(row.group(1)) if row else ""
    if measurable:
        checks.check(bool(re.match(r"0\.050 ± 0\.020 ms per frame", body)),
                     "timer overhead larger than its IQR: its figure is shown", body)
    else:
        checks.check("not measurable" in body and "0.010" not in body,
                     "timer overhead within its IQR: no figure, 'not measurable'", body)


# ---------------------------------------------------------------------------------------------
# Animated scenes (issue 11)
# ---------------------------------------------------------------------------------------------

def _section(dom: str, start: str, end: str) -> str:
    a = dom.find(start)
    if a < 0:
        return ""
    b = dom.find(end, a + len(start))
    return dom[a:b if b >= 0 else len(dom)]


def _attrs(tag: str) -> dict[str, str]:
    return {k: html.unescape(v) for k, v in re.findall(r'([\w-]+)="([^"]*)"', tag)}


def check_animation(checks: Any, results_dir: str, dom: str) -> None:
    """The animated-scene section exists exactly when a run is animated; on it: labels naming
    the basis and the dynamic frame, the cost table (static and dynamic columns, device in every
    time header, the numbers of result.json), the per-frame error figure (one line per run), the
    temporal-instability figure, the frame strip (reference + runs, the right number of images,
    the temporal map), "full rebuild" flagged and the within-noise-floor run marked."""
    runs = results_by_key(results_dir)
    scenes = animated_scenes(runs)
    fig_dir = os.path.join(results_dir, "figures")
    svgs = sorted(os.listdir(fig_dir)) if os.path.isdir(fig_dir) else []
    present = 'id="animation"' in dom
    checks.check(present == bool(scenes), f"the animated-scene section is there exactly when a "
                 f"run is animated ({len(scenes)} animated scene(s))")
    if not scenes:
        checks.check(not any(s.startswith(("sequence_", "temporal_")) for s in svgs)
                     and DYNAMIC not in dom and "mean over the" not in dom,
                     "no animated run: no per-frame or temporal figure, no dynamic-frame or "
                     "frame-mean label")
        return
    device = LAVAPIPE
    for scene in sorted(scenes):
        measured = {k: d for k, d in runs.items() if dig(d, "scene", "label") == scene
                    and d.get("status") in ("ok", "nonfinite")}
        slug_part = re.sub(r"[^A-Za-z0-9_.-]+", "_", scene)
        block = _section(dom, f'<section class="scene anim" id="anim-{slug_part}', "</section>")
        if not checks.check(bool(block), f"{scene}: its animated-scene block exists"):
            continue
        text = strip_tags(block)
        checks.check(f"Ranked by HDR-FLIP {BASIS_WORDS['sequence']}" in text and DYNAMIC in text,
                     f"{scene}: the block names the basis and the dynamic frame")
        # the scene's image cards: headline on the frame mean, time on the dynamic frame
        own_cards = [(k, p.split('class="card-links"')[0]) for k, p in cards(dom)
                     if k in measured]
        checks.check(bool(own_cards) and all(
            BASIS_WORDS["sequence"] in strip_tags(p) and DYNAMIC in strip_tags(p) and "static frame time" in strip_tags(p)
            for _, p in own_cards),
            f"{scene}: every image card names the frame-mean basis, the dynamic and the static "
            "frame")
        # the error-vs-time figure: dynamic frame on its time axes, basis in the first title
        pareto = [s for s in svgs if s.startswith(f"pareto_{slug_part}")]
        texts = svg_texts(os.path.join(fig_dir, pareto[0])) if pareto else []
        joined = " ".join(texts)
        checks.check(bool(pareto) and "dynamic frame" in joined
                     and "(light/camera moved, update included)" in joined
                     and "static frame of the same run" in joined
                     and next((t for t in texts if t.startswith("HDR-FLIP vs")), "")
                     .startswith("HDR-FLIP vs full reference, mean over the 5"),
                     f"{scene}: the error-vs-time figure is on the dynamic frame (static frame "
                     "shown too) and its first panel on the frame mean")
        check_cost_table(checks, scene, block, measured, device)
        check_animation_figures(checks, scene, block, fig_dir, slug_part, measured)
        check_strip(checks, scene, block, measured)
        rebuilt = [k for k, d in measured.items() if dig(d, "animation", "update") == "full rebuild"]
        flagged = [k for k, p in own_cards if 'class="badge b-rebuild" data-update="full rebuild"'
                   in p and "no real update path" in p]
        incremental = [k for k, p in own_cards if "b-rebuild" in p
                       and dig(runs[k], "animation", "update") != "full rebuild"]
        checks.check(bool(rebuilt) and set(flagged) == {k for k, _ in own_cards if k in rebuilt}
                     and not incremental and 'class="warn rebuild"' in block,
                     f"{scene}: \"full rebuild\" is flagged (badge on its cards and rows, a "
                     "warning in the block), \"incremental\" is not")
        quiet = [k for k, d in measured.items()
                 if (dig(d, "metrics", "sequence", "temporal", "temporal_instability") or 1.0)
                 <= (dig(d, "metrics", "sequence", "temporal", "noise_floor") or 0.0)]
        rows = {k: r for k, r in re.findall(r'<tr data-key="([^"]+)">(.*?)</tr>',
                                            _section(block, 'class="data sequence-errors"',
                                                     "</table>"), re.S)}
        checks.check(bool(quiet) and all("no measurable instability" in rows.get(k, "")
                                         for k in quiet)
                     and sum("no measurable instability" in r for r in rows.values()) == len(quiet),
                     f"{scene}: the run within the noise floor is marked 'no measurable "
                     "instability', and only it")


def check_cost_table(checks: Any, scene: str, block: str, measured: dict[str, dict],
                     device: str) -> None:
    table = _section(block, '<table class="data cost"', "</table>")
    heads = [strip_tags(h) for h in re.findall(r"<th>(.*?)</th>", table, re.S)]
    timed = [h for h in heads if ", ms" in h]
    checks.check(any(h.startswith("static frame time") for h in heads)
                 and any(DYNAMIC in h for h in heads)
                 and any(h.startswith("update (CPU clock)") for h in heads)
                 and len(timed) >= 4 and all(device in h for h in timed),
                 f"{scene}: the cost table has static frame, dynamic frame, update and update "
                 f"pass columns, every time header naming '{device}'", str(heads))
    rows = dict(re.findall(r'<tr data-key="([^"]+)">(.*?)</tr>', table, re.S))
    problems = [] if set(rows) == set(measured) else [f"rows {len(rows)} != {len(measured)}"]
    for key, row in rows.items():
        data = measured.get(key, {})
        cells = dict(re.findall(r'data-col="(static|dynamic|update)" data-v="([^"]*)"', row))
        for col, path in (("static", ("timing", "frame_gpu_ms", "median")),
                          ("dynamic", ("timing", "dynamic_frame_gpu_ms", "median")),
                          ("update", ("timing", "update_cpu_ms", "median"))):
            if not cells.get(col) or not close(float(cells[col]), dig(data, *path)):
                problems.append(f"{key[:8]} {col}: {cells.get(col)} != {dig(data, *path)}")
        passes = re.findall(r'data-col="pass" data-v="([^"]*)"', row)
        expected = sorted(dig(p, "gpu_ms", "median") for p in dig(data, "timing",
                                                                  "update_passes") or [])
        if sorted(float(v) for v in passes if v) != expected:
            problems.append(f"{key[:8]} passes {passes} != {expected}")
    checks.check(not problems, f"{scene}: one cost-table row per run with its static, dynamic, "
                 "update and update-pass medians from result.json", "; ".join(problems[:4]))


def check_animation_figures(checks: Any, scene: str, block: str, fig_dir: str, slug_part: str,
                            measured: dict[str, dict]) -> None:
    svgs = os.listdir(fig_dir)
    sequence = [s for s in svgs if s.startswith(f"sequence_{slug_part}")]
    temporal = [s for s in svgs if s.startswith(f"temporal_{slug_part}")]
    with_frames = {k for k, d in measured.items() if dig(d, "metrics", "sequence", "frames")}
    lines: list[str] = []
    if sequence:
        with open(os.path.join(fig_dir, sequence[0]), encoding="utf-8") as f:
            lines = re.findall(r'id="seq-line-full-([0-9a-f]+)"', f.read())
    checks.check(len(sequence) == 1 and f"figures/{sequence[0]}" in block
                 and sorted(lines) == sorted(with_frames),
                 f"{scene}: the per-frame error figure is shown, with one line per run "
                 f"({len(lines)} lines, {len(with_frames)} runs)")
    bars: list[str] = []
    if temporal:
        with open(os.path.join(fig_dir, temporal[0]), encoding="utf-8") as f:
            bars = re.findall(r'id="temporal-bar-([0-9a-f]+)"', f.read())
    caption = strip_tags(_section(block, f"figures/{temporal[0]}" if temporal else "\0",
                                  "</figure>"))
    checks.check(len(temporal) == 1 and sorted(bars) == sorted(measured)
                 and "Temporal instability" in caption and "noise floor" in caption
                 and "no measurable instability" in caption,
                 f"{scene}: the temporal-instability figure is shown (one bar per run), its "
                 "caption defines it and says what the noise floor means")


def check_strip(checks: Any, scene: str, block: str, measured: dict[str, dict]) -> None:
    strip = _section(block, '<table class="strip"', "</table>")
    rows = re.findall(r'<tr class="(strip-ref|strip-run)"([^>]*)>(.*?)</tr>', strip, re.S)
    refs = [r for r in rows if r[0] == "strip-ref"]
    run_rows = {_attrs(r[1]).get("data-key"): r[2] for r in rows if r[0] == "strip-run"}
    n_refs = {len(dig(d, "reference", "frames_png") or []) for d in measured.values()}
    problems = []
    if len(refs) != 1 or len(re.findall(r"<img ", refs[0][2])) != max(n_refs):
        problems.append(f"reference rows {len(refs)}")
    if set(run_rows) != set(measured):
        problems.append(f"run rows {sorted(run_rows)}")
    for key, row in run_rows.items():
        data = measured.get(key, {})
        srcs = re.findall(r'<img src="([^"]+)"', row)
        frames = [s for s in srcs if "/frames/" in s]
        want = [f"runs/{key}/{p}" for p in dig(data, "outputs", "frames_png") or []]
        if frames != want or srcs[-1:] != [f"runs/{key}/{dig(data, 'outputs', 'temporal_png')}"]:
            problems.append(f"{key[:8]}: {srcs}")
    checks.check(not problems and bool(run_rows), f"{scene}: the frame strip has the reference "
                 f"row ({max(n_refs)} frames) and one row per run ({len(run_rows)}) with its "
                 "frames in order and its temporal map last", "; ".join(problems[:3]))


# ---------------------------------------------------------------------------------------------
# "The report answers first" (issue: rank order, one badge, error maps on the headline basis,
# the cross-technique answer first, sweeps apart, noisy timings, devices named)
# ---------------------------------------------------------------------------------------------

def scene_sections(dom: str) -> dict[str, str]:
    """scene label -> the markup of its image section."""
    out = {}
    for part in re.split(r'(?=<section class="scene" id="scene-)', dom)[1:]:
        part = part.split("</section>")[0]
        title = re.search(r"<h3>(.*?) <span", part, re.S)
        if title:
            out[html.unescape(title.group(1))] = part
    return out


def ranked_cards(section: str) -> list[tuple[str, int, str]]:
    """(key, rank, markup) of the ranked cards of a scene section, in page order."""
    out = []
    for key, part in cards(section):
        rank = re.match(r'<div class="card" style="[^"]*" data-key="[^"]+" data-rank="(\d+)"',
                        part)
        if rank:
            out.append((key, int(rank.group(1)), part.split('<div class="card-nums">')[0]))
    return out


def check_rank_order(checks: Any, results_dir: str, dom: str, basis: str) -> None:
    """Per scene: one ranked card per technique (and reference group on the matched basis), in
    rank order 1, 2, ... with nondecreasing errors on the basis, and exactly one 'best' badge
    (one per reference group on the matched basis), on the #1 card, whose run has the lowest
    error of every ok run of the scene (group)."""
    runs = results_by_key(results_dir)
    animated = animated_scenes(runs)
    problems, badges_seen = [], 0
    for scene, section in scene_sections(dom).items():
        own = "sequence" if scene in animated else basis
        ranked = ranked_cards(section)
        measured = {k: d for k, d in runs.items() if dig(d, "scene", "label") == scene
                    and d.get("status") in ("ok", "nonfinite")}
        if not measured:
            continue

        def group(key: str) -> str:
            return dig(runs[key], "reference", "matched") if own == "matched" else ""
        groups = sorted({group(k) for k in measured}, key=lambda g: (len(g), g))
        wanted = {(dig(d, "technique", "id"), group(k)) for k, d in measured.items()}
        shown = [(dig(runs[k], "technique", "id"), group(k)) for k, _, _ in ranked]
        if sorted(shown) != sorted(wanted):
            problems.append(f"{scene}: ranked cards {shown} != techniques {sorted(wanted)}")
        for g in groups:
            members = [(k, r, m) for k, r, m in ranked if group(k) == g]
            ranks = [r for _, r, _ in members]
            values = [basis_value(runs[k], own) for k, _, _ in members]
            if ranks != list(range(1, len(members) + 1)):
                problems.append(f"{scene} {g}: ranks {ranks}")
            if any(v is None for v in values) or values != sorted(values):
                problems.append(f"{scene} {g}: errors not in rank order {values}")
            badged = [k for k, _, m in members if 'class="badge b-best' in m]
            badges_seen += len(badged)
            best_ok = min((basis_value(d, own), k) for k, d in measured.items()
                          if d.get("status") == "ok" and group(k) == g)
            if badged != [best_ok[1]] or members[0][0] != best_ok[1]:
                problems.append(f"{scene} {g}: badges on {badged}, #1 {members[0][0]}, lowest "
                                f"ok run {best_ok[1]}")
    others = [k for k, part in cards(dom) if 'class="badge b-best' in part
              and 'data-rank="' not in part.split(">")[0]]
    checks.check(not problems and not others and badges_seen > 0,
                 f"{basis} basis: the cards of each scene are in rank order (#1, #2, ...: "
                 "errors nondecreasing), one per technique, and only the overall best run "
                 f"carries the 'best' badge ({badges_seen} badges)",
                 "; ".join(problems[:4] + [f"badge off the ranked cards: {others[:2]}"]))


def check_order(checks: Any, dom: str) -> None:
    """The cross-technique answer right after the header (and the invalid-run warning), before
    the images, and first in the navigation: the study section (two or more techniques on a
    scene, gilab_report/study_html.py) when present, then the equal-time/error tables."""
    body = dom.split("</nav>", 1)[-1]
    h2s = re.findall(r'<h2 id="([^"]+)"', body)
    nav = re.search(r"<nav>(.*?)</nav>", dom, re.S)
    links = re.findall(r'href="#([^"]+)"', nav.group(1)) if nav else []
    first = ["study", "equal"] if "study" in h2s else ["equal"]
    checks.check(h2s[:len(first)] == first and links[:len(first)] == first
                 and dom.find('id="equal"') < dom.find('id="images"'),
                 "the cross-technique answer (study section where it applies, then the "
                 "equal-time/equal-error tables) comes first after the header and first in the "
                 "navigation", f"first sections {h2s[:2]}, nav {links[:3]}")


def _png_mean(path: str) -> float:
    import matplotlib.image  # Debian's python3-matplotlib, like make_fixture

    return float(matplotlib.image.imread(path)[..., :3].mean())


def check_error_maps(checks: Any, results_dir: str, dom: str) -> None:
    """On the full basis, every ranked card shows first the error map against the full
    reference (the runner's outputs.flip_full_png where recorded, else the report's own map in
    maps/, labelled as not HDR-FLIP), then the HDR-FLIP map against the bounce-matched
    reference, labelled. For the `direct` baseline (it lacks every bounce) the first map is
    brighter than the second."""
    runs = results_by_key(results_dir)
    problems, own_maps, runner_maps = [], 0, 0
    direct_pairs = []
    for scene, section in scene_sections(dom).items():
        for key, _, part in ranked_cards(section):
            data = runs[key]
            figs = re.findall(r'<figure[^>]*><a href="[^"]*"><img src="([^"]+)"[^>]*class="([^"]*)"'
                              r'[^>]*></a><figcaption[^>]*>(.*?)</figcaption>', part, re.S)
            first = next((i for i, f in enumerate(figs) if "errfull" in f[1].split()), None)
            second = next((i for i, f in enumerate(figs) if "errmatched" in f[1].split()), None)
            if first is None or second is None or first > second:
                problems.append(f"{key[:8]}: maps {[(f[0], f[1]) for f in figs]}")
                continue
            src, _, caption = figs[first]
            caption = html.unescape(caption)
            wanted = dig(data, "outputs", "flip_full_png")
            if wanted:
                runner_maps += 1
                if src != f"runs/{key}/{wanted}" or "HDR-FLIP map vs full reference" not in caption:
                    problems.append(f"{key[:8]}: runner's map {src} '{caption}'")
            else:
                own_maps += 1
                if not src.startswith("maps/") or "error vs full reference" not in caption \
                        or "not" not in caption.lower():
                    problems.append(f"{key[:8]}: own map {src} '{caption}'")
            msrc, _, mcaption = figs[second]
            if msrc != f"runs/{key}/flip.png" or "bounce-matched reference" not in \
                    html.unescape(mcaption):
                problems.append(f"{key[:8]}: matched map {msrc}")
            if dig(data, "technique", "id") == "direct" and src.startswith("maps/"):
                direct_pairs.append((os.path.join(results_dir, src),
                                     os.path.join(results_dir, msrc)))
    checks.check(not problems and own_maps > 0 and runner_maps > 0,
                 f"every ranked card shows the error map against the full reference first "
                 f"({runner_maps} the runner's HDR-FLIP map, {own_maps} the report's own, labelled "
                 "as not HDR-FLIP), then the bounce-matched HDR-FLIP map, labelled",
                 "; ".join(problems[:3]))
    brighter = [(a, b) for a, b in direct_pairs if _png_mean(a) > 2.0 * _png_mean(b)]
    checks.check(bool(direct_pairs) and brighter == direct_pairs,
                 "the direct baseline's first map (vs full reference: it misses every bounce) is "
                 "much brighter than its bounce-matched map",
                 str([(round(_png_mean(a), 3), round(_png_mean(b), 3)) for a, b in direct_pairs]))


def check_sweeps_apart(checks: Any, results_dir: str, dom: str) -> None:
    """Runs of one technique form one sweep only if they share their set of swept keys: each
    sweep figure's caption counts exactly the runs with that set, and its legend names only the
    other keys of the set, never an empty value (the old bug: 'shared.area_light_samples=')."""
    runs = results_by_key(results_dir)
    figures = re.findall(r'<figure class="plot"><a href="figures/(sweep_[^"]+)"><img [^>]*'
                         r'alt="sweep ([^ "]+) ([^"]+) ([^ "]+)"[^>]*></a><figcaption>(.*?)'
                         r"</figcaption>", dom, re.S)
    problems = []
    for name, tech, scene, key, caption in figures:
        tech, scene, key = html.unescape(tech), html.unescape(scene), html.unescape(key)
        keysets = {tuple(sorted(dig(d, "technique", "swept") or {})) for d in runs.values()
                   if dig(d, "technique", "id") == tech and dig(d, "scene", "label") == scene
                   and key in (dig(d, "technique", "swept") or {})}
        if len(keysets) != 1:
            problems.append(f"{name}: key sets {keysets}")
            continue
        keyset = keysets.pop()
        count = sum(1 for d in runs.values() if dig(d, "technique", "id") == tech
                    and dig(d, "scene", "label") == scene and d.get("status") in ("ok", "nonfinite")
                    and tuple(sorted(dig(d, "technique", "swept") or {})) == keyset)
        if f"({count} runs" not in strip_tags(caption):
            problems.append(f"{name}: caption '{strip_tags(caption)[:80]}' != {count} runs")
        legend = [t for t in svg_texts(os.path.join(results_dir, "figures", name)) if "=" in t]
        bad = [t for t in legend if t.endswith("=") or t.split("=")[0] not in keyset
               or t.split("=")[0] == key]
        if bad:
            problems.append(f"{name}: legend {bad}")
    direct = [f for f in figures if f[1] == "direct" and f[2] == "cornell_box"]
    checks.check(not problems and len(direct) == 2
                 and all("One of 2 separate sweeps" in strip_tags(f[4]) for f in direct),
                 f"each sweep is drawn on its own ({len(figures)} figures; direct on cornell_box: "
                 "area-light samples and PCF radius apart, each caption saying so), legends "
                 "name only the sweep's other keys", "; ".join(problems[:3]))


NOISY = 0.10


def _noisy(summary: Any) -> bool:
    median, iqr = dig(summary, "median"), dig(summary, "iqr")
    return isinstance(median, (int, float)) and isinstance(iqr, (int, float)) and median > 0 \
        and iqr > NOISY * median


def check_noisy(checks: Any, results_dir: str, dom: str) -> None:
    """Every frame time whose IQR is above 10 % of its median is flagged (class "noisy") in the
    run table (static and dynamic frame), on the cards, in the error-vs-time figures (SVG id
    noisy-time-<key>), in the header; and no other one is."""
    runs = results_by_key(results_dir)
    animated = animated_scenes(runs)
    measured = {k: d for k, d in runs.items() if d.get("status") in ("ok", "nonfinite")}
    static = {k for k, d in runs.items() if _noisy(dig(d, "timing", "frame_gpu_ms"))}
    dynamic = {k for k, d in runs.items() if _noisy(dig(d, "timing", "dynamic_frame_gpu_ms"))}
    ranked_by = {k for k in measured if (k in dynamic if dig(measured[k], "scene", "label")
                                         in animated else k in static)}
    problems = []
    rows = dict(re.findall(r'<tr class="run-row[^"]*" data-key="([^"]+)">(.*?)</tr>', dom, re.S))
    for key, row in rows.items():
        for col, wanted in (("frame", key in static), ("dynamic_frame", key in dynamic)):
            cell = re.search(rf'<td class="c-{col} [^"]*"[^>]*>(.*?)</td>', row, re.S)
            if cell and ('class="noisy"' in cell.group(1)) != wanted:
                problems.append(f"run table {key[:8]} {col}: marked {not wanted}")
    for key, part in cards(dom):
        line = re.search(r'<div class="time">(.*?)</div>', part, re.S)
        if line and ('class="noisy"' in line.group(1)) != (key in ranked_by):
            problems.append(f"card {key[:8]}: marked {key not in ranked_by}")
    fig_dir = os.path.join(results_dir, "figures")
    marked = set()
    for name in os.listdir(fig_dir) if os.path.isdir(fig_dir) else []:
        if name.startswith("pareto_"):
            with open(os.path.join(fig_dir, name), encoding="utf-8") as f:
                marked |= set(re.findall(r'id="noisy-time-([0-9a-f]+)"', f.read()))
    plotted = {k for k in ranked_by if measured[k].get("status") in ("ok", "nonfinite")}
    if marked != plotted:
        problems.append(f"error-vs-time figures mark {sorted(marked)}, noisy {sorted(plotted)}")
    header = re.search(r"<td>noisy timings</td><td>(.*?)</td></tr>", dom, re.S)
    expected = len({(k, "s") for k in static if k in measured}
                   | {(k, "d") for k in dynamic if k in measured})
    if bool(header) != bool(expected) or (header and f"{expected} noisy timing"
                                           not in strip_tags(header.group(1))):
        problems.append(f"header: {header and strip_tags(header.group(1))[:80]}, {expected}")
    if expected and 'id="noisy-timings"' not in dom:
        problems.append("no definition of noisy timings")
    checks.check(not problems and (not static or bool(rows)),
                 f"noisy timings (IQR > 10 % of the median: {len(static)} static, "
                 f"{len(dynamic)} dynamic frame times) are marked in the run table, the cards, "
                 "the error-vs-time figures and the header, and no other timing is",
                 "; ".join(problems[:4]))


def check_device_captions(checks: Any, results_dir: str, dom: str) -> None:
    """Every table comparing techniques (equal time/error, Pareto fronts, the cost tables) has a
    caption naming the device model (device.name) its times come from; the run table a line."""
    names = {dig(d, "device", "name") for d in results_by_key(results_dir).values()
             if dig(d, "device", "name")}
    tables = re.findall(r'<table class="data (?:ranking|cost)"[^>]*>(.*?)</thead>', dom, re.S)
    bad = [t[:120] for t in tables
           if not re.search(r'<caption class="device-line">timed on ([^<]+)</caption>', t)
           or not any(n in html.unescape(t) for n in names)]
    line = re.search(r'<p class="device-line">Timed on (.*?)</p>', dom, re.S)
    checks.check(bool(tables) and not bad and bool(line)
                 and any(n in html.unescape(line.group(1)) for n in names),
                 f"every table comparing techniques ({len(tables)}) names the device model "
                 f"({', '.join(sorted(names))}) in its caption, the run table in a line above it",
                 str(bad[:2]))


def check_verdict(checks: Any, dom: str) -> None:
    """The first screen gives the verdict (issue 44): the study's technique x budget table
    inside the header, under the title and above the provenance table, one row per series with
    a cell per budget (wins / ties / borderline / compensating counts or a dash), the ladder
    reach and the noise the rules used, then one line per quality scene."""
    header = dom.split("</header>", 1)[0]
    at_verdict, at_meta = header.find('id="verdict"'), header.find('class="meta"')
    checks.check(0 <= at_verdict < at_meta and header.find("<h1") < at_verdict,
                 "the verdict is the first screen: in the header, after the title, before the "
                 "provenance table", f"verdict at {at_verdict}, provenance at {at_meta}")
    block = header[at_verdict:at_meta] if at_verdict >= 0 else ""
    heads = [strip_tags(h) for h in re.findall(r"<th[^>]*>(.*?)</th>", block, re.S)]
    budgets = [h for h in heads if h.startswith("≤ ") and h.endswith(" ms")]
    rows = re.findall(r"<tr>(.*?)</tr>", block.split("<tbody>", 1)[-1], re.S)
    cells = [[strip_tags(c) for c in re.findall(r"<td[^>]*>(.*?)</td>", r, re.S)] for r in rows]
    form = re.compile(r"^(—|((wins|ties|borderline|compensating|beats the winner) \d+)"
                      r"(, (ties|borderline|compensating|beats the winner) \d+)*)$")
    ok = (len(budgets) >= 1 and heads[-2:] == ["ladder reach", "noise in the rules"]
          and len(cells) >= 2 and all(len(c) == len(budgets) + 3 for c in cells)
          and all(form.match(v) for c in cells for v in c[1:1 + len(budgets)])
          and any("wins" in v for c in cells for v in c[1:1 + len(budgets)]))
    checks.check(ok, f"the verdict table: {len(cells)} series x {len(budgets)} budgets, each "
                 "cell a count of wins / ties / borderline / compensating scenes, with the "
                 "ladder reach and the noise in the rules", str(cells[:3]))
    lines = re.findall(r'<ul class="scene-verdicts">(.*?)</ul>', block, re.S)
    items = re.findall(r"<li>(.*?)</li>", lines[0], re.S) if lines else []
    checks.check(bool(items) and all(": " in strip_tags(i) for i in items),
                 f"one verdict line per quality scene below the table ({len(items)})",
                 str(items[:2]))


# ---------------------------------------------------------------------------------------------
# Issue 48 ("everyday use, round 2"): one headline answer, the maps named for what they are,
# the HDR-FLIP guide, sweeps within noise, noisy marks in the study, distinguishing
# parameters, distinct header labels, no absolute paths
# ---------------------------------------------------------------------------------------------

def check_second_view(checks: Any, dom: str) -> None:
    """With the study on the page, its verdict is the one headline: the per-technique
    equal-time/error tables sit in a closed <details> under a heading that calls them a second
    view and says how they differ; the cards' badge says 'lowest error', not 'best'."""
    body = dom.split("</nav>", 1)[-1]
    section = _section(body, '<h2 id="equal"', "<h2 ")
    heading = strip_tags(re.search(r'<h2 id="equal">(.*?)</h2>', section, re.S).group(1)) \
        if section else ""
    folded = re.search(r'<details class="second-view"><summary>[^<]*</summary>(.*)</details>',
                       section, re.S)
    tables = len(re.findall(r'<table class="data ranking"', section))
    inside = len(re.findall(r'<table class="data ranking"', folded.group(1))) if folded else 0
    words = strip_tags(section.split("<details", 1)[0])
    badges = [strip_tags(b) for b in re.findall(r'<span class="badge b-best[^"]*"[^>]*>(.*?)'
                                                 r"</span>", body, re.S)]
    checks.check('id="study"' in body and tables > 0 and inside == tables
                 and "Which technique is best" not in heading and "second view" in heading
                 and "verdict" in words and "series" in words and "budgets" in words
                 and "open" not in section.split("<details", 1)[-1].split(">", 1)[0]
                 and bool(badges) and all(b.startswith("lowest error") for b in badges),
                 "one headline answer: the study's verdict; the per-technique equal-time/error "
                 f"tables ({tables}) are folded in a closed <details> under a heading calling "
                 "them a second view, which says how they differ (series, budgets); the card "
                 "badge says 'lowest error'",
                 f"heading '{heading}', {inside} of {tables} folded, badges {badges[:3]}")


def full_map_counts(results_dir: str) -> tuple[int, int]:
    """Measured runs with and without the runner's HDR-FLIP map vs the full reference on disk
    (among those with a full reference)."""
    with_map = without = 0
    for key, data in results_by_key(results_dir).items():
        if data.get("status") not in ("ok", "nonfinite") or not dig(data, "reference",
                                                                     "full_png"):
            continue
        name = dig(data, "outputs", "flip_full_png")
        folder = os.path.join(results_dir, "runs", key)
        if name and os.path.isfile(os.path.join(folder, name)):
            with_map += 1
        else:
            without += 1
    return with_map, without


def check_map_words(checks: Any, results_dir: str, dom: str) -> None:
    """The images' intro says what the error maps against the full reference are: the
    runner's HDR-FLIP maps for the runs that have them (counted), the report's own
    relative-error words only for the others, and not at all when every run has its map."""
    note = re.search(r'<p class="inspector-note">(.*?)</p>', dom, re.S)
    text = strip_tags(note.group(1)) if note else ""
    with_map, without = full_map_counts(results_dir)
    flip = re.search(r'<span class="flip-maps">(\d+)</span>', note.group(1)) if note else None
    own = re.search(r'<span class="own-maps">(\d+)</span>', note.group(1)) if note else None
    shown = (int(flip.group(1)) if flip else 0, int(own.group(1)) if own else 0)
    fallback = "It is not HDR-FLIP" in text
    checks.check(with_map > 0 and shown == (with_map, without) and fallback == (without > 0)
                 and "HDR-FLIP map" in text,
                 f"the images' intro calls the full-reference error maps HDR-FLIP maps for the "
                 f"{with_map} runs that have one and gives the report's own map's words only "
                 f"for the {without} without",
                 f"counted {shown}, fallback words {fallback}: {text[-400:]}")


def _median(values: list[float]) -> Optional[float]:
    values = sorted(values)
    if not values:
        return None
    mid = len(values) // 2
    return values[mid] if len(values) % 2 else 0.5 * (values[mid - 1] + values[mid])


def scene_floors(results_dir: str) -> dict[str, Optional[float]]:
    """scene -> median HDR-FLIP noise floor vs the full reference of its measured runs."""
    values: dict[str, list[float]] = {}
    for data in results_by_key(results_dir).values():
        if data.get("status") not in ("ok", "nonfinite"):
            continue
        scene = dig(data, "scene", "label")
        floor = dig(data, "metrics", "final_vs_full", "error_bars", "flip", "floor_mean")
        values.setdefault(scene, [])
        if isinstance(floor, (int, float)):
            values[scene].append(float(floor))
    return {scene: _median(v) for scene, v in values.items()}


def check_flip_guide(checks: Any, results_dir: str, dom: str) -> None:
    """A closed guide to HDR-FLIP sits on the first screen (after the verdict, before the
    provenance table): the scale, each scene's noise floor (the median floor_mean of its runs,
    'not recorded' without one) and why HDR-FLIP is about twice LDR FLIP on a dark scene."""
    header = dom.split("</header>", 1)[0]
    at, meta = header.find('id="flip-guide"'), header.find('class="meta"')
    guide = header[at:meta] if 0 <= at < meta else ""
    tag = re.search(r"<details[^>]*id=\"flip-guide\"[^>]*>", header)
    problems = []
    floors = scene_floors(results_dir)
    for scene, floor in floors.items():
        item = re.search(rf'<li data-scene="{re.escape(html.escape(scene))}">(.*?)</li>', guide,
                         re.S)
        if not item:
            problems.append(f"{scene}: not listed")
            continue
        shown = re.search(r'class="floor" data-v="([^"]+)">([^<]+)<', item.group(1))
        value = None if not shown or shown.group(1) == "None" else float(shown.group(1))
        if (floor is None) != (value is None) or (floor is not None and not close(value, floor)) \
                or (floor is None and "not recorded" not in shown.group(2)):
            problems.append(f"{scene}: floor {shown and shown.group(2)}, expected {floor}")
    words = strip_tags(guide)
    checks.check(bool(guide) and tag is not None and " open" not in tag.group(0)
                 and header.find('id="verdict"') < at and not problems
                 and any(f is not None for f in floors.values())
                 and all(w in words for w in ("0 (no visible difference)", "noise floor",
                                              "LDR FLIP", "exposure", "brightened")),
                 "the HDR-FLIP guide (closed, after the verdict, before the provenance) gives "
                 "the scale, each scene's noise floor as recorded by its runs "
                 f"({', '.join(f'{s}: {f}' for s, f in floors.items())}) and why HDR-FLIP "
                 "reads about twice LDR FLIP on a dark scene", "; ".join(problems[:4]))


def check_sweep_noise(checks: Any, results_dir: str, dom: str) -> None:
    """A sweep summary on a scene with a noise floor calls a change of the HDR-FLIP within the
    floor 'unchanged within noise (±floor', and only a larger one a fall or rise; the fixture
    has both (cornell_box: pcf_radius changes by 0.003, cone_count by 0.15; floor 0.02)."""
    floors = scene_floors(results_dir)
    summaries = re.findall(r'<img [^>]*alt="sweep ([^ "]+) ([^"]+) ([^ "]+)"[^>]*></a>'
                           r'<figcaption>.*?<ul class="trend">(.*?)</ul>', dom, re.S)
    within, beyond, problems = 0, 0, []
    for tech, scene, key, items in summaries:
        floor = floors.get(html.unescape(scene))
        if floor is None:
            continue
        for item in re.findall(r"<li>(.*?)</li>", items, re.S):
            words = strip_tags(item).split("; frame time")[0]
            values = [float(v) for v in re.findall(r"\b\d\.\d{4}\b", words)]
            if len(values) < 2:
                continue
            change = abs(values[-1] - values[-2]) if "unchanged" in words else \
                abs(values[1] - values[0])
            if change <= floor:
                within += 1
                if f"unchanged within noise (±{floor:.4f}" not in words:
                    problems.append(f"{tech} {key}: '{words}' (change {change:.4f})")
            else:
                beyond += 1
                if not re.search(r"\b(falls|rises) from", words):
                    problems.append(f"{tech} {key}: '{words}' (change {change:.4f})")
    checks.check(within > 0 and beyond > 0 and not problems,
                 f"sweep summaries: {within} HDR-FLIP changes within the scene's noise floor "
                 f"say 'unchanged within noise (±floor)', {beyond} beyond it fall or rise",
                 "; ".join(problems[:3]))


def _noisy_time(data: dict, animated: bool) -> bool:
    return _noisy(dig(data, "timing", "dynamic_frame_gpu_ms" if animated else "frame_gpu_ms"))


def check_study_noisy(checks: Any, results_dir: str, dom: str) -> None:
    """The study's figures draw a red square (SVG id noisy-time-<key>) on exactly the ranked runs
    whose frame time is noisy, and its equal-time/error tables mark exactly those cells ⚠."""
    runs = results_by_key(results_dir)
    animated = animated_scenes(runs)
    noisy = {k for k, d in runs.items() if d.get("status") == "ok"
             and _noisy_time(d, dig(d, "scene", "label") in animated)}
    fig_dir = os.path.join(results_dir, "figures")
    marked: set[str] = set()
    plotted: set[str] = set()
    for name in os.listdir(fig_dir):
        if name.startswith("study_"):
            with open(os.path.join(fig_dir, name), encoding="utf-8") as f:
                marked |= set(re.findall(r'id="noisy-time-([0-9a-f]+)"', f.read()))
    shown = {html.unescape(s) for s in re.findall(r'<h3 class="study-scene">(.*?)</h3>', dom)}
    plotted = {k for k in noisy if dig(runs[k], "scene", "label") in shown}
    cells = re.findall(r'<table class="data study">.*?</table>', dom, re.S)
    bad = [(k[:8], 'class="noisy"' in v) for t in cells
           for k, v in re.findall(r'<td[^>]*data-key="([^"]+)"[^>]*>(.*?)</td>', t, re.S)
           if ('class="noisy"' in v) != (k in noisy)]
    marked_cells = sum(1 for t in cells for k, v in re.findall(
        r'<td[^>]*data-key="([^"]+)"[^>]*>(.*?)</td>', t, re.S) if 'class="noisy"' in v)
    checks.check(bool(plotted) and marked == plotted and not bad and marked_cells > 0,
                 f"the study marks noisy timings: red squares on the {len(plotted)} noisy runs "
                 f"in its figures, ⚠ in {marked_cells} table cells, nowhere else",
                 f"figures {sorted(marked)}, noisy {sorted(plotted)}, cells {bad[:4]}")


def check_key_params(checks: Any, results_dir: str, dom: str) -> None:
    """Every card shows, outside '+ N more', each parameter whose value differs between the
    runs of its technique (the fixture's tech_b `seed`, not swept, is 1 on one run), and
    hides only the others."""
    runs = results_by_key(results_dir)
    values: dict[str, dict[str, set[str]]] = {}
    for data in runs.values():
        tech = dig(data, "technique", "id")
        for k, v in (dig(data, "technique", "params") or {}).items():
            values.setdefault(tech, {}).setdefault(k, set()).add(json.dumps(v))
    problems, seen = [], 0
    for key, part in cards(dom):
        params = re.search(r'<div class="card-params">(.*?)</div>', part, re.S).group(1)
        if "<details" not in params:
            continue
        seen += 1
        head, hidden = params.split("<details", 1)
        hidden = re.sub(r"<summary>.*?</summary>", " ", "<details" + hidden, flags=re.S)
        tech = dig(runs[key], "technique", "id")
        varying = {k for k, v in values[tech].items() if len(v) > 1}
        shown = set(re.findall(r"([\w.]+)=", strip_tags(head)))
        rest = set(re.findall(r"([\w.]+)=", strip_tags(hidden)))
        if not varying <= shown or rest & varying:
            problems.append(f"{key[:8]} ({tech}): shown {sorted(shown)}, hidden {sorted(rest)}")
    seed_one = [k for k, d in runs.items() if dig(d, "technique", "params", "seed") == 1]
    checks.check(seen > 0 and not problems and bool(seed_one)
                 and any(k == s for k, _ in cards(dom) for s in seed_one),
                 f"every card with '+ N more' ({seen}) shows the parameters that differ between "
                 "its technique's runs (tech_b's seed) and hides only the others",
                 "; ".join(problems[:3]))


def check_header_labels(checks: Any, dom: str) -> None:
    """The header's list of noisy timings never names two runs alike: two noisy tech_a runs on
    cornell_box are told apart by their cone_count."""
    row = re.search(r"<td>noisy timings</td><td>(.*?)</td></tr>", dom, re.S)
    text = strip_tags(row.group(1)) if row else ""
    labels = re.findall(r"(?:: |, )([\w#]+ on [\w#]+(?: \([^)]*=[^)]*\))?) \(", text)
    checks.check(len(labels) >= 2 and len(set(labels)) == len(labels)
                 and "tech_a on cornell_box (cone_count=2)" in labels,
                 f"the header's noisy timings name each run once ({len(labels)}: "
                 f"{', '.join(labels)})", text[:300])


def check_no_absolute_paths(checks: Any, page_path: str, results_dirs: list[str],
                            expected: list[str]) -> None:
    """The page never contains the writing machine's absolute results path; the header's
    results row shows each folder relative to the page (expected)."""
    with open(page_path, encoding="utf-8") as f:
        markup = f.read()
    leaks = [d for d in results_dirs if os.path.abspath(d) in markup]
    row = re.search(r"<td>results</td><td>(.*?)</td></tr>", markup, re.S)
    shown = [strip_tags(p).strip() for p in row.group(1).split("<br>")] if row else []
    checks.check(not leaks and shown == expected,
                 f"no absolute results path on the page; the header shows {expected}",
                 f"leaks {leaks}, header {shown}")
