"""The report page: one self-contained HTML file (inline CSS/JS, images by relative path).

Each section is one function returning an HTML string; a section that applies to no run
returns "" and is left out of the page and its navigation. The tables are in tables.py,
the shared helpers in common.py, the image inspector's data in inspector.py.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Optional

from .analysis import (Sweep, best_key, best_runs, by_device, by_scene, param_value,
                             params_text, pareto_fronts, pareto_ties, scene_noise_floor, slug)
from .assets import BODY_JS, CSS, HEAD_JS, INSPECTOR_JS, MAGMA_STOPS
from .animation import animation_anchor, animation_html
from .common import (CARD_IMAGE_WIDTH, DASH, REF_IMAGE_WIDTH, Page, doc_link,
                           esc, fmt_fixed, fmt_flip, fmt_ms, fmt_sig, img_html, noisy_mark,
                           nonfinite_count, params_html, rel_url, scene_anchor, shown_path,
                           status_badge, swatch, time_with_bar, update_badge, with_bar)
from .data import Run, dig, num, text
from .device import (DYNAMIC_FRAME, device_groups, device_label, device_names,
                           dynamic_clock, hosts_of, nodes_phrase, time_label)
from .guide import flip_guide_html
from .inspector import BUDGET_CHARS, MAX_PIXELS, Layer
from .noise import (NOISY_IQR_FRACTION, change_words, noisy_run, noisy_time, tied_best,
                          time_change_words)
from .templates import Markup, render
from .tables import (equal_html, experiment_name, failures_html, footer_html, header_html,
                           invalid_banner_html, run_table_html, skipped_html, unreadable_html)


NOISY_PERCENT = f"{100 * NOISY_IQR_FRACTION:.0f}"

# ---------------------------------------------------------------------------------------------
# Section 2: images per scene
# ---------------------------------------------------------------------------------------------

def _metric_line(label: str, view_flip: Optional[float], sigma: Optional[float],
                 rel_mse: Optional[float], css: str) -> str:
    return (f'<div class="{css}"><span class="basis">{esc(label)}</span> '
            f'<b class="v">{with_bar(fmt_flip(view_flip), sigma, fmt_flip)}</b>'
            f' · relMSE {fmt_sig(rel_mse)}</div>')


def _time_line(css: str, median: Optional[float], iqr: Optional[float], label: str) -> str:
    bar = f' <span class="pm">± {fmt_ms(iqr)}</span>' if iqr is not None else ""
    return (f'<div class="{css}">{fmt_ms(median)}{bar} ms <span class="muted">{esc(label)}'
            f"</span>{noisy_mark(median, iqr)}</div>")


def _card_numbers(run: Run, page: Page, ties: list[Run]) -> str:
    """The headline number (the scene's basis), the frame time (on an animated scene the dynamic
    frame, then the static one), then the bounce-matched view and the direct-light layer, each
    with its label."""
    basis = page.basis(run.scene)
    group = basis.group(run) if basis.name == "matched" else ""
    parts = [_metric_line(basis.label("HDR-FLIP", group), basis.flip(run), basis.flip_sigma(run),
                          basis.rel_mse(run), "headline")]
    parts.append(_time_line("time", run.frame_ms, run.frame_iqr,
                            time_label([run], "frame time", "")))
    if run.dynamic_clock:
        parts.append(_time_line("time static", run.static.median, run.static.iqr,
                                time_label([run], "static frame time", "", dynamic=False)))
    second = basis.matched_view
    if basis.name != "matched" and second.flip(run) is not None:
        parts.append(_metric_line(second.label("HDR-FLIP", run.reference_label()),
                                  second.flip(run), second.flip_sigma(run), second.rel_mse(run),
                                  "second") + '<div class="muted">the error of the light paths '
                     'the technique claims</div>')
    if run.direct.flip_mean is not None:
        parts.append(_metric_line("direct light: HDR-FLIP vs reference emission+direct"
                                  + (" (frame 0)" if run.animated else ""),
                                  run.direct.flip_mean, run.direct.flip_sigma,
                                  run.direct.rel_mse, "second"))
    if ties:
        parts.append(f'<div class="muted">tied within the error bars with {len(ties)} other '
                     f'run{"s" if len(ties) != 1 else ""} of {esc(run.technique)}</div>')
    bad = nonfinite_count(run)
    if bad:
        parts.append(f'<div><b>{int(bad)} NaN/Inf px</b> <span class="muted">(magenta)</span>'
                     '</div>')
    return "".join(parts)


def _exr_link(run: Run, page: Page) -> str:
    path = run.output_path("exr")
    if not path:
        return ""
    if not os.path.isfile(path):
        return f'<span class="muted">EXR missing: {esc(os.path.relpath(path, page.out_dir))}</span>'
    return f'<a class="exr" href="{rel_url(path, page.out_dir)}">output.exr (linear)</a>'


def _exists(path: Optional[str]) -> bool:
    return bool(path) and os.path.isfile(path)


# What the report's own error map is, where the runner wrote no HDR-FLIP map against the full
# reference (inspector.relerr_map).
RELERR_WORDS = ("per pixel |Y(run) − Y(full reference)| / mean Y(full reference), Y the linear "
                "luminance, in magma from 0 to 1 (1: an error as large as the reference's mean "
                "luminance). It is not HDR-FLIP: the runner wrote no FLIP map against the full "
                "reference (outputs.flip_full_png)")


@dataclass
class _Slot:
    """One image of a run card / the references card and its layer in the inspector."""

    layer: Layer
    caption: Optional[str]  # None: only in the inspector, not on the card
    css: str = ""
    tip: str = ""


def _card_slots(run: Run, page: Page) -> tuple[list[_Slot], str]:
    """The run's layers in the inspector's flipping order (run, reference of the headline basis,
    its error map, the bounce-matched error map and reference, the indirect layers), those the
    card shows with a caption; and a note when no error map against the full reference can be
    shown."""
    ins = page.inspector
    basis = page.basis(run.scene)
    label = run.reference_label() or "reference"
    frame0 = " (frame 0)" if run.animated else ""
    run_exr, full_exr = run.output_path("exr"), run.reference_path("full_exr")
    matched_exr = run.reference_path("final_exr")
    lin_run = ins.linear(run_exr) if ins else None
    slots = [_Slot(Layer("run" + frame0, run.output_path("final_png") or "", lin_run,
                         why=ins.why_not(run_exr) if ins else ""), "final" + frame0, "expo")]
    note = ""
    full_png = run.reference_path("full_png")
    if basis.name != "matched" and _exists(full_png):
        lin_full = ins.linear(full_exr) if ins else None
        slots.append(_Slot(Layer("full reference", full_png, lin_full,
                                 why=ins.why_not(full_exr) if ins else ""), None))
        flip_full = run.output_path("flip_full_png")
        made = None
        if _exists(flip_full):
            slots.append(_Slot(Layer("HDR-FLIP vs full reference" + frame0, flip_full,
                                     kind="map", expo=False),
                               f"HDR-FLIP map vs full reference{frame0}", "flipmap errfull"))
        elif ins is not None:
            made = ins.relerr_map(f"{slug(run.key)}_error_vs_full", lin_run, lin_full)
            if made:
                slots.append(_Slot(Layer("error vs full reference" + frame0, made[0],
                                         kind="relerr", expo=False, a=lin_run, b=lin_full,
                                         mean=made[1]),
                                   f"error vs full reference{frame0}: |ΔY| / mean Y, linear "
                                   "(not HDR-FLIP: no FLIP map vs full on disk)",
                                   "flipmap errfull relerr",
                                   RELERR_WORDS))
        if not _exists(flip_full) and not made:
            why = (ins.why_not(run_exr) or ins.why_not(full_exr)) if ins else ""
            note = ('<div class="muted no-full-map">No error map against the full reference: '
                    "the runner wrote none (<code>outputs.flip_full_png</code>) and the report "
                    f"could not draw one from the linear images{': ' + esc(why) if why else ''}"
                    ".</div>")
    slots.append(_Slot(Layer(f"HDR-FLIP vs bounce-matched reference ({label}){frame0}",
                             run.output_path("flip_png") or "", kind="map", expo=False),
                       f"HDR-FLIP map vs bounce-matched reference ({label}){frame0}",
                       "flipmap errmatched"))
    matched_png = run.reference_png()
    if _exists(matched_png):
        lin_matched = ins.linear(matched_exr) if ins else None
        slots.append(_Slot(Layer(f"bounce-matched reference ({label})", matched_png,
                                 lin_matched, why=ins.why_not(matched_exr) if ins else ""),
                           None))
    if run.output_path("indirect_png"):  # its values stay in the EXR (page size)
        slots.append(_Slot(Layer("indirect (this run)", run.output_path("indirect_png"),
                                 why="not embedded (the run's EXR has them: layer indirect)"),
                           "indirect (this run)", "expo indirect"))
        ref_indirect = run.reference_path("indirect_png")
        if ref_indirect:  # older results lack it (the references card says so)
            slots.append(_Slot(Layer(f"reference indirect ({label} − emission − direct)",
                                     ref_indirect, why="8-bit preview only (no EXR of this "
                                     "layer)"),
                               f"reference indirect ({run.reference_label() or 'matched'} − "
                               "emission − direct)", "expo refindirect"))
    return slots, note


def _slot_figures(slots: list[_Slot], page: Page, title: str, width: int, lazy: bool,
                  alt_prefix: str) -> str:
    """The captioned slots as <figure>s; every existing image opens the inspector on its
    layer (group of all the existing slots)."""
    present = [s for s in slots if _exists(s.layer.path)]
    group = page.inspector.group(title, [s.layer for s in present]) if page.inspector and \
        present else None
    out = []
    for slot in slots:
        if slot.caption is None:
            continue
        index = next((i for i, s in enumerate(present) if s is slot), None)
        inspect = (group, index) if group is not None and index is not None else None
        img = img_html(slot.layer.path or None, page, f"{alt_prefix} {slot.caption}", width,
                       slot.css, lazy, inspect)
        tip = f' title="{esc(slot.tip)}"' if slot.tip else ""
        out.append(f'<figure style="width:{width}px">{img}<figcaption{tip}>'
                   f"{esc(slot.caption)}</figcaption></figure>")
    return "".join(out)


def _card(run: Run, page: Page, rank: Optional[int], badge: str, lazy: bool,
          ties: list[Run]) -> str:
    """A run's card: its rank on the scene's basis (None: not ranked, e.g. the other runs of a
    technique), the badge of the overall best, images, numbers and the EXR link."""
    color = page.colors.get(run.technique, "#888")
    badges = f'<span class="rank" title="rank on the scene\'s ranking basis">#{rank}</span>' \
        if rank is not None else ""
    badges += badge
    if run.status != "ok":
        badges += status_badge(run.status)
    if run.final.within_reference_noise:
        badges += '<span class="badge b-noise">within ref. noise</span>'
    badges += update_badge(run)
    slots, note = _card_slots(run, page)
    title = f"{run.technique} on {run.scene}" + (f" ({params_text(run, True)})"
                                                 if run.swept else "")
    pair = _slot_figures(slots, page, title, CARD_IMAGE_WIDTH, lazy, run.technique)
    rank_attr = "" if rank is None else f' data-rank="{rank}"'
    return (f'<div class="card" style="border-top-color:{color}" data-key="{esc(run.key)}"'
            f'{rank_attr}>'
            f'<div class="card-title">{swatch(run.technique, page)}{badges}</div>'
            f'<div class="card-params">{params_html(run, page.distinguishing(run))}</div>'
            f'<div class="pair">{pair}</div>{note}'
            f'<div class="card-nums">{_card_numbers(run, page, ties)}</div>'
            f'<div class="card-links">{_exr_link(run, page)}</div></div>')


def _references_html(runs: list[Run], page: Page) -> str:
    """The full reference first, then each bounce-matched reference used on the scene and the
    full reference's indirect layer (when the runs recorded them)."""
    full: dict[str, Run] = {}
    matched: dict[str, Run] = {}
    indirect: dict[str, Run] = {}
    for run in runs:
        for name, seen in (("full_png", full), ("final_png", matched),
                           ("indirect_full_png", indirect)):
            path = run.reference_path(name)
            if path and path not in seen:
                seen[path] = run
    ins = page.inspector
    slots = []
    for path, run in full.items():
        exr = run.reference_path("full_exr")
        slots.append(_Slot(Layer("full reference", path, ins.linear(exr) if ins else None,
                                 why=ins.why_not(exr) if ins else ""),
                           "full reference (all light paths)", "expo ref-full"))
    for path, run in matched.items():
        ref = run.data.get("reference") if isinstance(run.data.get("reference"), dict) else {}
        detail = []
        if num(ref.get("samples")) is not None:
            detail.append(f"{int(num(ref.get('samples')))} spp")
        if num(ref.get("rel_error")) is not None:
            detail.append(f"rel. error {num(ref.get('rel_error')):.3g}")
        exr = run.reference_path("final_exr")
        label = run.reference_label() or "reference"
        slots.append(_Slot(Layer(label, path, ins.linear(exr) if ins else None,
                                 why=ins.why_not(exr) if ins else ""),
                           label + (f" ({', '.join(detail)})" if detail else ""),
                           "expo ref-matched"))
    for path in indirect:
        slots.append(_Slot(Layer("full reference's indirect", path,
                                 why="8-bit preview only (no EXR of this layer)"),
                           "full reference's indirect (full − emission − direct)",
                           "expo ref-indirect"))
    if not slots:
        return ""
    scene = runs[0].scene if runs else ""
    cards = _slot_figures(slots, page, f"path-traced references of {scene}", REF_IMAGE_WIDTH,
                          False, "reference")
    missing = [what for what, seen in (("the full reference image", full),
                                       ("the reference indirect layers", indirect)) if not seen]
    note = (f'<div class="muted">{" and ".join(missing)} '
            f'{"is" if len(missing) == 1 else "are"} not recorded by these runs (older results)'
            '</div>' if missing else "")
    return ('<div class="card refs" style="border-top-color:#000"><div class="card-title">'
            'path-traced reference</div><div class="pair">' + cards + "</div>"
            + note + "</div>")


def _exposure_bar() -> str:
    gradient = ", ".join(MAGMA_STOPS)
    return ('<div class="exposure-bar"><label>exposure '
            '<input type="range" class="exposure" min="-6" max="6" step="0.25" value="0">'
            '</label><output>+0.00 EV</output><button type="button" class="reset">reset</button>'
            '<span class="note">applied in the browser to the 8-bit sRGB previews as CSS '
            'brightness(2<sup>EV/2.2</sup>), which approximates a change of linear exposure '
            'for mid-tones; clipped highlights stay clipped. Error maps are not affected. '
            'The EXR files hold the linear values (shown by the inspector).</span>'
            f'<span class="colorbar note">error maps 0 <i style="background:linear-gradient('
            f'to right, {gradient})"></i> 1</span></div>')


def _scene_resolution(runs: list[Run]) -> str:
    for run in runs:
        res = dig(run.data, "scene", "resolution")
        if isinstance(res, list) and len(res) == 2:
            return f"{text(res[0])}×{text(res[1])}"
    return ""


def _direct_accuracy_line(runs: list[Run], page: Page) -> str:
    """The shared direct light's own error on this scene (metrics.direct of the `direct` run, else
    of any run): its energy against the path tracer's emission + direct, the light it puts where
    the path tracer has shadow, and its HDR-FLIP, part of every technique's error."""
    ok = [r for r in runs if r.status == "ok" and dig(r.data, "metrics", "direct") is not None]
    if not ok:
        return ""
    run = next((r for r in ok if r.technique == "direct"), ok[0])
    direct = dig(run.data, "metrics", "direct")
    energy, leak = num(dig(direct, "energy_ratio")), num(dig(direct, "shadow_leak"))
    parts = []
    if energy is not None:
        parts.append(f"energy {fmt_fixed(energy, 4)}× the path tracer's emission + direct")
    if leak is not None:
        parts.append(f"{fmt_fixed(100.0 * leak, 2)} % of its light in pixels the path tracer "
                     "has in shadow")
    if run.direct.flip_mean is not None:
        parts.append(f"HDR-FLIP {fmt_flip(run.direct.flip_mean)}")
    if not parts:
        return ""
    return ('<p class="direct-line">Shared direct light (every technique\'s direct layer): '
            + ", ".join(parts) + ". It is part of every technique's error on this scene ("
            + doc_link(page, "shared_passes.md") + ").</p>")


def ranked_bests(measured: list[Run], page: Page, scene: str) -> list[tuple[Run, int, str]]:
    """Each technique's best run (of each reference group on the matched fallback) in rank
    order on the scene's basis, with its rank and group; ranks count within a group (on the
    full basis there is one group: every run is compared with the same reference)."""
    basis = page.basis(scene)
    bests = best_runs(measured, basis)
    group = (lambda r: basis.group(r)) if basis.name == "matched" else (lambda r: "")
    order = sorted(bests, key=lambda r: ((len(group(r)), group(r)), best_key(r, basis)))
    out, seen = [], {}
    for run in order:
        seen[group(run)] = seen.get(group(run), 0) + 1
        out.append((run, seen[group(run)], group(run)))
    return out


def _best_badge(best: Run, rivals: list[Run], page: Page, group: str) -> str:
    """The one badge of a scene (of a reference group on the matched fallback): 'best', or
    'best (tie)' when another technique's best run is within the error bars."""
    basis = page.basis(best.scene)
    ties = tied_best(best, [r for r in rivals if r.status == "ok"], basis.flip,
                     basis.flip_sigma)
    where = f" vs {group}" if group else ""
    if not ties:
        return (f'<span class="badge b-best" title="lowest {esc(basis.label("HDR-FLIP", group))}'
                f' of every technique, at any frame time">lowest error{esc(where)}</span>')
    names = ", ".join(sorted({r.technique for r in ties}))
    return (f'<span class="badge b-best b-tie" title="lowest {esc(basis.label("HDR-FLIP", group))}'
            f', at any frame time, but {esc(names)} within the error bars">lowest error'
            f'{esc(where)} (tie)</span>')


def scene_section(scene: str, runs: list[Run], page: Page) -> str:
    measured = [r for r in runs if r.measured]
    basis = page.basis(scene)
    cards = [_references_html(measured, page)]
    details = []
    ranked = ranked_bests(measured, page, scene)
    winners: dict[str, Run] = {}
    for run, _, group in ranked:
        if run.status == "ok" and group not in winners:
            winners[group] = run
    for best, rank, group in ranked:
        members = [r for r in measured if r.technique == best.technique
                   and basis.group(r) == basis.group(best)]
        ties = tied_best(best, [r for r in members if r.status == "ok"], basis.flip,
                         basis.flip_sigma)
        badge = ""
        if winners.get(group) is best:
            rivals = [r for r, _, g in ranked if g == group and r is not best]
            badge = _best_badge(best, rivals, page, group if len(winners) > 1 else "")
        cards.append(_card(best, page, rank, badge, lazy=False, ties=ties))
        others = sorted((r for r in members if r is not best), key=lambda r: best_key(r, basis))
        if others:
            inner = "".join(_card(r, page, None, "", lazy=True, ties=[]) for r in others)
            details.append(f'<details><summary>show the other {len(others)} run'
                           f'{"s" if len(others) > 1 else ""} of {esc(best.technique)}</summary>'
                           f'<div class="cards">{inner}</div></details>')
    unsupported = [r for r in runs if r.status == "unsupported"]
    note = ""
    if unsupported:
        note = (f'<p class="note">{len(unsupported)} unsupported run(s) on this scene: '
                + "; ".join(f"{esc(r.technique)} ({esc(params_text(r, True)) or DASH}): "
                            f"{esc(r.reason) or DASH}" for r in unsupported) + "</p>")
    invalid = [r for r in runs if r.status == "invalid"]
    if invalid:
        note += (f'<p class="note">{len(invalid)} invalid run(s) on this scene, not shown '
                 '(Vulkan validation messages, see the warning at the top): '
                 + "; ".join(f"{esc(r.technique)} ({esc(params_text(r, True)) or DASH})"
                             for r in invalid) + "</p>")
    title = (f'<h3>{esc(scene)} <span class="muted">{esc(_scene_resolution(runs))}</span>'
             '</h3>')
    if not measured:
        return f'<section class="scene" id="{scene_anchor(scene)}">{title}{note}</section>'
    basis_line = (f'<p class="basis-line">Ranked by <b class="basis">{esc(basis.label())}</b>'
                  + ("" if basis.name != "matched" else
                     " (no full-reference errors recorded: each technique is ranked against its "
                     "own bounce-matched reference only)")
                  + (f' and timed by the <b class="clock">{esc(DYNAMIC_FRAME)}</b>; the images '
                     'are frame 0, every frame is in the <a href="#'
                     f'{animation_anchor(scene)}">animation section</a>'
                     if dynamic_clock(measured) else "")
                  + ". Cards in rank order (#1 first), each technique's lowest-error run; the "
                  "badge marks the lowest error of all, at any frame time"
                  + (" (the verdict at the top weighs frame time too)" if page.study else "")
                  + ".</p>")
    return (f'<section class="scene" id="{scene_anchor(scene)}">{title}{basis_line}'
            f'{_direct_accuracy_line(measured, page)}'
            f'{_exposure_bar()}<div class="cards">{"".join(cards)}</div>{"".join(details)}'
            f'{note}</section>')


def _inspector_words(page: Page) -> str:
    """What the inspector does and how its values are embedded, with this page's numbers."""
    ins = page.inspector
    count = len(ins.images) if ins else 0
    size = (ins.chars / 1024.0) if ins else 0.0
    side = int(MAX_PIXELS ** 0.5)
    skipped = (f" {ins.skipped_budget} more were left out: the page's budget of "
               f"{BUDGET_CHARS // (1024 * 1024)} MiB for them is spent."
               if ins and ins.skipped_budget else "")
    return (f'<b>Click any image</b> to inspect it: nearest-neighbour zoom at the cursor (wheel '
            'or +/−, 0 = fit, drag to pan), flip '
            'between the run, the reference and the error maps of its card (keys 1–9, ← → or '
            'space) and read the <b>linear values</b> under the cursor (on an error map, the '
            'error, with a colour bar). The values come from '
            'the runs\' and references\' EXR files, embedded in this page as float16 RGB '
            f'(base64) for images of at most {side}×{side} pixels: {count} images, '
            f'{size:,.0f} KiB.{skipped} {_full_map_words(page)} A link '
            '<code>report.html#inspect=&lt;run key&gt;</code> opens the inspector on a run.')


def _full_map_runs(page: Page) -> tuple[list[Run], list[Run]]:
    """The measured runs of full-basis scenes with and without the runner's HDR-FLIP map
    against the full reference on disk (outputs.flip_full_png)."""
    runs = [r for r in page.results.runs if r.measured and page.basis(r.scene).name != "matched"
            and _exists(r.reference_path("full_png"))]
    with_map = [r for r in runs if _exists(r.output_path("flip_full_png"))]
    return with_map, [r for r in runs if not _exists(r.output_path("flip_full_png"))]


def _full_map_words(page: Page) -> str:
    """What the error maps against the full reference are on this page: the runner's HDR-FLIP
    maps, and the report's own relative-error map only for the runs without one."""
    with_map, without = _full_map_runs(page)
    if not with_map and not without:
        return ""
    flip = ('the runner\'s HDR-FLIP map (<code>outputs.flip_full_png</code>; magma, 0 = no '
            'visible difference, 1 = maximal)')
    if not without:
        return (f'The error map against the full reference is, on every card '
                f'(<span class="flip-maps">{len(with_map)}</span> runs), {flip}.')
    own = f'the report draws its own: {esc(RELERR_WORDS)}'
    if not with_map:
        return f'No run has an HDR-FLIP map against the full reference, so {own}.'
    scenes: dict[str, int] = {}
    for run in without:
        scenes[run.scene] = scenes.get(run.scene, 0) + 1
    where = ", ".join(f"{n} on {esc(scene)}" for scene, n in scenes.items())
    return (f'The error map against the full reference is {flip} for '
            f'<span class="flip-maps">{len(with_map)}</span> runs; for the '
            f'<span class="own-maps">{len(without)}</span> runs without one ({where}) {own}.')


def scenes_html(page: Page) -> str:
    scenes = by_scene(page.results.runs)
    if not any(r.measured for r in page.results.runs):
        return ""
    body = "".join(scene_section(s, runs, page) for s, runs in scenes.items())
    return ('<h2 id="images">Images</h2><p>Per scene: the path-traced references (the full one, '
            'with all light paths, and the bounce-matched ones the techniques claim), then each '
            'technique\'s best run — lowest mean HDR-FLIP against the <b>full reference</b> — '
            'in rank order, with its error map against the full reference first, then its '
            'HDR-FLIP map against the bounce-matched reference (the light paths it claims), its '
            'indirect layer next to the reference\'s matching indirect layer, and a link to its '
            'linear EXR. The first number of a card is the ranking basis; the bounce-matched '
            'error and the direct-light error (shared by every technique) follow, each '
            'labelled. "lowest error (tie)": another technique\'s best run is within the '
            f'error bars.</p><p class="inspector-note">{_inspector_words(page)}</p>' + body)



# ---------------------------------------------------------------------------------------------
# Sections 4-6: figures
# ---------------------------------------------------------------------------------------------

def figure_html(path: str, page: Page, alt: str, caption: str) -> str:
    url = rel_url(path, page.out_dir)
    return (f'<figure class="plot"><a href="{url}"><img src="{url}" alt="{esc(alt)}" '
            f'onerror="gilabImageError(this)"></a><figcaption>{caption}</figcaption></figure>')


def _front_table(front: list[Run], page: Page, scene: str, group: str, ties: dict[int, Run],
                 compared: list[Run]) -> str:
    """The front's runs, then the runs tied with it (inseparable within IQR and error bars);
    every number in the error column is the scene's one basis (data-basis names it). compared:
    the runs the front was taken over (those of one device when the scene has several)."""
    basis = page.basis(scene)
    runs = page.results.runs
    tied = [r for r in runs if id(r) in ties]
    rows = []
    for run in front + tied:
        tie = ties.get(id(run))
        mark = ("front" if tie is None else f"tie with {esc(params_text(tie, True)) or tie.technique}"
                f" ({esc(tie.technique)})")
        rows.append(f'<tr data-key="{esc(run.key)}"><td>{swatch(run.technique, page)}</td>'
                    f"<td class='params'>{params_html(run, page.distinguishing(run))}</td>"
                    "<td class='n c-time'>"
                    f"{time_with_bar(run.frame_ms, run.frame_iqr)}</td>"
                    f'<td class="n" data-key="{esc(run.key)}" data-basis="{esc(basis.name)}" '
                    f'data-v="{basis.flip(run)!r}">'
                    f"{with_bar(fmt_flip(basis.flip(run)), basis.flip_sigma(run), fmt_flip)}</td>"
                    f"<td>{mark}</td></tr>")
    measured = [r for r in compared if r.measured]
    return (f'<table class="data ranking" data-basis="{esc(basis.name)}" data-value="error">'
            f'<caption class="device-line">timed on {esc(device_names(measured))}</caption>'
            f'<thead><tr><th>technique</th><th>parameters</th>'
            f'<th>{esc(time_label(measured, "frame time"))} ± IQR</th>'
            f'<th>mean {esc(basis.label("HDR-FLIP", group))}</th><th>on the front</th></tr>'
            '</thead><tbody>' + "".join(rows) + "</tbody></table>")


def _mixed_references_note(runs: list[Run], page: Page, scene: str) -> str:
    """Says which bounce-matched references the runs of a scene were compared with."""
    matched: dict[str, list[str]] = {}
    for run in runs:
        if run.measured and run.reference_label():
            techs = matched.setdefault(run.reference_label(), [])
            if run.technique not in techs:
                techs.append(run.technique)
    if len(matched) < 2:
        return ""
    listing = "; ".join(f"{', '.join(swatch(t, page) for t in techs)} → {esc(label)}"
                        for label, techs in matched.items())
    full = page.basis(scene).name == "full"
    return ('<p class="note">The bounce-matched references differ between runs on this scene '
            f'({listing}). A bounce-matched error measures how well a technique renders the '
            'light paths it claims: one that leaves out bounces is not penalised for the missing '
            'light, so the matched rows only rank runs compared with the same reference'
            + ('; the full-reference panels (at the top) and every ranking use the full '
               'reference.' if full else '.')
            + '</p>')


def _timed(runs: list[Run]) -> list[Run]:
    return [r for r in runs if r.measured and r.frame_ms is not None]


def _groups_list(groups: dict[str, list[Run]]) -> str:
    """'A (3 runs on node01, node02); B (1 run on node03)'."""
    return "; ".join(f"<b>{esc(device)}</b> ({len(rs)} run{'s' if len(rs) != 1 else ''}"
                     f"{' ' + esc(nodes_phrase(rs)) if hosts_of(rs) else ''})"
                     for device, rs in groups.items())


def _devices_warning(page: Page) -> str:
    """docs/timing.md: timings from different devices are never mixed without saying so."""
    groups = device_groups(_timed(page.results.runs))
    if len(groups) < 2:
        return ""
    return (f'<p class="warn">These runs were timed on {len(groups)} devices: '
            f'{_groups_list(groups)}. Frame times of different devices are not comparable, so '
            '<b>timings are grouped by device</b>: each figure below has one column of panels '
            'per device, with its own time axis, and the Pareto fronts (their tables, the run '
            'table\'s Pareto column) and the equal-time and equal-error tables compare runs of '
            'one device only. The run table, the sweep and time-per-pass figures and the '
            'animated-scene tables show the devices\' times side by side: their time headers '
            'say "mixed devices" and the run table has a device column.</p>')


def _devices_caption(runs: list[Run]) -> str:
    """What the scene's figure says about devices and nodes ('' for one device on one node)."""
    groups = device_groups(_timed(runs))
    if len(groups) > 1:
        return f" Timings are grouped by device, one column each: {_groups_list(groups)}."
    if len(hosts_of(_timed(runs))) > 1:
        return (f" Timed on {esc(next(iter(groups)))}, the same device model "
                f"{esc(nodes_phrase(_timed(runs)))}.")
    return ""


def _front_tables(page: Page, scene: str, runs: list[Run]) -> str:
    """The Pareto tables under a scene's figure: one per comparable group, of each device apart
    when the runs were timed on several (as the figure's columns; make.page_fronts)."""
    basis = page.basis(scene)
    parts = []
    for device, members in by_device(runs).items():
        ties = pareto_ties(members, basis)
        on = f" on {esc(device)}" if device else ""
        parts += [f'<h4>Pareto-optimal runs{on}: mean <span class="basis">'
                  f'{esc(basis.label("HDR-FLIP", label))}</span></h4>'
                  + _front_table(front, page, scene, label, ties.get(label, {}), members)
                  for label, front in pareto_fronts(members, basis).items()]
    return "".join(parts)


def pareto_html(page: Page) -> str:
    if not page.figures.pareto:
        return ""
    parts = ['<h2 id="pareto">Error against frame time</h2><p>Each point is a run; one colour '
             'per technique. The <b>top row</b> is the ranking basis of the scene (mean HDR-FLIP '
             'and relMSE against the <b>full reference</b>, all light paths, where every run is '
             'comparable); the row below is the second view, against each run\'s bounce-matched '
             'reference (the light paths it claims), and a one-bounce row puts the direct '
             'baseline and one-bounce techniques on one yardstick where both ran. Horizontal '
             'bars span the frame time\'s interquartile range, vertical bars ±1σ of the metric '
             'from the reference\'s noise where measured. The step line is the Pareto front: '
             'the runs (ringed) that no other run compared with the same reference beats in both '
             'error and frame time. A run whose IQR and error bar both overlap a front run\'s '
             'cannot be told apart from it: it is marked as a <b>tie</b> (dashed grey ring), '
             'not as beaten. Axes are logarithmic when the values span more than 10×.</p>'
             + _devices_warning(page)]
    scenes = by_scene(page.results.runs)
    for scene, path in page.figures.pareto.items():
        basis = page.basis(scene)
        parts.append(f"<h3>{esc(scene)}</h3>")
        runs = scenes.get(scene, [])
        several = len(device_groups(_timed(runs))) > 1
        noisy = [r for r in _timed(runs) if noisy_run(r)]
        parts.append(figure_html(path, page, f"error vs frame time, {scene}",
                                 f"{'Top two rows' if several else 'Top row'}: "
                                 f"{esc(basis.label('HDR-FLIP'))} "
                                 f"{'and' if several else '(left) and'} "
                                 f"{esc(basis.label('relMSE'))}{'' if several else ' (right)'} "
                                 f"against median frame time on {esc(scene)}."
                                 + _devices_caption(runs)
                                 + (f" Timed on {esc(device_names(_timed(runs)))}."
                                    if not several else "")
                                 + (f" {_noisy_figure_note(len(noisy))}" if noisy else "")))
        parts.append(_mixed_references_note(runs, page, scene))
        parts.append(_front_tables(page, scene, runs))
    return "".join(parts)


def _noisy_figure_note(count: int) -> str:
    """The caption's word on the noisy-timing marker of a figure."""
    return (f'<span class="noisy">\u26a0 {count} noisy timing{"s" if count != 1 else ""}</span>'
            f' (a red square in the figure: frame-time IQR above {NOISY_PERCENT} % of its '
            'median, '
            'see <a href="#noisy-timings">noisy timings</a>).')


def _series_name(sweep: Sweep, others: tuple) -> str:
    return ", ".join(f"{k}={v}" for k, v in zip(sweep.other_keys, others)) or "all runs"


def study_spreads(page: Page, technique: str) -> tuple[float, Optional[float]]:
    """The technique's seed spread of HDR-FLIP (0 when not run) and relative between-run
    spread of the frame time (None when not measured) from the cross-technique study."""
    for study in page.study:
        if technique in study.seed_spread or technique in study.time_spread:
            return study.seed_spread.get(technique, 0.0), study.time_spread.get(technique)
    return 0.0, None


def sweep_summary(sweep: Sweep, page: Page) -> str:
    """Per series: how the headline error and the frame time change from the smallest to the
    largest value of the swept key, called a change only beyond the noise: the scene's noise
    floor, the error bars and seed spread (error), the IQRs and run-to-run spread (time)."""
    basis = page.basis(sweep.scene)
    floor = scene_noise_floor(by_scene(page.results.runs).get(sweep.scene, []), basis)
    seeds, spread = study_spreads(page, sweep.technique)
    items = []
    for others, members in sweep.series.items():
        ok = [r for r in members if r.status == "ok" and basis.flip(r) is not None]
        if len(ok) < 2:
            continue
        first, last = ok[0], ok[-1]
        error = change_words(basis.flip(first), basis.flip_sigma(first), basis.flip(last),
                             basis.flip_sigma(last), fmt_flip, floor, seeds)
        items.append(f"<li>{esc(_series_name(sweep, others))}: from {esc(sweep.key)}="
                     f"{esc(text(param_value(first, sweep.key)))} to "
                     f"{esc(text(param_value(last, sweep.key)))}, "
                     f"{esc(basis.label('HDR-FLIP'))} {esc(error)}; frame time "
                     f"{esc(time_change_words(first, last, fmt_ms, spread))}"
                     + "".join(f" ({esc(sweep.key)}={esc(text(param_value(r, sweep.key)))}:"
                               f"{noisy_mark(r.frame_ms, r.frame_iqr)})" for r in (first, last)
                               if noisy_run(r))
                     + "</li>")
    return f'<ul class="trend">{"".join(items)}</ul>' if items else ""


def no_effect_html(page: Page) -> str:
    if not page.figures.no_effect:
        return ""
    items = "".join(f'<li class="no-effect">{swatch(s.technique, page)} on {esc(s.scene)}: '
                    f'<b>{esc(s.key)}</b> has <b>no effect on this scene</b> ({esc(why)}); no '
                    'figure is drawn.</li>' for s, why in page.figures.no_effect)
    return f'<h3 id="no-effect">Swept parameters without effect</h3><ul>{items}</ul>'


def sweeps_html(page: Page) -> str:
    if not page.figures.sweeps and not page.figures.no_effect:
        return ""
    parts = ['<h2 id="sweeps">Parameter sweeps</h2><p>Runs of one technique on one scene that '
             'differ in a swept parameter: the scene\'s ranking error (HDR-FLIP vs the full '
             'reference), the bounce-matched error, relMSE and the frame time (bars: its IQR) '
             'against that parameter. For grids, one line per value of the other swept '
             'parameter(s), light to dark. ✕ marks a run with non-finite output. A change is '
             'only called a rise or a fall when it is larger than the noise: for the error, the '
             'scene\'s noise floor (the HDR-FLIP of the reference\'s own noise, see the '
             '<a href="#flip-guide">guide to HDR-FLIP</a>) or the two ends\' error bars and '
             'seed spread, whichever is larger; for the time, their IQRs and the technique\'s '
             'run-to-run spread. Anything smaller is "unchanged within noise (±band)". A '
             'parameter whose runs give identical images is '
             'reported as having no effect on the scene.</p>']
    all_sweeps = [s for s, _ in page.figures.sweeps] + [s for s, _ in page.figures.no_effect]
    for sweep, path in page.figures.sweeps:
        n = sum(len(m) for m in sweep.series.values())
        others = (f"; one line per {esc(', '.join(sweep.other_keys))}" if sweep.other_keys
                  else "")
        apart = {s.keys for s in all_sweeps if s.technique == sweep.technique
                 and s.scene == sweep.scene}
        alone = (f" One of {len(apart)} separate sweeps of {esc(sweep.technique)} on this "
                 f"scene; this one sweeps {esc(' × '.join(sweep.keys))} only."
                 if len(apart) > 1 else "")
        noisy = [r for m in sweep.series.values() for r in m if r.measured and noisy_run(r)]
        flag = (f" {_noisy_figure_note(len(noisy))}" if noisy else "")
        parts.append(figure_html(
            path, page, f"sweep {sweep.technique} {sweep.scene} {sweep.key}",
            f"{swatch(sweep.technique, page)} on {esc(sweep.scene)}: "
            f"<b>{esc(sweep.key)}</b> ({n} runs{others}).{alone}{flag}"
            + sweep_summary(sweep, page)))
    parts.append(no_effect_html(page))
    return "".join(parts)


def passes_html(page: Page) -> str:
    if not page.figures.passes:
        return ""
    device = device_label([r for r in page.results.runs if r.measured])
    parts = ['<h2 id="passes">Time per pass</h2><p>For each technique\'s best run per scene: '
             f'the median time of every pass of a frame on {esc(device)}, stacked (left), and '
             'the one-time set-up cost by stage, wall clock (right). Totals above the bars.</p>']
    scenes = by_scene(page.results.runs)
    for scene, path in page.figures.passes.items():
        parts.append(f"<h3>{esc(scene)}</h3>")
        best = best_runs(scenes.get(scene, []), page.basis(scene))
        noisy = any(noisy_time(t.median, t.iqr) for r in best for _, t in r.pass_times()) or \
            any(noisy_time(r.static.median, r.static.iqr) for r in best)
        flag = (' <span class="noisy">\u26a0 noisy timings</span> are marked: a hatched pass '
                f'has an IQR above {NOISY_PERCENT} % of its median; a total with * is a frame '
                'time whose IQR is (see <a href="#noisy-timings">noisy timings</a>).'
                if noisy else "")
        parts.append(figure_html(path, page, f"time per pass, {scene}",
                                 f"Per-pass time ({esc(device)}) and set-up time on {esc(scene)}"
                                 f", timed on {esc(device_names(best))}.{flag}"))
    return "".join(parts)


# ---------------------------------------------------------------------------------------------
# The page
# ---------------------------------------------------------------------------------------------

NAV_TITLES = (("study", "Study"), ("equal", "Equal time/error"), ("images", "Images"),
              ("animation", "Animation"), ("runs", "All runs"), ("pareto", "Error vs. time"),
              ("sweeps", "Sweeps"),
              ("passes", "Time per pass"), ("skipped", "Skipped passes"),
              ("unreadable", "Unreadable"), ("definitions", "Definitions"))


def inspector_html(page: Page) -> str:
    """The inspector's (hidden) overlay and its data; '' when no image can be inspected."""
    ins = page.inspector
    if ins is None or not ins.groups:
        return ""
    payload = ins.payload(lambda path: rel_url(path, page.out_dir))
    return ('<div id="inspector" class="inspector" hidden role="dialog" '
            'aria-label="image inspector" tabindex="-1"><div class="ins-bar">'
            '<b class="ins-title"></b><span class="ins-layers"></span>'
            '<span class="ins-zoom"><button type="button" data-zoom="out" title="zoom out (−)">'
            '−</button><output class="ins-factor">1×</output><button type="button" '
            'data-zoom="in" title="zoom in (+)">+</button><button type="button" data-zoom="fit" '
            'title="fit (0)">fit</button></span><a class="ins-file" href="#">open the file</a>'
            '<button type="button" class="ins-close" title="close (Esc)">close</button></div>'
            '<div class="ins-view"><img class="ins-img" alt="" draggable="false"></div>'
            '<div class="ins-status"><span class="ins-pos">move the cursor over the image'
            '</span> <span class="ins-value"></span><div class="ins-more"></div></div>'
            '<div class="ins-help">keys: 1–9 a layer · ← → or space: previous / next layer · '
            'wheel or + / − over the image: zoom at the cursor (nearest neighbour) · drag: pan · '
            '0: fit · Esc: close. Values: linear RGB from the EXR files (float16, so about 3 '
            'significant digits); on an error map, its value (HDR-FLIP maps to ±0.002, read back '
            'from the map\'s colours; the report\'s own map computed from the linear images), '
            'with the colour bar above the image.</div></div>'
            f'<script type="application/json" id="gilab-inspector">{payload}</script>'
            '<pre id="inspector-selftest-result" hidden></pre>')


def study_html(page: Page) -> str:
    """The cross-technique study section (study_html), one block per device model;
    '' when it does not apply."""
    from .study_html import series_colors, study_section_html

    blocks = []
    for study in page.study:
        keys = {r.get("key") for r in study.rows}
        measured = [r for r in page.results.runs if r.measured and r.frame_ms is not None
                    and r.key in keys]
        count = len(page.study)
        figures = {scene: page.figures.study[k] for scene in study.scenes
                   for k in [scene if count < 2 else f"{scene} on {study.device}"]
                   if k in page.figures.study}
        block = study_section_html(study, series_colors(study.series, page.colors), figures,
                                   lambda p: rel_url(p, page.out_dir),
                                   device_label(measured or page.results.runs),
                                   first=not blocks)
        if block:
            blocks.append(block)
    return "".join(blocks)


def verdict_html(page: Page) -> str:
    """The first screen's verdict table of the first device model's study ('' without one)."""
    from .study_html import series_colors, verdict_screen_html

    for study in page.study[:1]:
        return verdict_screen_html(study, series_colors(study.series, page.colors))
    return ""


def render_page(page: Page) -> str:
    study = study_html(page)
    sections = [invalid_banner_html(page), study, equal_html(page, folded=bool(study)),
                scenes_html(page),
                animation_html(page), run_table_html(page) + failures_html(page),
                pareto_html(page), sweeps_html(page), passes_html(page), skipped_html(page),
                unreadable_html(page)]
    body = "".join(sections)
    if not page.results.runs:
        body = ('<div class="empty" id="empty">No finished runs in '
                + ", ".join(f"<code>{esc(shown_path(d, page))}</code>"
                            for d in page.results.dirs)
                + ". Run the experiment first (<code>gilab run CONFIG</code>); runs in progress "
                "(folders starting with '.') are not shown.</div>") + unreadable_html(page)
    nav = [(i, t) for i, t in NAV_TITLES if f'id="{i}"' in body or i == "definitions"]
    header = header_html(page, verdict_html(page) + flip_guide_html(page))
    return render("page.html.j2", title=f"gilab report — {experiment_name(page.results)}",
                  css=Markup(CSS), head_js=Markup(HEAD_JS), header=Markup(header), nav=nav,
                  body=Markup(body), footer=Markup(footer_html(page)),
                  inspector=Markup(inspector_html(page)), body_js=Markup(BODY_JS),
                  inspector_js=Markup(INSPECTOR_JS))
