"""The report's tables: the header, the run table, equal-time and equal-error tables, skipped
passes, unreadable folders, definitions and provenance. Each function returns an HTML string, ""
when the table applies to no run.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Callable, Optional

from .analysis import (MIN_COMPARED, best_within_budget, by_device, by_scene,
                             by_technique, cheapest_reaching, comparable_groups, error_targets,
                             ordered_unique, params_text, slug, time_budgets)
from .common import (DASH, MIB, Page, distinct_labels, doc_link, esc, first_message_html,
                           fmt_fixed, fmt_flip, fmt_ms, fmt_sig, noisy_mark, nonfinite_count,
                           params_html, rel_url, shown_path, status_badge, swatch,
                           time_with_bar, update_badge, validation_summary, with_bar)
from .data import Results, Run, dig, num, text
from .device import (device_group, device_groups, device_names, device_note_html,
                           time_label)
from .noise import NOISY_IQR_FRACTION, error_separable, noisy_time, time_separable
from .templates import Markup, render


# ---------------------------------------------------------------------------------------------
# Header
# ---------------------------------------------------------------------------------------------

def _counted(values: list[str]) -> str:
    counts: dict[str, int] = {}
    for v in values:
        if v:
            counts[v] = counts.get(v, 0) + 1
    if not counts:
        return DASH
    return "; ".join(f"{esc(v)} <span class='muted'>({n} run{'s' if n != 1 else ''})</span>"
                     for v, n in sorted(counts.items(), key=lambda kv: -kv[1]))


def _experiment_field(page: Page, name: str) -> list[str]:
    return ordered_unique([text(e.get(name)) for e in page.results.experiments if e.get(name)])


def experiment_name(results: Results) -> str:
    names = ordered_unique([text(e.get("name")) for e in results.experiments if e.get("name")])
    if not names:
        names = ordered_unique([text(r.data.get("experiment")) for r in results.runs
                                if r.data.get("experiment")])
    if not names:
        names = [os.path.basename(d.rstrip("/")) for d in results.dirs]
    return " + ".join(names)


def header_html(page: Page, verdict: str = "") -> str:
    """The title, the experiment's description, then `verdict` (the study's first screen), then
    the provenance table."""
    res = page.results
    runs = res.runs
    rows: list[tuple[str, str]] = []
    descriptions = _experiment_field(page, "description")
    dates = sorted(r.date for r in runs if r.date)
    if dates:
        rows.append(("runs dated", esc(dates[0]) if dates[0] == dates[-1]
                     else f"{esc(dates[0])} … {esc(dates[-1])}"))
    rows.append(("git commits", _counted([text(dig(r.data, "provenance", "git_commit"))
                                          for r in runs])))
    devices = []
    for r in runs:
        name = text(dig(r.data, "device", "name"))
        driver = text(dig(r.data, "device", "driver_info")) or text(dig(r.data, "device", "driver"))
        devices.append(f"{name} ({driver})" if name and driver else name)
    rows.append(("devices", _counted(devices)))
    rows.append(("hosts", _counted([r.host for r in runs])))
    configs = [f"{esc(p)}" for p in _experiment_field(page, "config_path")]
    hashes = _experiment_field(page, "config_hash")
    if configs or hashes:
        rows.append(("config", ", ".join(configs) +
                     (f" <span class='muted'>hash {esc(', '.join(hashes))}</span>"
                      if hashes else "")
                     + (" <b>(shards disagree on the config hash)</b>" if len(hashes) > 1 else "")))
    overhead = _instrumentation(page)
    if overhead:
        rows.append(("timer overhead", overhead))
    note = device_note_html([r for r in runs if r.measured])
    if note:
        rows.append(("timings", f'<span class="device-note">{note}</span>'))
    noisy = noisy_summary(page)
    if noisy:
        rows.append(("noisy timings", noisy))
    rows.append(("results", "<br>".join(esc(shown_path(d, page)) for d in res.dirs)))
    rows.append(("runs", counts_html(page)))
    return render("header.html.j2", name=experiment_name(res), descriptions=descriptions,
                  verdict=Markup(verdict), rows=[(k, Markup(v)) for k, v in rows])


def noisy_timings(runs: list[Run]) -> list[tuple[Run, str, float, float]]:
    """(run, what, median, IQR) of every frame time of the measured runs whose IQR is above
    NOISY_IQR_FRACTION of its median: the static frame and, on animated scenes, the dynamic
    one."""
    out = []
    for run in runs:
        if not run.measured:
            continue
        times = [("frame time", run.static)]
        if run.anim is not None:
            times.append(("dynamic frame time", run.anim.dynamic))
        out += [(run, what, t.median, t.iqr) for what, t in times
                if noisy_time(t.median, t.iqr)]
    return out


def noisy_summary(page: Page) -> str:
    """The header's line on noisy frame times ('' when none)."""
    runs = page.results.runs
    noisy = noisy_timings(runs)
    if not noisy:
        return ""
    timed = sum(1 for r in runs if r.measured and r.static.median is not None)
    labels = distinct_labels([r for r, *_ in noisy], lambda r: f"{r.technique} on {r.scene}")
    items = ", ".join(f"{esc(label)} ({what} {fmt_ms(m)} ± {fmt_ms(i)} ms, IQR "
                      f"{100 * i / m:.0f} %)"
                      for label, (r, what, m, i) in zip(labels[:8], noisy[:8]))
    more = f" and {len(noisy) - 8} more" if len(noisy) > 8 else ""
    return (f'<span class="noisy">\u26a0 {len(noisy)} noisy timing'
            f'{"s" if len(noisy) != 1 else ""}</span> of {timed} timed runs: {items}{more}. '
            f"Their IQR is above {100 * NOISY_IQR_FRACTION:.0f} % of the median; each is marked "
            "\u26a0 in every table and figure that shows the run's own time (the study's too), "
            "not in summaries over several runs (verdict, ladder reach, whole cost) "
            '(<a href="#noisy-timings">why</a>).')


def _instrumentation(page: Page) -> str:
    """experiment.json's measured cost of the timestamp queries (docs/timing.md, rule 6)."""
    parts = []
    for experiment in page.results.experiments:
        probe = experiment.get("instrumentation")
        if not isinstance(probe, dict):
            continue
        if probe.get("skipped"):
            parts.append(f"not measured: {esc(probe.get('skipped'))}")
            continue
        ms, iqr = num(probe.get("overhead_ms")), num(probe.get("overhead_iqr_ms"))
        where = (f"<span class='muted'>({esc(probe.get('technique'))} on "
                 f"{esc(probe.get('scene'))}, CPU frame time with − without timestamp "
                 "queries)</span>")
        if ms is not None and (iqr is None or abs(ms) > iqr):
            parts.append(f"{with_bar(fmt_ms(ms), iqr, fmt_ms)} ms per frame {where}")
        elif ms is not None:
            parts.append(f"not measurable: the difference is within its IQR (± {fmt_ms(iqr)} "
                         f"ms) {where}")
    return "; ".join(ordered_unique(parts))


def counts_html(page: Page) -> str:
    res = page.results
    parts = []
    for status in ("ok", "nonfinite", "unsupported", "invalid"):
        n = sum(1 for r in res.runs if r.status == status)
        if n or status != "invalid":  # invalid only when there are any
            parts.append(f"{status_badge(status)} {n}")
    if res.unreadable:
        parts.append(f'{status_badge("unreadable")} {len(res.unreadable)}')
    totals = [num(e.get("runs_total")) for e in res.experiments]
    totals = [int(t) for t in totals if t is not None]
    found = len(res.runs) + len(res.unreadable)
    total = f" of {max(totals)} configured" if totals else ""
    extra = f" ({res.duplicates} duplicate{'s' if res.duplicates != 1 else ''} merged)" \
        if res.duplicates else ""
    return (f'<span class="counts"><b>{found}</b> run folders{total}{extra}: '
            + " ".join(f"<span>{p}</span>" for p in parts) + "</span>")


# ---------------------------------------------------------------------------------------------
# Section 3: the run table
# ---------------------------------------------------------------------------------------------

@dataclass
class Column:
    id: str
    title: str
    tip: str
    cell: Callable[[Run], tuple[str, object]]  # -> (inner HTML, sort value or None)
    numeric: bool = True
    css: str = "n"


def _n(value: Optional[float], shown: str) -> tuple[str, object]:
    return shown, value


def _region_columns(runs: list[Run]) -> list[Column]:
    names = ordered_unique([n for r in runs for n in r.regions])
    return [Column(f"region_{slug(n)}", f"FLIP [{n}]", f"mean FLIP of the final image over the "
                   f"region '{n}'",
                   lambda r, n=n: _n(r.regions[n].flip_mean if n in r.regions else None,
                                     fmt_flip(r.regions[n].flip_mean) if n in r.regions else DASH))
            for n in names]


def _passes_cell(run: Run) -> tuple[str, object]:
    passes = run.pass_times()
    if not passes:
        return DASH, None
    total = sum(t.median for _, t in passes if t.median is not None)
    body = " · ".join(f'<span class="pass">{esc(n)}&nbsp;{fmt_ms(t.median)}'
                      f'{noisy_mark(t.median, t.iqr, True)}</span>' for n, t in passes)
    return body, total


def _memory_cell(run: Run) -> tuple[str, object]:
    total = num(dig(run.data, "memory", "total_bytes"))
    peak = num(dig(run.data, "memory", "peak_bytes"))
    if total is None:
        return DASH, None
    shown = f"{total / MIB:.1f}"
    if peak is not None and peak > total:
        shown += f' <span class="pm">peak {peak / MIB:.1f}</span>'
    return shown, total


def _frame_cell(run: Run) -> tuple[str, object]:
    """The static frame (on an animated scene too: the dynamic one has its own column)."""
    frame = run.static
    shown = time_with_bar(frame.median, frame.iqr)
    if frame.source == "cpu":
        shown += ' <span class="pm">(CPU clock)</span>'
    return shown, frame.median


def _dynamic_cell(run: Run) -> tuple[str, object]:
    frame = run.anim.dynamic if run.anim is not None else None
    if frame is None or frame.median is None:
        return DASH, None
    shown = time_with_bar(frame.median, frame.iqr)
    if frame.source == "cpu":
        shown += ' <span class="pm">(CPU clock)</span>'
    shared, own = run.anim.dynamic_shared.median, run.anim.dynamic_technique.median
    if shared is not None and own is not None:
        shown += (f' <span class="pm">(shared passes {shared:.3g} ms, technique {own:.3g} ms)'
                  '</span>')
    return shown, frame.median


def _update_cell(run: Run) -> tuple[str, object]:
    kind = run.anim.update if run.anim is not None else ""
    return (update_badge(run), kind) if kind else (DASH, None)


def _sequence_cell(run: Run) -> tuple[str, object]:
    anim = run.anim
    value = anim.full_flip_mean if anim is not None else None
    if value is None:
        return DASH, None
    n = anim.measured_count
    return (fmt_flip(value) + (f' <span class="pm">({n} frames)</span>' if n else ""), value)


def _temporal_cell(run: Run) -> tuple[str, object]:
    block = run.anim.temporal if run.anim is not None else None
    if block is None or block.instability is None:
        return DASH, None
    shown = fmt_fixed(block.instability, 4)
    if block.noise_floor is not None:
        shown += f' <span class="pm">floor {fmt_fixed(block.noise_floor, 4)}</span>'
    if block.within_noise:
        shown += ' <span class="badge b-quiet">within noise</span>'
    return shown, block.instability


def _status_cell(run: Run) -> tuple[str, object]:
    shown = status_badge(run.status)
    if run.reason:
        shown += f'<div class="reason">{esc(run.reason)}</div>'
    if run.status == "invalid":
        shown += f'<div class="reason">{validation_summary(run)}</div>'
    return shown, run.status


def _noise_cell(run: Run) -> tuple[str, object]:
    if not run.final.bars_available:
        return DASH, None  # no error bars: the column is dropped when no run has them
    hits = [name for name, hit in (("MSE", run.final.within_reference_noise),
                                   ("FLIP", run.final.flip_within_noise)) if hit]
    if not hits:
        return "no", 0
    return f'<span class="badge b-noise">{" + ".join(hits)}</span>', len(hits)


def _reference_cell(run: Run) -> tuple[str, object]:
    label = run.reference_label()
    spp = num(dig(run.data, "reference", "samples"))
    if not label and spp is None:
        return DASH, None
    shown = esc(label) + (f' <span class="pm">{int(spp)} spp</span>' if spp is not None else "")
    return shown, label


def _front_cell(run: Run, page: Page) -> tuple[str, object]:
    if page.on_front(run):
        return '<span class="badge b-front">front</span>', 2
    if page.tie_of(run) is not None:
        return '<span class="badge b-tie">tie</span>', 1
    return "", 0


def _exr_cell(run: Run, page: Page) -> tuple[str, object]:
    path = run.output_path("exr")
    if not path:
        return DASH, None
    if not os.path.isfile(path):
        return '<span class="muted">missing</span>', None
    return f'<a class="exr" href="{rel_url(path, page.out_dir)}">EXR</a>', "exr"


def _flip_cell(view: Callable[[Run], object]) -> Callable[[Run], tuple[str, object]]:
    def cell(run: Run) -> tuple[str, object]:
        m = view(run)
        return _n(m.flip_mean, with_bar(fmt_flip(m.flip_mean), m.flip_sigma, fmt_flip))
    return cell


def _relmse_cell(view: Callable[[Run], object]) -> Callable[[Run], tuple[str, object]]:
    def cell(run: Run) -> tuple[str, object]:
        m = view(run)
        return _n(m.rel_mse, with_bar(fmt_sig(m.rel_mse), m.rel_mse_sigma, fmt_sig))
    return cell


def _device_columns(measured: list[Run]) -> list[Column]:
    """A device column when the runs were timed on more than one device model."""
    if len(device_groups([r for r in measured if r.frame_ms is not None])) < 2:
        return []
    return [Column("device", "device (node)", "the device model the run's times were measured "
                   "on (device.name, device.type), and the node it ran on (host)",
                   lambda r: (esc(device_group(r)) + (f' <span class="muted">({esc(r.host)})'
                                                      '</span>' if r.host else ""),
                              device_group(r)), False, "")]


def run_columns(page: Page) -> list[Column]:
    """The run table's columns: identity, error (full reference first: the ranking basis),
    then cost; those no run has are dropped."""
    runs = page.results.runs
    measured = [r for r in runs if r.measured]
    animated = [r for r in measured if r.animated]
    frame = time_label(measured, "static frame time" if animated else "frame time",
                       dynamic=False)
    cols = [
        Column("technique", "technique", "technique id",
               lambda r: (swatch(r.technique, page), r.technique), False, "tech"),
        Column("index", "#", "run index in the experiment", lambda r: _n(r.index, text(r.index))),
        Column("scene", "scene", "scene label", lambda r: (esc(r.scene), r.scene), False, ""),
        Column("params", "parameters", "technique parameters: the swept ones and those that "
               "differ between runs of the technique, the others one click away",
               lambda r: (params_html(r, page.distinguishing(r)), params_text(r)), False,
               "params"),
        Column("status", "status", "ok / nonfinite / unsupported (with the reason) / invalid "
               "(Vulkan validation reported errors or warnings: numbers not trusted, not ranked)",
               _status_cell, False, "reason"),
        *_device_columns(measured),
        Column("frame", f"{frame} ± IQR", "median frame time over the timed frames ± IQR "
               "(sum of the passes' timestamps on the device named)"
               + ("; on an animated scene the static frame (nothing moved)" if animated else ""),
               _frame_cell),
        Column("dynamic_frame", f"{time_label(animated, 'frame time', dynamic=True)} ± IQR",
               "animated scenes: median time of a frame in which the light or camera moved, the "
               "technique's update included (timing.dynamic_frame_gpu_ms, else _cpu_ms); the "
               "time the scene's rankings use. In brackets its GPU time split: the shared "
               "passes every technique pays (G-buffer, shadow maps and cascades re-rendered "
               "after a camera move, direct light) and the technique's own passes",
               _dynamic_cell),
        Column("update", "update kind", "animated scenes: how the technique follows the motion "
               "(incremental / full rebuild: no real update path / none)", _update_cell, False,
               ""),
        Column("flip_sequence", "HDR-FLIP vs full reference, mean over the measured frames",
               "animated scenes: mean HDR-FLIP against each measured frame's full reference "
               "(metrics.sequence.full_flip_mean): the scene's ranking basis (↓)",
               _sequence_cell),
        Column("temporal", "temporal instability vs full reference frames", "animated scenes: "
               "how wrong the frame-to-frame change is, relative to the mean level, with the "
               "reference's noise floor (docs/metrics.md); within the floor = no measurable "
               "instability (↓)", _temporal_cell),
        Column("flip_full", "HDR-FLIP vs full reference", "mean HDR-FLIP of the final image "
               "against the full reference (all light paths): the ranking basis (↓)",
               _flip_cell(lambda r: r.vs_full)),
        Column("relmse_full", "relMSE vs full reference", "relMSE against the full reference "
               "(↓); ± 1σ", _relmse_cell(lambda r: r.vs_full)),
        Column("flip", "HDR-FLIP vs bounce-matched reference", "mean HDR-FLIP of the final image "
               "against the bounce-matched reference (the light paths the technique claims, see "
               "the reference column) (↓); ± 1σ from the reference's noise",
               _flip_cell(lambda r: r.final)),
        Column("relmse", "relMSE vs bounce-matched reference", "relative MSE of the linear "
               "images against the bounce-matched reference (↓); ± 1σ",
               _relmse_cell(lambda r: r.final)),
        Column("flip_direct", "direct light: HDR-FLIP vs emission+direct", "mean HDR-FLIP of "
               "the technique's direct-light layer against the reference's emission + direct "
               "(shared by every technique) (↓)", _flip_cell(lambda r: r.direct)),
        Column("psnr", "PSNR LDR vs bounce-matched [dB]", "PSNR of the tonemapped 8-bit images "
               "against the bounce-matched reference (↑); ± 1σ",
               lambda r: _n(r.final.psnr_ldr, with_bar(fmt_fixed(r.final.psnr_ldr, 2),
                                                        r.final.psnr_ldr_sigma,
                                                        lambda x: fmt_fixed(x, 2)))),
        Column("ssim", "SSIM vs bounce-matched", "SSIM of the tonemapped luma against the "
               "bounce-matched reference (↑)",
               lambda r: _n(r.final.ssim, fmt_fixed(r.final.ssim, 4))),
        *_region_columns(runs),
        Column("flip_indirect", "indirect: HDR-FLIP vs matched indirect", "mean HDR-FLIP of the "
               "indirect layer against the bounce-matched reference's indirect layer",
               lambda r: _n(r.indirect.flip_mean, fmt_flip(r.indirect.flip_mean))),
        Column("energy", "energy ratio", "mean luminance of the indirect layer over the "
               "reference's (1 = the right amount of indirect light)",
               lambda r: _n(r.energy_ratio, fmt_fixed(r.energy_ratio, 3))),
        Column("nonfinite", "NaN/Inf px", "NaN or Inf pixels in the final image",
               lambda r: _n(nonfinite_count(r), fmt_sig(nonfinite_count(r), 6))),
        Column("noise", "within ref. noise", "whether the error against the bounce-matched "
               "reference is no larger than what the reference's own Monte Carlo noise produces "
               "(MSE and/or FLIP)", _noise_cell, True, ""),
        Column("front", "Pareto", "on its scene's Pareto front (mean HDR-FLIP against the "
               "scene's ranking basis, the full reference where measured, vs. frame time); "
               "'tie': inseparable from a front run within IQR and error bars",
               lambda r: _front_cell(r, page), True, ""),
        Column("setup", time_label(measured, "set-up (wall clock)"), "one-time set-up, wall "
               "clock (timing.setup_ms.total)", lambda r: _n(r.setup_ms, fmt_ms(r.setup_ms))),
        Column("passes", time_label(measured, "passes"), "median time of each pass on the "
               "device named (sorts by their sum)", _passes_cell, True, "passes"),
        Column("memory", "memory [MiB]", "device memory allocated by gilab (total; peak if "
               "higher)", _memory_cell),
        Column("exr", "EXR", "the run's linear output (outputs.exr)",
               lambda r: _exr_cell(r, page), False, ""),
        Column("reference", "bounce-matched reference", "light paths of the matched reference, "
               "samples per pixel", _reference_cell, False, ""),
    ]
    return _applicable(cols, runs, page)


def _applicable(cols: list[Column], runs: list[Run], page: Page) -> list[Column]:
    """Drops the columns no run has a value for; 'Pareto' only when a front exists."""
    always = {"index", "scene", "technique", "params", "status"}
    keep = []
    for c in cols:
        if c.id == "front":
            if any(page.fronts.values()):
                keep.append(c)
        elif c.id in always or any(c.cell(r)[1] not in (None, "") for r in runs):
            keep.append(c)
    return keep


def run_table_html(page: Page) -> str:
    runs = page.results.runs
    if not runs:
        return ""
    cols = run_columns(page)
    head = "".join(f'<th data-col="{c.id}" data-type="{"num" if c.numeric else "text"}" '
                   f'title="{esc(c.tip)}">{esc(c.title)}</th>' for c in cols)
    rows = []
    for run in runs:
        cells = []
        for c in cols:
            shown, value = c.cell(run)
            sort = "" if value is None else (repr(float(value)) if c.numeric and
                                             num(value) is not None else esc(value))
            cells.append(f'<td class="c-{c.id} {c.css}" data-v="{sort}">{shown}</td>')
        css = "run-row" + (" noise" if run.final.within_reference_noise else "") + (
            " invalid" if run.status == "invalid" else "")
        rows.append(f'<tr class="{css}" data-key="{esc(run.key)}">{"".join(cells)}</tr>')
    return ('<h2 id="runs">All runs</h2><p>Every finished run. Click a column header to sort '
            '(click again to reverse); hover a header for its definition. Rows shaded green '
            'have an error within the reference\'s noise.</p>'
            '<div class="filter">filter <input id="run-filter" type="search" '
            'placeholder="scene, technique, parameter, status…"> '
            f'<span id="run-count" class="muted">{len(runs)} of {len(runs)}</span></div>'
            f'<p class="device-line">Timed on {esc(device_names([r for r in runs if r.measured]))}'
            '.</p>'
            f'<div class="table-wrap"><table id="run-table" class="data sortable"><thead><tr>'
            f'{head}</tr></thead><tbody>{"".join(rows)}</tbody></table></div>')


def _run_title(run: Run, page: Page) -> str:
    """'technique on scene (swept parameters)' for lists of runs."""
    return (f"{swatch(run.technique, page)} on {esc(run.scene)} "
            f"({esc(params_text(run, True)) or 'no swept parameter'})")


def invalid_banner_html(page: Page) -> str:
    """A warning at the top of the page listing every invalid run and its first message."""
    invalid = [r for r in page.results.runs if r.status == "invalid"]
    if not invalid:
        return ""
    items = "".join(f"<li>{status_badge(r.status)} {_run_title(r, page)}: "
                    f"{validation_summary(r) or 'validation messages'}"
                    f"{'<br>' + first_message_html(r) if r.first_validation_message() else ''}"
                    "</li>" for r in invalid)
    return (f'<div class="warn invalid" id="invalid"><b>{len(invalid)} invalid run'
            f'{"s" if len(invalid) != 1 else ""}</b>: Vulkan validation reported errors or '
            'warnings while they ran, so their images and numbers are not trusted. They are '
            'listed in the run table but left out of the images, figures, Pareto fronts and '
            'comparisons; a later <code>gilab run</code> redoes them. First message of each '
            f'(all of them are in its <code>result.json</code>):<ul>{items}</ul></div>')


def failures_html(page: Page) -> str:
    bad = [r for r in page.results.runs if r.status in ("unsupported", "nonfinite", "invalid")]
    if not bad:
        return ""
    items = []
    for run in bad:
        if run.status == "unsupported":
            why = esc(run.reason) or "no reason recorded"
        elif run.status == "invalid":
            why = (validation_summary(run) or "validation messages") + \
                " (see the warning at the top)"
        else:
            count = nonfinite_count(run)
            why = (f"{int(count)} NaN/Inf pixels in the final image" if count
                   else "non-finite values in an output layer") + \
                "; its metrics cover the finite pixels only"
        items.append(f"<li>{status_badge(run.status)} {_run_title(run, page)}: {why}</li>")
    return ('<h3 id="failures">Where techniques break</h3><ul>' + "".join(items) + "</ul>")


# ---------------------------------------------------------------------------------------------
# Section 7: equal-time and equal-error tables
# ---------------------------------------------------------------------------------------------

@dataclass
class Ranking:
    """One equal-time or equal-error table: which run each cell shows and how it is compared."""

    headers: list[str]
    pick: Callable[[list[Run], int], Optional[Run]]
    show: Callable[[Run], str]
    value: Callable[[Run], float]
    tied: Callable[[Run, Run], bool]  # inseparable within the noise
    basis_name: str
    corner: str  # the header of the first column (names the basis / device)
    shows: str  # "error" or "time": what the cells' data-v holds
    device: str = ""  # the device model(s) the times were measured on (the table's caption)


def _equal_table(page: Page, runs: list[Run], table: Ranking) -> str:
    """Techniques × constraints; the best cell of each column highlighted, and every cell that
    cannot be told apart from it within the noise marked as tied with it."""
    techs = by_technique([r for r in runs if r.status == "ok"])
    winners: dict[int, Run] = {}
    picks: dict[str, list[Optional[Run]]] = {}
    for tech, tech_runs in techs.items():
        picks[tech] = [table.pick(tech_runs, i) for i in range(len(table.headers))]
        for i, run in enumerate(picks[tech]):
            if run is not None and (i not in winners or table.value(run) < table.value(winners[i])):
                winners[i] = run
    rows = []
    for tech, chosen in picks.items():
        cells = []
        for i, run in enumerate(chosen):
            if run is None:
                cells.append(f'<td class="n">{DASH}</td>')
                continue
            best = winners.get(i)
            css = " best" if run is best else (" best tie" if table.tied(run, best) else "")
            mark = ' <span class="pm">(tie)</span>' if css == " best tie" else ""
            cells.append(f'<td class="n{css}" data-key="{esc(run.key)}" '
                         f'data-basis="{esc(table.basis_name)}" data-v="{table.value(run)!r}" '
                         f'title="{esc(params_text(run))}">{table.show(run)}{mark}</td>')
        rows.append(f"<tr><td>{swatch(tech, page)}</td>{''.join(cells)}</tr>")
    head = "".join(f'<th>{esc(h)}</th>' for h in table.headers)
    caption = (f'<caption class="device-line">timed on {esc(table.device)}</caption>'
               if table.device else "")
    return (f'<table class="data ranking" data-basis="{esc(table.basis_name)}" '
            f'data-value="{table.shows}">{caption}<thead><tr><th>{esc(table.corner)}</th>{head}'
            f'</tr></thead><tbody>{"".join(rows)}</tbody></table>')


def _equal_group_html(page: Page, ok: list[Run], scene: str, group: str) -> str:
    """The equal-time and equal-error tables of runs compared with one reference."""
    basis = page.basis(scene)
    budgets = time_budgets([r.frame_ms for r in ok])
    targets = error_targets([basis.flip(r) for r in ok])
    flip_label = basis.label("HDR-FLIP", group)
    frame = time_label(ok, "frame time")
    error_tied = lambda a, b: not error_separable(a, b, basis.flip, basis.flip_sigma)  # noqa
    time_tied = lambda a, b: not time_separable(a, b)  # noqa: E731
    device = device_names(ok)
    equal_time = Ranking([f"≤ {b:g} ms" for b in budgets],
                         lambda rs, i: best_within_budget(rs, budgets[i], basis),
                         lambda r: fmt_flip(basis.flip(r)), basis.flip, error_tied, basis.name,
                         f"mean {flip_label}, by {frame} budget", "error", device)
    equal_error = Ranking([f"≤ {t:g}" for t in targets],
                          lambda rs, i: cheapest_reaching(rs, targets[i], basis),
                          lambda r: fmt_ms(r.frame_ms) + noisy_mark(r.frame_ms, r.frame_iqr,
                                                                    True),
                          lambda r: r.frame_ms, time_tied,
                          basis.name, f"{frame}, by mean {flip_label} target", "time", device)
    return (f'<h4>Equal time: lowest mean <span class="basis">{esc(flip_label)}</span> within a '
            f'budget of {esc(frame)}</h4>' + _equal_table(page, ok, equal_time)
            + f'<h4>Equal error: shortest {esc(frame)} reaching a mean <span class="basis">'
            f'{esc(flip_label)}</span></h4>' + _equal_table(page, ok, equal_error))


def _left_out_note(runs: list[Run], groups: dict[str, list[Run]], page: Page) -> str:
    left_out = sorted({r.technique for r in runs if r.measured}
                      - {r.technique for g in groups.values() for r in g})
    if not left_out:
        return ""
    return (f'<p class="note">not in this comparison (no ok run with a time and an error on '
            f'this basis, or fewer than {MIN_COMPARED} runs compared with its reference): '
            + ", ".join(swatch(t, page) for t in left_out) + "</p>")


EQUAL_WORDS = ('Budgets are '
               'the 1-2-5 series of milliseconds covering the observed median frame times; target '
               'errors are the 90/75/50/25/10 % quantiles of the observed values (2 significant '
               'digits). Each cell is the technique\'s best ok run under that constraint (hover '
               'for its parameters); the best cell of each column is highlighted, and cells that '
               'cannot be told apart from it (error bars or frame-time IQRs overlap) are marked '
               f'"(tie)"; {DASH} = no run qualifies; \u26a0 marks a noisy frame time (IQR above '
               f'{100 * NOISY_IQR_FRACTION:.0f} % of the median). Each table names the device its '
               'times were measured on.')

# How the per-technique tables differ from the study's verdict (when both are on the page).
SECOND_VIEW_WORDS = ('<b>The answer to cite is the study\'s verdict</b> (the first screen) and its '
                     'equal-time and equal-error tables above. These per-technique tables are a '
                     'second, coarser view of the same runs, and their winners can differ: one '
                     'row per <i>technique</i> (its best run of any setting, where the study has '
                     'one row per <i>series</i>, e.g. cvgi with each gather apart); budgets from '
                     'the observed times (1-2-5 ms series) instead of the study\'s fixed ones; '
                     'targets from quantiles of the observed errors instead of fractions of the '
                     'direct floor; ties from IQRs and error bars only (no seed or run-to-run '
                     'spread), and no compensating or path-tracer rules.')


def equal_html(page: Page, folded: bool = False) -> str:
    """The per-technique equal-time and equal-error tables: the page's answer when there is no
    study; folded (a closed <details> under a heading that says what they are) when the
    study's verdict is on the page."""
    parts = []
    for scene, scene_runs in by_scene(page.results.runs).items():
        basis = page.basis(scene)
        tables = []
        for device, runs in by_device(scene_runs).items():  # one device's times at a time
            groups = comparable_groups(runs, basis)
            if not groups:
                continue
            if device:
                tables.append(f'<h4 class="device">Timed on {esc(device)}</h4>')
            tables += [_equal_group_html(page, ok, scene, label) for label, ok in groups.items()]
            tables.append(_left_out_note(runs, groups, page))
        if tables:
            parts += [f"<h3>{esc(scene)}</h3>"] + tables
    if not parts:
        return ""
    if folded:
        return ('<h2 id="equal">Per-technique equal-time and equal-error tables (a second view)'
                f'</h2><p class="second-view">{SECOND_VIEW_WORDS} {EQUAL_WORDS}</p>'
                '<details class="second-view"><summary>show the per-technique tables</summary>'
                + "".join(parts) + "</details>")
    return ('<h2 id="equal">Which technique is best? Equal-time and equal-error comparison'
            '</h2><p>The cross-technique answer, per scene: every run '
            'is compared on the scene\'s one ranking basis, named in each heading: mean HDR-FLIP '
            'against the <b>full reference</b> (all light paths) where measured; results without '
            'it are compared only with runs of the same bounce-matched reference. '
            f'{EQUAL_WORDS} The images, every run and the figures follow.</p>' + "".join(parts))


# ---------------------------------------------------------------------------------------------
# Section 8: skipped passes and notes; unreadable folders
# ---------------------------------------------------------------------------------------------

def _grouped_lists_table(page: Page, field_name: str, title: str) -> str:
    groups: dict[tuple, list[Run]] = {}
    for run in page.results.runs:
        values = run.data.get(field_name)
        items = tuple(text(v) for v in values) if isinstance(values, list) else ()
        if items:
            groups.setdefault(items, []).append(run)
    if not groups:
        return ""
    rows = []
    for items, runs in groups.items():
        listing = "".join(f"<li>{_pass_and_reason(i)}</li>" for i in items)
        techs = ", ".join(swatch(t, page) for t in ordered_unique([r.technique for r in runs]))
        scenes = ", ".join(esc(s) for s in ordered_unique([r.scene for r in runs]))
        rows.append(f'<tr><td><ul class="skipped">{listing}</ul></td><td class="n">{len(runs)}'
                    f"</td><td>{techs}</td><td>{scenes}</td></tr>")
    return (f"<h3>{title}</h3><table class='data'><thead><tr><th>{title.lower()}</th><th>runs"
            "</th><th>techniques</th><th>scenes</th></tr></thead><tbody>" + "".join(rows) +
            "</tbody></table>")


def _pass_and_reason(item: str) -> str:
    name, sep, reason = item.partition(": ")
    return f"<code>{esc(name)}</code>: {esc(reason)}" if sep else esc(item)


def skipped_html(page: Page) -> str:
    skipped = _grouped_lists_table(page, "skipped_passes", "Skipped passes")
    notes = _grouped_lists_table(page, "notes", "Notes")
    if not skipped and not notes:
        return ""
    return ('<h2 id="skipped">Skipped passes and notes</h2><p>Runs grouped by identical lists. '
            'A skipped pass did not run (and cost nothing) for the reason given.</p>'
            + skipped + notes)


def unreadable_html(page: Page) -> str:
    bad = page.results.unreadable
    if not bad:
        return ""
    rows = "".join(f"<tr><td>{status_badge('unreadable')}</td>"
                   f"<td><code>{esc(shown_path(u.path, page))}</code>"
                   f"</td><td>{esc(u.why)}</td></tr>" for u in bad)
    return ('<h2 id="unreadable">Unreadable run folders</h2><p>These run folders have no usable '
            'result.json; they are not in any table or figure.</p><table class="data"><thead><tr>'
            '<th>status</th><th>path</th><th>problem</th></tr></thead><tbody>' + rows +
            "</tbody></table>")


# ---------------------------------------------------------------------------------------------
# Section 10: definitions and provenance
# ---------------------------------------------------------------------------------------------

def footer_html(page: Page) -> str:
    definitions = [
        ("Frame time", "median over the timed frames (warm-up frames discarded) of the frame "
         "time, the sum of the per-pass timestamp intervals on the device named in every time "
         "axis and header (\u201clavapipe (CPU)\u201d: Vulkan on the llvmpipe CPU rasteriser, "
         "not a GPU); ± is the interquartile range (q3 − q1). Runs without timestamps use the "
         "CPU frame time, marked (CPU clock). See " + doc_link(page, "timing.md") + "."),
        ('<span id="noisy-timings">Noisy timings</span>', "a timing whose interquartile range "
         f"is above {100 * NOISY_IQR_FRACTION:.0f} % of its median is marked \u26a0 noisy "
         "wherever it is shown (image cards, the run table's frame, dynamic-frame and pass "
         "times, the Pareto and equal-error tables, the study's equal-time and equal-error "
         "tables, the animated-scene cost tables) and drawn with a red square in the "
         "error-against-time figures (the study's too) and sweep figures (hatched in the "
         "time-per-pass figure, its total starred). Its median is uncertain by about the IQR: two such "
         "times are only told apart when their IQRs do not overlap (see Noise). Timing more "
         "frames (the runner's timed frames) narrows it; on lavapipe (a CPU shared with other "
         "work) frame times are often noisy."),
        ("Set-up time", "wall clock of the one-time set-up (scene upload, shared passes, "
         "shadow maps, technique set-up), <code>timing.setup_ms.total</code>."),
        ("Memory", "bytes of device memory allocated through gilab's accounting, in MiB "
         "(2<sup>20</sup> bytes); the peak is shown when higher than the final total."),
        ("Ranking basis", "every headline number and ranking of a scene (best run, Pareto "
         "front, equal-time and equal-error tables, image-card numbers, the top row of the "
         "error-vs-time figure) uses one basis, named in its label: mean HDR-FLIP <i>vs full "
         "reference</i> (all light paths, <code>metrics.final_vs_full</code>), so a technique "
         "that leaves out bounces pays for the missing light. Results without it fall back to the "
         "bounce-matched reference, ranking only runs compared with the same one. No ranking "
         "mixes references." + (
             " On an <b>animated scene</b> the basis is the mean HDR-FLIP vs full reference over "
             "the measured frames (<code>metrics.sequence.full_flip_mean</code>) and the time is "
             "the <i>dynamic frame (light/camera moved, update included)</i>; the static frame "
             "is shown next to it." if any(r.animated for r in page.results.runs) else "")),
        ("Errors", "\u201cvs bounce-matched reference\u201d: against the path-traced reference "
         "with the light paths the technique claims (emission, direct and its number of "
         "indirect bounces; <code>metrics.final</code>), the error of what it claims to render, "
         "a second view. \u201cdirect light\u201d: the direct-light layer against the "
         "reference's emission + direct (<code>metrics.direct</code>), shared by every "
         "technique. relMSE on linear values, PSNR (LDR) and SSIM on the tonemapped 8-bit "
         "images, FLIP is HDR-FLIP. Definitions in " + doc_link(page, "metrics.md") + ". Error "
         "bars (±1σ) come from re-sampling the reference's per-pixel standard error. <i>Within "
         "the reference's noise</i>: MSE ≤ 2 × the reference's noise floor (MSE), or FLIP ≤ the "
         "FLIP of a noise-only image + 2 of its standard deviations (FLIP)."),
        ("Noise", "two runs are told apart only when their frame-time IQRs or their error "
         "intervals (± 1σ; a point where no error bar is measured) do not overlap. A best run "
         "with another within its error bars is \u201cbest (tie)\u201d; a run whose IQR and "
         "error bar both overlap a front run's is a tie with the front; sweep summaries call a "
         "change a rise or fall only beyond the larger of the scene's noise floor (the "
         "HDR-FLIP of the reference's own noise, listed in the guide to HDR-FLIP at the top) "
         "and the two ends' error bars and seed spread; smaller changes are \u201cunchanged "
         "within noise\u201d."),
        ("Best run", "per technique and scene: the ok run with the lowest mean HDR-FLIP on the "
         "scene's ranking basis (ties: lower relMSE, then shorter frame time)."),
        ("Pareto front", "the runs for which no other run has both a frame time ≤ and an error "
         "<; runs inseparable from a front run are listed as ties."),
        ("No effect", "a swept parameter whose runs (differing only in it) have identical output "
         "images, or identical metrics where no image is readable, has no effect on the scene: "
         "no sweep figure, a note instead."),
        ("Equal time / equal error", "equal time: for each budget B, the lowest mean HDR-FLIP "
         "among the technique's runs with median frame time ≤ B (budgets: the 1-2-5 series of "
         "ms covering the observed times). Equal error: for each target E, the shortest median "
         "frame time among its runs with mean HDR-FLIP ≤ E (targets: the 90/75/50/25/10 % "
         "quantiles of the observed values)."),
        ("Report", f"generated {esc(page.generated)} by <code>python3 -m gilab_report"
         f"</code> ({esc(page.tool_versions)}); described in " + doc_link(page, "report.md")
         + "."),
    ]
    items = "".join(f"<dt>{k}</dt><dd>{v}</dd>" for k, v in definitions)
    return f'<footer><h2 id="definitions">Definitions and provenance</h2><dl>{items}</dl>' \
           f'{provenance_html(page)}</footer>'


def provenance_html(page: Page) -> str:
    keys = ("git_commit", "gilab_version", "build_type", "compiler", "host", "cpu")
    seen: dict[tuple, int] = {}
    for run in page.results.runs:
        prov = run.data.get("provenance") if isinstance(run.data.get("provenance"), dict) else {}
        row = tuple(text(prov.get(k)) for k in keys) + (
            text(dig(run.data, "device", "name")), text(dig(run.data, "device", "driver_info")),
            text(dig(run.data, "device", "vulkan_api")))
        seen[row] = seen.get(row, 0) + 1
    if not seen:
        return ""
    head = "".join(f"<th>{h}</th>" for h in keys + ("device", "driver", "Vulkan", "runs"))
    rows = "".join("<tr>" + "".join(f"<td>{esc(v) or DASH}</td>" for v in row)
                   + f"<td class='n'>{n}</td></tr>" for row, n in seen.items())
    return (f'<h3>Provenance</h3><div class="table-wrap"><table class="data"><thead><tr>{head}'
            f'</tr></thead><tbody>{rows}</tbody></table></div>')
