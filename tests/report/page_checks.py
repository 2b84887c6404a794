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
BASIS_WORDS = {"full": "vs full reference", "matched": "vs bounce-matched reference ("}
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
    metric = "final_vs_full" if basis == "full" else "final"
    return dig(data, "metrics", metric, "flip", "mean")


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
    """Every headline label names the basis; every ranking number comes from that basis; the
    best card is the lowest on it; no table mixes references."""
    runs = results_by_key(results_dir)
    word = BASIS_WORDS[basis]
    shown = cards(dom)
    headlines = [(key, re.search(r'<div class="headline"><span class="basis">(.*?)</span> '
                                 r'<b class="v">([0-9.]+)', part)) for key, part in shown]
    checks.check(bool(shown) and all(m and word in html.unescape(m.group(1))
                                     for _, m in headlines),
                 f"{basis} basis: every image card's headline label names it ('{word}')",
                 str([k for k, m in headlines if not m or word not in m.group(1)][:3]))
    wrong = [k for k, m in headlines if m and not close(
        round(basis_value(runs[k], basis) or -1, 4), float(m.group(2)))]
    checks.check(not wrong, f"{basis} basis: every card's headline number is the run's error "
                 "on that basis", str(wrong[:3]))
    for key, part in shown:
        if 'class="badge b-best"' not in part and "b-tie" not in part.split('card-params')[0]:
            continue
        data = runs[key]
        rivals = [basis_value(d, basis) for d in runs.values() if d.get("status") == "ok"
                  and dig(d, "scene", "label") == dig(data, "scene", "label")
                  and dig(d, "technique", "id") == dig(data, "technique", "id")
                  and (basis == "full" or dig(d, "reference", "matched")
                       == dig(data, "reference", "matched"))]
        if not checks.check(basis_value(data, basis) is not None
                            and basis_value(data, basis) <= min(v for v in rivals if v is not None),
                            f"{basis} basis: best card {key[:8]} has its technique's lowest error"):
            break
    tables = ranking_tables(dom)
    checks.check(bool(tables) and all(b == basis for b, _, _ in tables),
                 f"{basis} basis: {len(tables)} ranking tables, all on it",
                 str({b for b, _, _ in tables}))
    problems = []
    for table_basis, value, markup in tables:
        heads = " | ".join(strip_tags(h) for h in re.findall(r"<th>(.*?)</th>", markup, re.S))
        if word not in heads:
            problems.append(f"header without '{word}': {heads[:120]}")
        cells = re.findall(r'data-key="([^"]+)" data-basis="([^"]+)" data-v="([^"]+)"', markup)
        if not cells:
            problems.append("table without ranked cells")
        references = set()
        for key, cell_basis, v in cells:
            data = runs[key]
            references.add(dig(data, "reference", "matched"))
            expected = (basis_value(data, table_basis) if value == "error"
                        else dig(data, "timing", "frame_gpu_ms", "median"))
            if cell_basis != table_basis or not close(float(v), expected):
                problems.append(f"{key[:8]}: {cell_basis} {v} != {expected}")
        if table_basis == "matched" and len(references) > 1:
            problems.append(f"one table mixes the references {sorted(references)}")
    checks.check(not problems, f"{basis} basis: every ranked number is the run's {basis}-basis "
                 "value (or its frame time) and no table mixes references", "; ".join(problems[:4]))


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
