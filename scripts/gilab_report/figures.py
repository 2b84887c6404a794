"""The report's figures: matplotlib, SVG backend, text kept as text (small files).

Every function draws one figure into one .svg file and returns nothing; colours come from the
caller (analysis.technique_colors) so that a technique has one colour everywhere.
"""
from __future__ import annotations

import textwrap
from dataclasses import dataclass
from typing import Callable, Optional

import matplotlib

matplotlib.use("svg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402
from matplotlib.ticker import FuncFormatter, LogLocator, MaxNLocator, NullFormatter  # noqa: E402

from .analysis import (GREYS, MATCHED, Basis, Sweep, baseline_value,  # noqa: E402
                             by_technique, param_value, params_text, pareto_fronts, pareto_ties,
                             shade, sweep_x)
from .device import (DYNAMIC_FRAME, device_group, device_groups,  # noqa: E402
                           device_label, dynamic_clock, nodes_phrase, time_label)
from .data import Run, Temporal, text  # noqa: E402
from .noise import (NOISY_COLOR, NOISY_GID, NOISY_IQR_FRACTION, NOISY_LABEL,  # noqa: E402
                    noisy_run, noisy_time)

STYLE = {
    "svg.fonttype": "none",
    "svg.hashsalt": "gilab-report",
    "font.family": "sans-serif",
    "font.sans-serif": ["DejaVu Sans", "Arial", "Helvetica"],
    "font.size": 9,
    "axes.titlesize": 10,
    "axes.labelsize": 9,
    "legend.fontsize": 8,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "axes.grid": True,
    "grid.color": "#dddddd",
    "grid.linewidth": 0.6,
    "axes.axisbelow": True,
    "figure.dpi": 100,
}
FRONT_STYLES = ("--", ":", "-.", (0, (6, 2, 1, 2, 1, 2)), (0, (1, 1)), (0, (8, 3)))
IQR_GID = "iqr-bars"  # SVG id prefix of the frame-time IQR bars (the report's test looks for it)
SEQUENCE_GID = "seq-line-"  # + run key: one line per run in the per-frame error figure
TEMPORAL_GID = "temporal-bar-"  # + run key: one bar per run in the temporal-instability figure
LOG_SPAN = 10.0  # use a log axis when the largest positive value is > LOG_SPAN x the smallest

Metric = Callable[[Run], Optional[float]]


def configure() -> None:
    plt.rcParams.update(STYLE)


def _save(fig: plt.Figure, path: str) -> None:
    fig.savefig(path, format="svg", bbox_inches="tight", metadata={"Date": None})
    plt.close(fig)


def _wants_log(values: list[float]) -> bool:
    positive = [v for v in values if v is not None and v > 0]
    return len(positive) == len([v for v in values if v is not None]) and len(positive) > 1 \
        and max(positive) > LOG_SPAN * min(positive)


def _log_axis(axis: matplotlib.axis.Axis) -> None:
    """Log scale with 1-2-5 ticks written as plain numbers."""
    axis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_formatter(NullFormatter())


def _xerr(runs: list[Run]) -> Optional[list[list[float]]]:
    """Asymmetric bars from the frame-time quartiles (0 where unknown)."""
    lo = [max(0.0, r.frame_ms - r.frame_q1) if r.frame_q1 is not None else 0.0 for r in runs]
    hi = [max(0.0, r.frame_q3 - r.frame_ms) if r.frame_q3 is not None else 0.0 for r in runs]
    return [lo, hi] if any(lo) or any(hi) else None


def _yerr(runs: list[Run], sigma: Metric) -> Optional[list[float]]:
    values = [sigma(r) or 0.0 for r in runs]
    return values if any(values) else None


def _title(ax: plt.Axes, title: str, width: int = 52) -> None:
    """A panel title wrapped to the panel's width (constrained layout keeps them apart)."""
    ax.set_title(textwrap.fill(title, width), fontsize=9)


def axis_time_label(runs: list[Run], what: str) -> str:
    """time_label for an axis: the dynamic-frame wording on its own line (the device and the
    unit stay together on the last line)."""
    return time_label(runs, what).replace(f", {DYNAMIC_FRAME}", ", dynamic frame\n"
                                          + DYNAMIC_FRAME[len("dynamic frame "):])


def _noisy_marks(ax: plt.Axes, points: list[tuple[Run, float, float]]) -> None:
    """A red square around every point whose frame time is noisy (IQR above
    NOISY_IQR_FRACTION of the median), each with its SVG id (NOISY_GID + key)."""
    for run, x, y in points:
        if noisy_run(run):
            mark, = ax.plot([x], [y], "s", ms=13, mfc="none", mec=NOISY_COLOR, mew=1.1,
                            ls="none", zorder=5)
            mark.set_gid(f"{NOISY_GID}{run.key}")


def _noisy_handle() -> Line2D:
    return Line2D([], [], marker="s", ls="none", ms=11, mfc="none", mec=NOISY_COLOR,
                  label=NOISY_LABEL)


def _static_marks(ax: plt.Axes, runs: list[Run], colors: dict[str, str], error: Metric
                  ) -> list[float]:
    """For runs timed by their dynamic frame: the static frame of the same run as a hollow
    marker joined to it by a dotted line (the cost of the update and the motion, visible).
    Returns the static times drawn."""
    drawn = []
    for run in runs:
        if not run.dynamic_clock or run.static.median is None:
            continue
        ax.plot([run.static.median, run.frame_ms], [error(run), error(run)], ":", lw=0.8,
                color=colors[run.technique], alpha=0.7, zorder=1)
        ax.plot([run.static.median], [error(run)], "o", ms=5, mfc="white",
                mec=colors[run.technique], mew=0.9, zorder=2)
        drawn.append(run.static.median)
    return drawn


def _scatter_panel(ax: plt.Axes, runs: list[Run], colors: dict[str, str], basis: Basis,
                   error: Metric, sigma: Metric, ylabel: str, ylog: Optional[bool] = None,
                   front_order: Optional[list[str]] = None) -> None:
    """Error against frame time, one colour per technique, the Pareto front of each group of
    comparable runs as a step line (runs on it ringed; runs tied with it within the noise in a
    dashed grey ring). On an animated scene the time is the dynamic frame's, and each run's
    static frame is a hollow marker on the same error. ylog None: a log error axis when this
    panel's errors span > LOG_SPAN; front_order: the groups in the legend's order (of styles)."""
    plotted = [r for r in runs if r.measured and r.frame_ms is not None and error(r) is not None]
    ax.set_ylabel(ylabel)
    ax.set_xlabel(axis_time_label([r for r in runs if r.measured], "median frame time"))
    if not plotted:
        ax.text(0.5, 0.5, "no run has this metric", ha="center", va="center",
                transform=ax.transAxes, color="#777777")
        return
    statics = _static_marks(ax, plotted, colors, error)
    for tech in sorted({r.technique for r in plotted}):
        for status, marker, size in (("ok", "o", 5), ("nonfinite", "X", 8)):
            group = [r for r in plotted if r.technique == tech and r.status == status]
            if not group:
                continue
            xerr = _xerr(group)
            bars = ax.errorbar([r.frame_ms for r in group], [error(r) for r in group],
                               xerr=xerr, yerr=_yerr(group, sigma), fmt=marker, ms=size,
                               color=colors[tech],
                               mec="black" if status == "nonfinite" else colors[tech],
                               mew=0.8, elinewidth=0.8, capsize=0, alpha=0.9, zorder=3)
            if xerr is not None:
                bars.lines[2][0].set_gid(IQR_GID)  # the frame-time IQR bars (x comes first)
    right = max(r.frame_ms for r in plotted)
    styles = FRONT_STYLES if basis.name == "matched" else ("-",)
    fronts = pareto_fronts(runs, basis, error)
    order = front_order or list(fronts)
    for label, front in fronts.items():
        if label not in order or order.index(label) >= len(styles):
            continue
        style = styles[order.index(label)]
        xs = [r.frame_ms for r in front] + [right]
        ys = [error(r) for r in front] + [error(front[-1])]
        ax.step(xs, ys, where="post", color="black", lw=1.0, ls=style, zorder=2)
        ax.plot(xs[:-1], ys[:-1], "o", ms=9, mfc="none", mec="black", mew=0.8, zorder=4)
    _noisy_marks(ax, [(r, r.frame_ms, error(r)) for r in plotted])
    tied = [r for ties in pareto_ties(runs, basis, error, sigma).values()
            for r in plotted if id(r) in ties]
    if tied:
        ax.plot([r.frame_ms for r in tied], [error(r) for r in tied], "o", ms=10, mfc="none",
                mec="#777777", mew=0.9, ls="none", zorder=4, dashes=(2, 1))
    if _wants_log([r.frame_ms for r in plotted] + statics):
        ax.set_xscale("log")
        _log_axis(ax.xaxis)
    if _wants_log([error(r) for r in plotted]) if ylog is None else ylog:
        ax.set_yscale("log")
        _log_axis(ax.yaxis)


def _pareto_legend(fig: plt.Figure, runs: list[Run], colors: dict[str, str],
                   bases: list[Basis]) -> None:
    techs = sorted({r.technique for r in runs if r.measured})
    handles = [Line2D([], [], marker="o", ls="none", color=colors[t], label=t) for t in techs]
    single = [b for b in bases if b.name != "matched"]
    if single:
        handles.append(Line2D([], [], color="black", ls="-", marker="o", mfc="none",
                              label="Pareto front (" + " / ".join(b.reference for b in single)
                              + ")"))
    if any(b.name == "matched" for b in bases):
        groups = list(pareto_fronts(runs, MATCHED))
        for style, label in zip(FRONT_STYLES, groups):
            handles.append(Line2D([], [], color="black", ls=style, marker="o", mfc="none",
                                  label=f"Pareto front, matched reference {label}"))
    handles.append(Line2D([], [], marker="o", ls="none", ms=10, mfc="none", mec="#777777",
                          label="tie with the front (IQR and error bars overlap)"))
    if any(r.status == "nonfinite" for r in runs):
        handles.append(Line2D([], [], marker="X", ls="none", color="#999999", mec="black",
                              label="nonfinite output"))
    if dynamic_clock([r for r in runs if r.measured]):
        handles.append(Line2D([], [], marker="o", ls=":", color="#777777", mfc="white",
                              label="static frame of the same run (nothing moved, no update)"))
    if any(noisy_run(r) for r in runs if r.measured and r.frame_ms is not None):
        handles.append(_noisy_handle())
    fig.legend(handles=handles, loc="upper center", ncol=min(len(handles), 4),
               bbox_to_anchor=(0.5, 0.0), frameon=False)


def _row_title(basis: Basis, runs: list[Run], metric: str) -> str:
    if basis.name != "matched":
        return basis.label(metric)
    labels = sorted({r.reference_label() for r in runs if r.measured and r.reference_label()})
    group = labels[0] if len(labels) == 1 else "each run's own"
    return basis.label(metric, group) + " (the light paths each technique claims)"


def pareto_figure(runs: list[Run], colors: dict[str, str], bases: list[Basis], path: str,
                  scene: str) -> None:
    """Mean HDR-FLIP and relMSE against median frame time for one scene: one row of two panels
    per basis, the headline basis (the full reference) on top; one column per device when the
    runs were timed on more than one (error_time_figure)."""
    _save(error_time_figure(runs, colors, bases, scene), path)


def error_time_figure(runs: list[Run], colors: dict[str, str], bases: list[Basis],
                      scene: str) -> plt.Figure:
    """The figure of pareto_figure, not saved. Times of two device models never share an axis:
    with several, each gets its own column of panels (_device_columns)."""
    measured = [r for r in runs if r.measured]
    groups = device_groups([r for r in measured if r.frame_ms is not None])
    what = "dynamic frame time" if dynamic_clock(measured) else "frame time"
    if len(groups) > 1:
        fig = _device_columns(runs, groups, colors, bases, scene, what)
        _pareto_legend(fig, runs, colors, bases)
        return fig
    fig, axes = plt.subplots(len(bases), 2, figsize=(10.0, 3.8 * len(bases)), squeeze=False,
                             gridspec_kw={"wspace": 0.25, "hspace": 0.62})
    for row, basis in zip(axes, bases):
        _scatter_panel(row[0], runs, colors, basis, basis.flip, basis.flip_sigma,
                       "mean HDR-FLIP ↓")
        _scatter_panel(row[1], runs, colors, basis, basis.rel_mse, basis.rel_mse_sigma,
                       "relMSE ↓")
        _title(row[0], _row_title(basis, runs, "HDR-FLIP"))
        _title(row[1], _row_title(basis, runs, "relMSE"))
    lines = max(len(textwrap.wrap(_row_title(bases[0], runs, m), 52))
                for m in ("HDR-FLIP", "relMSE"))
    title = f"{scene}: error against {what} (top row: the ranking basis)"
    timed = [r for runs_of_group in groups.values() for r in runs_of_group]
    if len({r.host for r in timed} - {""}) > 1:  # one device model on several nodes
        title += f"\ntimed on {next(iter(groups))}, the same model {nodes_phrase(timed)}"
        lines += 1
    fig.suptitle(title, fontsize=10,
                 y=(0.94 if len(bases) == 1 else 0.93) + 0.03 * (lines - 1) * (2 / len(bases)))
    _pareto_legend(fig, runs, colors, bases)
    return fig


def _device_columns(runs: list[Run], groups: dict[str, list[Run]], colors: dict[str, str],
                    bases: list[Basis], scene: str, what: str) -> plt.Figure:
    """One column per device model, each with its own time axis and Pareto fronts, titled with
    the device and its nodes; one row per basis and metric, the error axis shared along it."""
    rows = [(b, m) for b in bases for m in ("HDR-FLIP", "relMSE")]
    height = 3.6 * len(rows)
    fig, axes = plt.subplots(len(rows), len(groups), figsize=(5.0 * len(groups), height),
                             squeeze=False, sharey="row",
                             gridspec_kw={"wspace": 0.2, "hspace": 0.95,
                                          "top": 1 - 0.9 / height, "bottom": 0.5 / height})
    matched = list(pareto_fronts(runs, MATCHED))  # the legend's matched fronts, in order
    for row, (basis, metric) in zip(axes, rows):
        flip = metric == "HDR-FLIP"
        error, sigma = (basis.flip, basis.flip_sigma) if flip else \
            (basis.rel_mse, basis.rel_mse_sigma)
        ylog = _wants_log([error(r) for r in runs if r.measured and r.frame_ms is not None])
        for ax, (device, timed) in zip(row, groups.items()):
            own = [r for r in runs if device_group(r) == device]
            _scatter_panel(ax, own, colors, basis, error, sigma,
                           "mean HDR-FLIP ↓" if flip else "relMSE ↓", ylog,
                           matched if basis.name == "matched" else None)
            lines = [_row_title(basis, runs, metric), device, nodes_phrase(timed)]
            ax.set_title("\n".join(textwrap.fill(t, 52) for t in lines if t), fontsize=9)
            if ax is not row[0]:  # the error axis is shared along the row
                ax.set_ylabel("")
    fig.suptitle(f"{scene}: error against {what}, timed on {len(groups)} devices: one column "
                 "each, never one time axis (top two rows: the ranking basis)", fontsize=10,
                 y=1.0, va="bottom")
    return fig


def _sweep_positions(sweep: Sweep) -> tuple[dict[str, float], list[str]]:
    """x position of each value of the swept key (numbers, or 0..n-1 for categories)."""
    runs = [r for members in sweep.series.values() for r in members]
    if sweep.numeric:
        return {text(param_value(r, sweep.key)): sweep_x(r, sweep.key) for r in runs}, []
    labels = sorted({text(param_value(r, sweep.key)) for r in runs})
    return {v: float(i) for i, v in enumerate(labels)}, labels


def _time_bars(runs: list[Run]) -> Optional[list[list[float]]]:
    return _xerr(runs)


def _sweep_panel(ax: plt.Axes, sweep: Sweep, color: str, panel: "SweepPanel",
                 positions: dict[str, float]) -> None:
    n = len(sweep.series)
    drawn: list[float] = []
    for i, (others, members) in enumerate(sweep.series.items()):
        tone = shade(color, i, n)
        label = ", ".join(f"{k}={v}" for k, v in zip(sweep.other_keys, others)) or None
        ok = [r for r in members if r.status == "ok" and panel.value(r) is not None]
        xs = [positions[text(param_value(r, sweep.key))] for r in ok]
        ys = [panel.value(r) for r in ok]
        drawn += ys
        bars = _time_bars(ok) if panel.is_time else _yerr(ok, panel.sigma)
        drawn_bars = ax.errorbar(xs, ys, yerr=bars, fmt="-o", ms=4, lw=1.3, color=tone,
                                 elinewidth=0.9, capsize=3, label=label)
        if panel.is_time and bars is not None:
            drawn_bars.lines[2][0].set_gid(IQR_GID)
        if panel.is_time:
            _noisy_marks(ax, list(zip(ok, xs, ys)))
        bad = [r for r in members if r.status == "nonfinite" and panel.value(r) is not None]
        if bad:
            drawn += [panel.value(r) for r in bad]
            ax.plot([positions[text(param_value(r, sweep.key))] for r in bad],
                    [panel.value(r) for r in bad], "X", ms=8, color=tone, mec="black", mew=0.8)
    if not drawn:
        ax.text(0.5, 0.5, "no run has this metric", ha="center", va="center",
                transform=ax.transAxes, color="#777777")
    if _wants_log(drawn):
        ax.set_yscale("log")
        _log_axis(ax.yaxis)
    ax.set_ylabel(panel.ylabel)
    ax.set_xlabel(sweep.key)
    _title(ax, panel.title, 60)


def _sweep_bounces(sweep: Sweep) -> Optional[int]:
    """The bounce count the swept runs claim, if they all claim the same."""
    claimed = {r.claimed_bounces for members in sweep.series.values() for r in members}
    return claimed.pop() if len(claimed) == 1 else None


@dataclass
class SweepPanel:
    title: str
    ylabel: str
    value: Metric
    sigma: Metric
    baseline: Optional[float] = None  # the direct baseline against the same reference
    is_time: bool = False


def _sweep_panels(sweep: Sweep, basis: Basis, baseline: Optional[Run]) -> list[SweepPanel]:
    """Headline error (the scene's basis), the bounce-matched view, relMSE, frame time ± IQR."""
    runs = [r for members in sweep.series.values() for r in members]
    bounces = _sweep_bounces(sweep)
    panels = [SweepPanel(basis.label("HDR-FLIP"), "mean HDR-FLIP ↓", basis.flip,
                         basis.flip_sigma)]
    if basis.name != "matched":
        panels[0].baseline = basis.flip(baseline) if baseline is not None else None
        second = basis.matched_view  # frame means on an animated scene
        panels.append(SweepPanel(_row_title(second, runs, "HDR-FLIP"), "mean HDR-FLIP ↓",
                                 second.flip, second.flip_sigma,
                                 second.flip(baseline) if baseline is not None
                                 and second is not MATCHED else
                                 baseline_value(baseline, bounces, lambda m: m.flip_mean)))
        panels.append(SweepPanel(basis.label("relMSE"), "relMSE ↓", basis.rel_mse,
                                 basis.rel_mse_sigma,
                                 basis.rel_mse(baseline) if baseline is not None else None))
    else:
        panels[0].baseline = baseline_value(baseline, bounces, lambda m: m.flip_mean)
        panels.append(SweepPanel(basis.label("relMSE"), "relMSE ↓", basis.rel_mse,
                                 basis.rel_mse_sigma,
                                 baseline_value(baseline, bounces, lambda m: m.rel_mse)))
    measured = [r for r in runs if r.measured]
    dynamic = dynamic_clock(measured)
    title = f"median time of the {DYNAMIC_FRAME} ± IQR" if dynamic else "median frame time ± IQR"
    ylabel = time_label(measured, "median frame time")
    if dynamic:  # the panel title says what a dynamic frame is; the axis stays short
        ylabel = ylabel.replace(f"median frame time, {DYNAMIC_FRAME}", "dynamic frame")
    panels.append(SweepPanel(title, ylabel,
                             lambda r: r.frame_ms, lambda r: None,
                             baseline.frame_ms if baseline is not None else None, True))
    return panels


def _integer_values(values: list[float]) -> bool:
    return bool(values) and all(float(v).is_integer() for v in values)


def _sweep_ticks(ax: plt.Axes, positions: dict[str, float], categories: list[str]) -> None:
    """Categories by name; numbers at their values when few (integers as integers), a log
    axis (base 2) when they span more than 10x."""
    ticks = sorted(set(positions.values()))
    if categories:
        ax.set_xticks(range(len(categories)), categories)
        return
    if _wants_log(ticks):
        ax.set_xscale("log", base=2)
        ax.minorticks_off()
    if len(ticks) <= 12:
        ax.set_xticks(ticks, [f"{t:g}" for t in ticks])
    elif _integer_values(ticks):
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))


def sweep_figure(sweep: Sweep, colors: dict[str, str], path: str, basis: Basis,
                 baseline: Optional[Run] = None) -> None:
    """The swept parameter against the scene's headline error (basis), the bounce-matched error,
    relMSE and the frame time with its IQR as bars; a baseline run (`direct`) as a dashed line
    measured against the same reference."""
    positions, categories = _sweep_positions(sweep)
    color = colors[sweep.technique]
    panels = _sweep_panels(sweep, basis, baseline)
    rows = (len(panels) + 1) // 2
    fig, axes = plt.subplots(rows, 2, figsize=(10.0, 3.4 * rows), squeeze=False,
                             gridspec_kw={"wspace": 0.25, "hspace": 0.62})
    flat = list(axes.flat)
    for ax, panel in zip(flat, panels):
        _sweep_panel(ax, sweep, color, panel, positions)
        if panel.baseline is not None and baseline is not None:
            ax.axhline(panel.baseline, ls="--", lw=1.0,
                       color=colors.get(baseline.technique, "#777777"),
                       label=f"{baseline.technique} (same reference)")
        _sweep_ticks(ax, positions, categories)
    for ax in flat[len(panels):]:
        ax.set_visible(False)
    handles, _ = flat[0].get_legend_handles_labels()
    extra = []
    if any(r.status == "nonfinite" for m in sweep.series.values() for r in m):
        extra = [Line2D([], [], marker="X", ls="none", color="#999999", mec="black",
                        label="nonfinite output")]
    if any(r.status == "ok" and noisy_run(r) for m in sweep.series.values() for r in m):
        extra.append(_noisy_handle())
    if len(handles) > 1 or extra or baseline is not None:
        fig.legend(handles=handles + extra, loc="upper center",
                   ncol=min(len(handles) + len(extra), 4), bbox_to_anchor=(0.5, 0.0),
                   frameon=False)
    fig.suptitle(f"{sweep.technique} on {sweep.scene}: sweep of {sweep.key}", fontsize=10,
                 color=color, y=0.99 if rows > 1 else 1.04)
    _save(fig, path)


def _stacked_bars(ax: plt.Axes, best: list[Run], stacks: list[list[tuple[str, float]]],
                  color: Callable[[Run, str], str],
                  noisy: Optional[Callable[[Run, str], bool]] = None,
                  starred: Optional[Callable[[Run], bool]] = None) -> None:
    """One stacked bar per run, its total written above it; a segment for which noisy() holds
    is hatched, a total for which starred() holds gets a '*'."""
    for i, (run, stack) in enumerate(zip(best, stacks)):
        bottom = 0.0
        for name, value in stack:
            hatched = noisy is not None and noisy(run, name)
            bars = ax.bar(i, value, bottom=bottom, width=0.6, color=color(run, name),
                          edgecolor=NOISY_COLOR if hatched else "white", linewidth=0.5,
                          hatch="////" if hatched else None)
            if hatched:
                bars.patches[0].set_gid(f"{NOISY_GID}pass-{run.key}-{name}")
            bottom += value
        if stack:
            star = "*" if starred is not None and starred(run) else ""
            ax.text(i, bottom, f"{bottom:.3g}{star}", ha="center", va="bottom", fontsize=8,
                    color=NOISY_COLOR if star else "black")
    labels = [r.technique for r in best]
    rotate = len(labels) > 3
    ax.set_xticks(range(len(labels)), labels, rotation=20 if rotate else 0,
                  ha="right" if rotate else "center")
    ax.margins(y=0.12)
    ax.grid(axis="x", visible=False)


def _legend(ax: plt.Axes, entries: list[tuple[str, str]]) -> None:
    """A legend of (label, colour) patches beside the axes, top to bottom as given."""
    handles = [Patch(facecolor=c, edgecolor="black" if c == "white" else c, linewidth=0.5,
                     label=label) for label, c in entries]
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.0, 1.0), frameon=False)


def passes_figure(best: list[Run], tech_colors: dict[str, str], pass_colors: dict[str, str],
                  path: str, scene: str) -> None:
    """Per-pass median GPU time (stacked) and set-up time by stage for each technique's best
    run on one scene. Shared passes and stages are grey, a technique's own in its colour."""
    frame = [[(n, v) for n, v in r.passes() if v is not None and v > 0] for r in best]
    setup = [[(n, v) for n, v in r.setup_stages() if v is not None and v > 0] for r in best]
    stages = list(dict.fromkeys(n for stack in setup for n, _ in stack if n != "technique"))
    stage_colors = {n: GREYS[i % len(GREYS)] for i, n in enumerate(stages)}

    def setup_color(run: Run, name: str) -> str:
        return tech_colors.get(run.technique, "#888") if name == "technique" \
            else stage_colors[name]

    fig, axes = plt.subplots(1, 2, figsize=(10.0, 3.9), gridspec_kw={"wspace": 0.75})
    spread = {id(r): dict(r.pass_times()) for r in best}

    def noisy_pass(run: Run, name: str) -> bool:
        summary = spread[id(run)].get(name)
        return summary is not None and noisy_time(summary.median, summary.iqr)

    def noisy_frame(run: Run) -> bool:
        return noisy_time(run.static.median, run.static.iqr)

    _stacked_bars(axes[0], best, frame, lambda run, name: pass_colors[name], noisy_pass,
                  noisy_frame)
    static = "static " if any(r.animated for r in best) else ""
    axes[0].set_ylabel(time_label(best, f"median time per {static}frame"))
    axes[0].set_title(f"per-{static}frame time by pass ({device_label(best)})")
    used = list(dict.fromkeys(n for stack in frame for n, _ in stack))
    _legend(axes[0], [(n, pass_colors[n]) for n in reversed(used)])
    _stacked_bars(axes[1], best, setup, setup_color)
    axes[1].set_ylabel(time_label(best, "set-up time (wall clock)"))
    axes[1].set_title("one-time set-up by stage")
    entries = [("technique (its colour)", "white")] if any(
        n == "technique" for stack in setup for n, _ in stack) else []
    _legend(axes[1], entries + [(n, stage_colors[n]) for n in reversed(stages)])
    for ax in axes:
        for tick, run in zip(ax.get_xticklabels(), best):
            tick.set_color(tech_colors.get(run.technique, "black"))
    if any(noisy_pass(r, n) for r, stack in zip(best, frame) for n, _ in stack) or \
            any(noisy_frame(r) for r in best):
        fig.text(0.5, -0.02, "noisy timings: hatched (red edge), a pass whose IQR is above "
                 f"{100 * NOISY_IQR_FRACTION:.0f} % of its median; a total with *, a frame whose "
                 "IQR is", ha="center", va="top", fontsize=8, color=NOISY_COLOR)
    fig.suptitle(f"{scene}: where the time goes (best run per technique)", fontsize=10, y=1.0)
    _save(fig, path)


# ---------------------------------------------------------------------------------------------
# Animated scenes
# ---------------------------------------------------------------------------------------------

def run_tones(runs: list[Run], colors: dict[str, str]) -> dict[int, str]:
    """id(run) -> its colour: the technique's, in shades when the technique has several runs."""
    tones = {}
    for members in by_technique(runs).values():
        for i, run in enumerate(members):
            base = colors.get(run.technique, "#888888")
            tones[id(run)] = base if len(members) == 1 else shade(base, i, len(members))
    return tones


def run_name(run: Run) -> str:
    """'tech_a (cone_count=4)': technique and swept parameters."""
    swept = params_text(run, True)
    return f"{run.technique} ({swept})" if swept else run.technique


def _sequence_panel(ax: plt.Axes, runs: list[Run], tones: dict[int, str], full: bool) -> bool:
    """Per measured frame: HDR-FLIP of each run against that frame's full (or bounce-matched)
    reference, one line per run. Returns whether anything was drawn."""
    values: list[float] = []
    for run in runs:
        frames = [f for f in run.anim.sequence if f.frame is not None]
        points = [(f.frame, (f.vs_full if full else f.matched).flip_mean) for f in frames]
        points = [(x, y) for x, y in points if y is not None]
        if not points:
            continue
        line, = ax.plot([x for x, _ in points], [y for _, y in points], "-o", ms=4, lw=1.4,
                        color=tones[id(run)], label=run_name(run),
                        mec="black" if run.status == "nonfinite" else tones[id(run)])
        line.set_gid(f"{SEQUENCE_GID}{'full' if full else 'matched'}-{run.key}")
        values += [y for _, y in points]
    if not values:
        ax.text(0.5, 0.5, "no run has this metric", ha="center", va="center",
                transform=ax.transAxes, color="#777777")
        return False
    if _wants_log(values):
        ax.set_yscale("log")
        _log_axis(ax.yaxis)
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_xlabel("frame index (measured frames)")
    ax.set_ylabel("mean HDR-FLIP ↓")
    return True


def sequence_figure(runs: list[Run], colors: dict[str, str], path: str, scene: str) -> None:
    """HDR-FLIP against the frame index for every measured run of an animated scene: against
    each frame's full reference (left, the basis of the scene's ranking, whose mean it is) and
    against its bounce-matched reference (right)."""
    drawn = [r for r in runs if r.measured and r.anim is not None and r.anim.sequence]
    tones = run_tones(drawn, colors)
    fig, axes = plt.subplots(1, 2, figsize=(10.0, 3.6), gridspec_kw={"wspace": 0.25})
    _sequence_panel(axes[0], drawn, tones, True)
    _title(axes[0], "HDR-FLIP vs full reference, per measured frame (its mean over the frames "
           "ranks the scene)", 60)
    has_matched = _sequence_panel(axes[1], drawn, tones, False)
    labels = sorted({r.reference_label() for r in drawn if r.reference_label()})
    detail = f" ({labels[0]})" if len(labels) == 1 else " (each run's own)"
    _title(axes[1], f"HDR-FLIP vs bounce-matched reference{detail}, per measured frame", 60)
    if not has_matched:
        axes[1].set_visible(False)
    handles, _ = axes[0].get_legend_handles_labels()
    if handles:
        fig.legend(handles=handles, loc="upper center", ncol=min(len(handles), 4),
                   bbox_to_anchor=(0.5, 0.0), frameon=False)
    fig.suptitle(f"{scene}: error of every measured frame (one line per run)", fontsize=10,
                 y=1.04)
    _save(fig, path)


def _temporal_panel(ax: plt.Axes, runs: list[Run], tones: dict[int, str],
                    block: Callable[[Run], Temporal], gid: str) -> bool:
    """One bar per run (its temporal instability), the noise floor hatched over it up to the
    floor with a black tick at the floor, p95 as a diamond. Returns whether anything was
    drawn."""
    shown = [r for r in runs if block(r).instability is not None]
    if not shown:
        ax.text(0.5, 0.5, "not measured", ha="center", va="center", transform=ax.transAxes,
                color="#777777")
        ax.set_xticks([])
        return False
    top = 0.0
    for i, run in enumerate(shown):
        t = block(run)
        bars = ax.bar(i, t.instability, width=0.6, color=tones[id(run)], edgecolor="black",
                      linewidth=0.5, zorder=2)
        bars.patches[0].set_gid(f"{gid}{run.key}")
        top = max(top, t.instability)
        if t.noise_floor is not None:
            ax.bar(i, t.noise_floor, width=0.6, facecolor="none", edgecolor="#222222",
                   hatch="////", linewidth=0.0, zorder=3)
            ax.plot([i - 0.38, i + 0.38], [t.noise_floor] * 2, color="black", lw=1.6, zorder=4)
            top = max(top, t.noise_floor)
        if t.p95 is not None:
            ax.plot([i], [t.p95], "D", ms=5, color="white", mec="black", mew=1.0, zorder=5)
            top = max(top, t.p95)
        if t.within_noise:
            ax.text(i, max(v for v in (t.instability, t.noise_floor, t.p95) if v is not None),
                    "within the\nnoise floor", ha="center", va="bottom", fontsize=7,
                    color="#17602a", zorder=6, linespacing=0.95,
                    bbox={"boxstyle": "square,pad=0.3", "fc": "white", "ec": "none"})
    labels = [textwrap.fill(run_name(r), 18) for r in shown]
    rotate = len(labels) > 4
    ax.set_xticks(range(len(shown)), labels, rotation=25 if rotate else 0,
                  ha="right" if rotate else "center", fontsize=8)
    for tick, run in zip(ax.get_xticklabels(), shown):
        tick.set_color(tones[id(run)])
    ax.set_ylim(0.0, top * 1.18 if top > 0 else 1.0)
    ax.grid(axis="x", visible=False)
    ax.set_ylabel("temporal instability ↓ (relative to the mean level)")
    return True


def temporal_figure(runs: list[Run], colors: dict[str, str], path: str, scene: str) -> None:
    """Temporal instability of every measured run of an animated scene, against the full
    reference's frames (left) and the bounce-matched reference's (right, where measured)."""
    drawn = [r for r in runs if r.measured and r.anim is not None]
    tones = run_tones(drawn, colors)
    fig, axes = plt.subplots(1, 2, figsize=(10.0, 3.8), gridspec_kw={"wspace": 0.3})
    n = {int(r.anim.temporal.frames) for r in drawn if r.anim.temporal.frames} or \
        {r.anim.measured_count for r in drawn if r.anim.measured_count}
    frames = f" over {n.pop()} measured frames" if len(n) == 1 else ""
    _temporal_panel(axes[0], drawn, tones, lambda r: r.anim.temporal, TEMPORAL_GID)
    _title(axes[0], f"temporal instability vs full reference frames{frames}", 60)
    if not _temporal_panel(axes[1], drawn, tones, lambda r: r.anim.temporal_matched,
                           TEMPORAL_GID + "matched-"):
        axes[1].set_visible(False)
    _title(axes[1], f"temporal instability vs bounce-matched reference frames{frames}", 60)
    handles = [Patch(facecolor="#bbbbbb", edgecolor="black", linewidth=0.5,
                     label="temporal instability (mean |change − reference change| / level)"),
               Patch(facecolor="white", edgecolor="#222222", hatch="////", linewidth=0.0,
                     label="noise floor (what an exact technique scores): up to the black tick"),
               Line2D([], [], marker="D", ls="none", color="white", mec="black",
                      label="p95 of |change − reference change| / level")]
    fig.legend(handles=handles, loc="upper center", ncol=3, bbox_to_anchor=(0.5, -0.02),
               frameon=False)
    fig.suptitle(f"{scene}: temporal instability (one bar per run)", fontsize=10, y=1.03)
    _save(fig, path)
