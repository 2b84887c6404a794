"""The page's short guide to reading HDR-FLIP (a closed <details> under the verdict): its scale,
each scene's noise floor, and why HDR-FLIP reads about twice LDR FLIP on a dark scene
(docs/metrics.md, "Reading HDR-FLIP")."""
from __future__ import annotations

import statistics
from typing import Optional

from .analysis import by_scene, scene_noise_floor
from .common import Page, doc_link, esc, fmt_flip, fmt_sig
from .data import Run, dig, num


def _median(values: list[Optional[float]]) -> Optional[float]:
    kept = [v for v in values if v is not None]
    return statistics.median(kept) if kept else None


def _metric_key(page: Page, scene: str) -> str:
    """result.json's metric set of the scene's ranking basis."""
    return "final" if page.basis(scene).name == "matched" else "final_vs_full"


def _exposures(runs: list[Run], key: str) -> Optional[tuple[float, float]]:
    """The HDR-FLIP exposure range (stops) the scene's reference gave (the same for every run
    compared with it)."""
    for run in runs:
        flip = dig(run.data, "metrics", key, "flip")
        start, stop = num(dig(flip, "start_exposure")), num(dig(flip, "stop_exposure"))
        if start is not None and stop is not None:
            return start, stop
    return None


def scene_line(page: Page, scene: str, runs: list[Run]) -> str:
    """'<b>scene</b>: noise floor …; error bar …; exposures …; direct light alone …'."""
    basis = page.basis(scene)
    measured = [r for r in runs if r.measured]
    floor = scene_noise_floor(measured, basis)
    sigma = _median([basis.flip_sigma(r) for r in measured])
    exposures = _exposures(measured, _metric_key(page, scene))
    direct = [basis.flip(r) for r in measured if r.technique == "direct" and r.status == "ok"]
    parts = [f'noise floor <b class="floor" data-v="{floor!r}">'
             f'{fmt_flip(floor) if floor is not None else "not recorded"}</b>',
             f"error bar ± {fmt_sig(sigma, 2) if sigma is not None else 'not recorded'}"]
    if exposures:
        parts.append(f"HDR-FLIP exposures {exposures[0]:+.2f} … {exposures[1]:+.2f} stops")
    if any(v is not None for v in direct):
        parts.append(f"direct light alone (no indirect light) "
                     f"{fmt_flip(min(v for v in direct if v is not None))}")
    return (f'<li data-scene="{esc(scene)}"><b>{esc(scene)}</b> '
            f'<span class="muted">({esc(basis.label())})</span>: ' + "; ".join(parts) + "</li>")


def flip_guide_html(page: Page) -> str:
    """The guide ('' without measured runs)."""
    scenes = {s: rs for s, rs in by_scene(page.results.runs).items()
              if any(r.measured for r in rs)}
    if not scenes:
        return ""
    lines = "".join(scene_line(page, s, rs) for s, rs in scenes.items())
    return (
        '<details id="flip-guide" class="guide"><summary>How to read HDR-FLIP, the error in '
        'every ranking: its scale, each scene\'s noise floor, and why it is about twice LDR '
        'FLIP on a dark scene</summary>'
        '<p><b>Scale.</b> Per pixel, HDR-FLIP is how different the image looks from the '
        'reference to a viewer flipping between the two, from 0 (no visible difference) to 1 '
        '(the largest: black against white scores 0.967, a uniform step from sRGB grey 0.5 to '
        '0.6 scores 0.285). It is evaluated at several exposures, from the one that brings the '
        'reference\'s brightest pixel to 0.85 up to the one that brings its median there, '
        'keeping each pixel\'s largest value; a number on this page averages it over the '
        'pixels. Two anchors per scene below: the <i>direct light alone</i> (no indirect light '
        'at all) and the <i>noise floor</i> (what an exact image scores); a technique between '
        'them has recovered part of the indirect light.</p>'
        '<p><b>What is noise.</b> The reference is path-traced, so it is noisy: even an exact '
        'image scores the <b>noise floor</b>, the HDR-FLIP of the reference\'s own noise '
        '(<code>error_bars.flip.floor_mean</code>). A difference between two means smaller than '
        'the floor is less than the reference\'s own noise shows, so the sweep summaries call '
        'it unchanged. The <b>error bar</b> (± after a number) is how much a score moves with '
        'another draw of the reference\'s noise; it is far smaller, and decides ties.</p>'
        f'<ul class="floors">{lines}</ul>'
        '<p><b>Why HDR-FLIP reads about twice LDR FLIP on a dark scene.</b> LDR FLIP '
        '(<code>flip_ldr</code>) compares the images as shown at exposure 0, where a dark box '
        'is mostly near black and its differences are crushed. HDR-FLIP\'s exposures start '
        'where the reference\'s brightest pixel reaches 0.85 (the exposure ranges above: '
        'positive on a dark scene), so dark regions are brightened until their differences '
        'show; the maximum over the exposures adds a little more. Measured on the spot-lit '
        'Cornell box, the brightening does most of it: HDR-FLIP at exposure 0 alone scores '
        'about LDR FLIP, at its first exposure alone about 90 % of the full HDR-FLIP ('
        + doc_link(page, "metrics.md") + ', "Reading HDR-FLIP").</p></details>')
