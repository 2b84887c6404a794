"""The page's section on animated scenes (moving lights or camera): per scene, the cost of a
frame in which something moved (static frame, dynamic frame, the update and its passes), the
error over the measured frames and the temporal instability, the per-frame error and
temporal-instability figures, and a strip of every measured frame of the reference and of
each run. Left out when no run is animated. Every number is described in docs/report.md,
"Animated scenes".
"""
from __future__ import annotations

from typing import Optional

from .analysis import by_scene, by_technique, best_key, ordered_unique, slug
from .common import (DASH, Page, doc_link, esc, fmt_fixed, fmt_flip, fmt_ms, img_html,
                           noisy_mark, params_html, rel_url, swatch, time_with_bar,
                           update_badge)
from .data import Run, Temporal, TimeSummary
from .device import DYNAMIC_FRAME, device_label, device_names, time_label

STRIP_IMAGE_WIDTH = 72  # CSS px of each thumbnail of the frame strip


def animation_anchor(scene: str) -> str:
    return "anim-" + slug(scene)


def animated_scenes(page: Page) -> dict[str, list[Run]]:
    """Scene -> its measured runs, for the scenes with at least one animated run."""
    out = {}
    for scene, runs in by_scene(page.results.runs).items():
        if any(r.animated for r in runs):
            out[scene] = [r for r in runs if r.measured]
    return out


def _ordered(runs: list[Run], page: Page) -> list[Run]:
    """By technique, each technique's best run (on the scene's basis) first."""
    out = []
    for members in by_technique(runs).values():
        basis = page.basis(members[0].scene)
        out += sorted(members, key=lambda r: best_key(r, basis))
    return out


def _time_cell(summary: Optional[TimeSummary], col: str) -> str:
    median = summary.median if summary is not None else None
    iqr = summary.iqr if summary is not None else None
    shown = time_with_bar(median, iqr)
    if summary is not None and summary.source == "cpu" and col != "update":
        shown += ' <span class="pm">(CPU clock)</span>'
    value = "" if median is None else repr(median)
    return f'<td class="n" data-col="{col}" data-v="{value}">{shown}</td>'


def _run_cells(run: Run, page: Page) -> str:
    params = params_html(run, page.distinguishing(run))
    return (f"<td>{swatch(run.technique, page)}</td><td class='params'>{params}</td>"
            f"<td>{update_badge(run) or DASH}</td>")


def cost_table(runs: list[Run], page: Page) -> str:
    """Technique, static frame, dynamic frame, update (CPU clock) and each update pass (median),
    every time header naming the device."""
    passes = ordered_unique([name for r in runs if r.anim is not None
                             for name, _ in r.anim.update_passes])
    heads = ["technique", "parameters", "update kind",
             time_label(runs, "static frame time", dynamic=False) + " ± IQR",
             time_label(runs, "frame time", dynamic=True) + " ± IQR",
             time_label(runs, "update (CPU clock)") + " ± IQR"]
    heads += [time_label(runs, f"update pass {name}, median") for name in passes]
    rows = []
    for run in _ordered(runs, page):
        anim = run.anim
        cells = [_time_cell(run.static, "static"),
                 _time_cell(anim.dynamic if anim else None, "dynamic"),
                 _time_cell(anim.update_cpu if anim else None, "update")]
        own = dict(anim.update_passes) if anim else {}
        spread = anim.update_pass_times if anim else {}
        for name in passes:
            value = own.get(name)
            iqr = spread[name].iqr if name in spread else None
            cells.append(f'<td class="n" data-col="pass" data-v="'
                         f'{"" if value is None else repr(value)}">{fmt_ms(value)}'
                         f'{noisy_mark(value, iqr, True)}</td>')
        rows.append(f'<tr data-key="{esc(run.key)}">{_run_cells(run, page)}{"".join(cells)}'
                    "</tr>")
    head = "".join(f"<th>{esc(h)}</th>" for h in heads)
    return (f'<div class="table-wrap"><table class="data cost" data-device="'
            f'{esc(device_label(runs))}"><caption class="device-line">timed on '
            f'{esc(device_names(runs))}</caption><thead><tr>{head}</tr></thead><tbody>'
            f'{"".join(rows)}</tbody></table></div>')


def _temporal_cell(block: Temporal, col: str) -> str:
    if block.instability is None:
        why = f' title="{esc(block.note)}"' if block.note else ""
        return f'<td class="n" data-col="{col}" data-v=""{why}>{DASH}</td>'
    floor = (f' <span class="pm">floor {fmt_fixed(block.noise_floor, 4)}</span>'
             if block.noise_floor is not None else "")
    quiet = (' <span class="badge b-quiet" title="within the noise floor: no measurable '
             'instability">no measurable instability</span>' if block.within_noise else "")
    p95 = (f'<div class="pm">p95 {fmt_fixed(block.p95, 4)}</div>'
           if block.p95 is not None else "")
    note = f'<div class="pm">{esc(block.note)}</div>' if block.note else ""
    return (f'<td class="n" data-col="{col}" data-v="{block.instability!r}">'
            f"{fmt_fixed(block.instability, 4)}{floor}{quiet}{p95}{note}</td>")


def error_table(runs: list[Run], page: Page, scene: str) -> str:
    """The sequence's errors: the ranking basis (mean over the measured frames vs the full
    reference), the bounce-matched mean, frame 0 vs the full reference, and the temporal
    instability against the full and the bounce-matched reference's frames."""
    basis = page.basis(scene)
    second = basis.matched_view
    heads = ["technique", "parameters", "update kind", "mean " + basis.label("HDR-FLIP"),
             "mean " + second.label("HDR-FLIP"), "frame 0: HDR-FLIP vs full reference",
             "temporal instability vs full reference frames (noise floor, p95)",
             "temporal instability vs bounce-matched reference frames"]
    rows = []
    for run in _ordered(runs, page):
        anim = run.anim
        temporal = anim.temporal if anim else Temporal()
        matched = anim.temporal_matched if anim else Temporal()
        value = basis.flip(run)
        rows.append(
            f'<tr data-key="{esc(run.key)}">{_run_cells(run, page)}'
            f'<td class="n" data-col="basis" data-basis="{esc(basis.name)}" '
            f'data-v="{"" if value is None else repr(value)}">{fmt_flip(value)}</td>'
            f'<td class="n" data-col="matched">{fmt_flip(second.flip(run))}</td>'
            f'<td class="n" data-col="frame0">{fmt_flip(run.vs_full.flip_mean)}</td>'
            f'{_temporal_cell(temporal, "temporal")}{_temporal_cell(matched, "temporal_matched")}'
            "</tr>")
    head = "".join(f"<th>{esc(h)}</th>" for h in heads)
    return (f'<div class="table-wrap"><table class="data sequence-errors"><thead><tr>{head}</tr>'
            f'</thead><tbody>{"".join(rows)}</tbody></table></div>')


def _frame_heads(runs: list[Run]) -> list[str]:
    """'frame 2 · 1.00 s' for each measured frame (from the first run that says)."""
    for run in runs:
        anim = run.anim
        if anim is None or not (anim.measured or anim.sequence):
            continue
        indices = anim.measured or [f.frame for f in anim.sequence]
        times = anim.frame_times()
        out = []
        for i, index in enumerate(indices):
            t = times[i] if i < len(times) else None
            out.append(f"frame {index if index is not None else '?'}"
                       + (f"<br>{t:.2f} s" if t is not None else ""))
        return out
    return []


def frame_strip(runs: list[Run], page: Page, scene: str) -> str:
    """The full reference's measured frames in one row, each run's below (best run of each
    technique first), its temporal map at the end of its row; thumbnails link to the files."""
    references: dict[tuple, Run] = {}
    for run in runs:
        paths = tuple(run.reference_list("frames_png"))
        if paths and paths not in references:
            references[paths] = run
    framed = [r for r in _ordered(runs, page) if r.output_list("frames_png")
              or r.output_path("temporal_png")]
    if not references and not framed:
        return ""
    columns = max([len(p) for p in references] + [len(r.output_list("frames_png"))
                                                  for r in framed] + [0])
    heads = _frame_heads(runs)
    heads += [""] * (columns - len(heads))
    head = ("<tr><th></th>" + "".join(f"<th>{h}</th>" for h in heads[:columns])
            + '<th class="tmap-head">temporal map</th></tr>')
    rows = []
    for paths in references:
        label = ("full reference" if len(references) == 1 else
                 f"full reference ({esc(references[paths].technique)}'s)")
        cells = "".join(f'<td>{img_html(p, page, f"full reference, measured frame {i + 1}", STRIP_IMAGE_WIDTH, "expo", True)}</td>'
                        for i, p in enumerate(paths))
        pad = "".join("<td></td>" for _ in range(columns - len(paths)))
        rows.append(f'<tr class="strip-ref"><th>{label}</th>{cells}{pad}<td class="tmap"></td>'
                    "</tr>")
    for run in framed:
        frames = run.output_list("frames_png")
        cells = "".join(f'<td>{img_html(p, page, f"{run.technique}, measured frame {i + 1}", STRIP_IMAGE_WIDTH, "expo", True)}</td>'
                        for i, p in enumerate(frames))
        pad = "".join("<td></td>" for _ in range(columns - len(frames)))
        tmap = run.output_path("temporal_png")
        tail = (f'<td class="tmap">{img_html(tmap, page, f"{run.technique} temporal map", STRIP_IMAGE_WIDTH, "tmap", True)}</td>'
                if tmap else '<td class="tmap"></td>')
        params = params_html(run, page.distinguishing(run))
        title = (f"{swatch(run.technique, page)} <span class='pm'>{params}</span>"
                 f"<br>{update_badge(run)}")
        rows.append(f'<tr class="strip-run" data-key="{esc(run.key)}"><th>{title}</th>'
                    f"{cells}{pad}{tail}</tr>")
    return (f'<div class="table-wrap"><table class="strip" data-scene="{esc(scene)}"><thead>'
            f'{head}</thead><tbody>{"".join(rows)}</tbody></table></div>')


def _exposure_bar() -> str:
    return ('<div class="exposure-bar"><label>exposure '
            '<input type="range" class="exposure" min="-6" max="6" step="0.25" value="0">'
            '</label><output>+0.00 EV</output><button type="button" class="reset">reset</button>'
            '<span class="note">applied to the frame thumbnails (8-bit sRGB previews), not to '
            'the temporal maps; clipped highlights stay clipped.</span></div>')


def _describe(runs: list[Run]) -> str:
    """'9 frames over 4.0 s, 5 measured (0, 2, 4, 6, 8)' from the first run that says."""
    for run in runs:
        anim = run.anim
        if anim is None:
            continue
        parts = []
        if anim.frames is not None:
            parts.append(f"{anim.frames} frames" + (f" over {anim.duration_s:g} s"
                                                    if anim.duration_s is not None else ""))
        if anim.measured:
            parts.append(f"{len(anim.measured)} measured ("
                         + ", ".join(str(i) for i in anim.measured) + ")")
        if parts:
            return "; ".join(parts)
    return ""


def _figure(path: Optional[str], page: Page, alt: str, caption: str) -> str:
    if not path:
        return ""
    url = rel_url(path, page.out_dir)
    return (f'<figure class="plot"><a href="{url}"><img src="{url}" alt="{esc(alt)}" '
            f'onerror="gilabImageError(this)"></a><figcaption>{caption}</figcaption></figure>')


def _flagged(runs: list[Run], kind: str) -> list[Run]:
    return [r for r in runs if r.anim is not None and r.anim.update == kind]


def scene_animation(scene: str, runs: list[Run], page: Page) -> str:
    basis = page.basis(scene)
    device = device_label(runs)
    rebuilt = _flagged(runs, "full rebuild")
    flags = ""
    if rebuilt:
        names = ", ".join(ordered_unique([swatch(r.technique, page) for r in rebuilt]))
        flags += (f'<p class="warn rebuild">{names}: <b>full rebuild</b> — no real update path; '
                  "the technique rebuilds everything whenever the light or camera moves, so its "
                  "dynamic frame includes its whole set-up work.</p>")
    described = _describe(runs)
    sequence = page.figures.sequence.get(scene)
    temporal = page.figures.temporal.get(scene)
    parts = [f'<section class="scene anim" id="{animation_anchor(scene)}">'
             f"<h3>{esc(scene)}</h3>"
             + (f'<p class="muted">{esc(described)}</p>' if described else "")
             + f'<p class="basis-line">Ranked by <b class="basis">{esc(basis.label())}</b> and '
             f'timed by the <b class="clock">{esc(DYNAMIC_FRAME)}</b> on {esc(device)}.</p>'
             + flags,
             f'<h4>Cost of a frame on {esc(device)}: static frame (nothing moved), dynamic frame '
             "and its update</h4>", cost_table(runs, page),
             "<h4>Error over the sequence</h4>", error_table(runs, page, scene)]
    parts.append(_figure(sequence, page, f"per-frame error, {scene}",
                         f"Mean HDR-FLIP of every measured frame of {esc(scene)} against that "
                         "frame's full reference (left; its mean over the frames is the ranking "
                         "basis) and against its bounce-matched reference (right), one line "
                         "per run."))
    parts.append(_figure(temporal, page, f"temporal instability, {scene}",
                         _temporal_caption(scene, page)))
    strip = frame_strip(runs, page, scene)
    if strip:
        parts.append("<h4>Frames</h4>" + _exposure_bar() + strip)
    parts.append("</section>")
    return "".join(parts)


def _temporal_caption(scene: str, page: Page) -> str:
    return (f"Temporal instability on {esc(scene)}, one bar per run. <b>Definition</b> "
            f"({doc_link(page, 'metrics.md')}, \u201cTemporal instability\u201d): per pixel and "
            "pair of consecutive measured frames, the absolute difference between the "
            "technique's change of luminance and the reference's change, averaged over pixels "
            "and pairs and divided by the reference's mean luminance (0.1 = the change is wrong "
            "by 10 % of the scene's mean brightness per frame). Real changes (the moving light) "
            "are in both and cancel: what remains is flicker, shimmering and lag; a technique "
            "that is wrong by the same amount in every frame scores 0. The <b>hatched part up to "
            "the black tick is the noise floor</b>, what an exact technique scores against the "
            "noisy path-traced reference: <b>a value within the noise floor means no measurable "
            "instability</b> (the technique's change cannot be told from the reference's "
            "noise). ◆ = p95, the 95th percentile of the per-pixel differences over the level "
            "(flicker concentrated in a few places).")


def animation_html(page: Page) -> str:
    scenes = animated_scenes(page)
    scenes = {s: runs for s, runs in scenes.items() if runs}
    if not scenes:
        return ""
    body = "".join(scene_animation(s, runs, page) for s, runs in scenes.items())
    return ('<h2 id="animation">Animated scenes</h2><p>Scenes whose lights or camera move. '
            'Each run renders the animation; the measured frames are compared with the '
            'path-traced reference of the same frame. The <b>ranking basis</b> of such a scene '
            'is the mean HDR-FLIP against the full reference <b>over the measured frames</b> '
            '(<code>metrics.sequence.full_flip_mean</code>), and its rankings, fronts and '
            'error-against-time figures use the time of a <b>dynamic frame</b> (the light or '
            'camera moved and the technique brought its global illumination up to date: the '
            'update is included), not the static frame (nothing moved), which is shown next to '
            'it. The update kind says how a technique follows the motion: '
            '<i>incremental</i> (updates what changed), <i>full rebuild</i> (no real update '
            'path: it redoes its whole set-up every time something moves; flagged) or '
            '<i>none</i> (nothing it precomputes depends on what moved, e.g. only the camera '
            'moved).</p>' + body)
