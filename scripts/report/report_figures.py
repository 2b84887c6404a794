"""The report's figures: matplotlib, SVG backend, text kept as text (small files).

Every function draws one figure into one .svg file and returns nothing; colours come from the
caller (report_analysis.technique_colors) so that a technique has one colour everywhere.
"""
from __future__ import annotations

from typing import Callable, Optional

import matplotlib

matplotlib.use("svg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter  # noqa: E402

from report_analysis import (GREYS, Basis, Sweep, baseline_value, param_value,  # noqa: E402
                             pareto_fronts, shade, sweep_x)
from report_data import Run, text  # noqa: E402

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


def _time_label(runs: list[Run]) -> str:
    sources = {r.frame_source for r in runs if r.frame_source}
    if sources == {"cpu"}:
        return "median frame time [ms] (CPU)"
    if "cpu" in sources:
        return "median frame time [ms] (GPU; CPU where no GPU timings)"
    return "median frame time [ms] (GPU)"


def _xerr(runs: list[Run]) -> Optional[list[list[float]]]:
    """Asymmetric x bars from the frame-time quartiles (0 where unknown)."""
    lo = [max(0.0, r.frame_ms - r.frame_q1) if r.frame_q1 is not None else 0.0 for r in runs]
    hi = [max(0.0, r.frame_q3 - r.frame_ms) if r.frame_q3 is not None else 0.0 for r in runs]
    return [lo, hi] if any(lo) or any(hi) else None


def _yerr(runs: list[Run], sigma: Metric) -> Optional[list[float]]:
    values = [sigma(r) or 0.0 for r in runs]
    return values if any(values) else None


def _scatter_panel(ax: plt.Axes, runs: list[Run], colors: dict[str, str], basis: Basis,
                   error: Metric, sigma: Metric, ylabel: str) -> None:
    """Error against frame time, one colour per technique, the Pareto front of each group of
    comparable runs as a step line (runs on it ringed)."""
    plotted = [r for r in runs if r.measured and r.frame_ms is not None and error(r) is not None]
    ax.set_ylabel(ylabel)
    if not plotted:
        ax.text(0.5, 0.5, "no run has this metric", ha="center", va="center",
                transform=ax.transAxes, color="#777777")
        return
    for tech in sorted({r.technique for r in plotted}):
        for status, marker, size in (("ok", "o", 5), ("nonfinite", "X", 8)):
            group = [r for r in plotted if r.technique == tech and r.status == status]
            if not group:
                continue
            ax.errorbar([r.frame_ms for r in group], [error(r) for r in group],
                        xerr=_xerr(group), yerr=_yerr(group, sigma), fmt=marker, ms=size,
                        color=colors[tech], mec="black" if status == "nonfinite" else colors[tech],
                        mew=0.8, elinewidth=0.8, capsize=0, alpha=0.9, zorder=3)
    right = max(r.frame_ms for r in plotted)
    styles = ("-",) if basis.name == "full" else FRONT_STYLES
    for style, front in zip(styles, pareto_fronts(runs, basis, error).values()):
        xs = [r.frame_ms for r in front] + [right]
        ys = [error(r) for r in front] + [error(front[-1])]
        ax.step(xs, ys, where="post", color="black", lw=1.0, ls=style, zorder=2)
        ax.plot(xs[:-1], ys[:-1], "o", ms=9, mfc="none", mec="black", mew=0.8, zorder=4)
    if _wants_log([r.frame_ms for r in plotted]):
        ax.set_xscale("log")
        _log_axis(ax.xaxis)
    if _wants_log([error(r) for r in plotted]):
        ax.set_yscale("log")
        _log_axis(ax.yaxis)
    ax.set_xlabel(_time_label(plotted))


def _pareto_legend(fig: plt.Figure, runs: list[Run], colors: dict[str, str],
                   bases: list[Basis]) -> None:
    techs = sorted({r.technique for r in runs if r.measured})
    handles = [Line2D([], [], marker="o", ls="none", color=colors[t], label=t) for t in techs]
    groups = list(pareto_fronts(runs, bases[0]))
    for style, label in zip(FRONT_STYLES, groups):
        name = f"Pareto front (reference {label})" if len(groups) > 1 else \
            "Pareto front" + (" (matched reference)" if len(bases) > 1 else "")
        handles.append(Line2D([], [], color="black", ls=style, marker="o", mfc="none",
                              label=name))
    if any(b.name == "full" for b in bases):
        handles.append(Line2D([], [], color="black", ls="-", marker="o", mfc="none",
                              label="Pareto front (full reference)"))
    if any(r.status == "nonfinite" for r in runs):
        handles.append(Line2D([], [], marker="X", ls="none", color="#999999", mec="black",
                              label="nonfinite output"))
    fig.legend(handles=handles, loc="upper center", ncol=min(len(handles), 6),
               bbox_to_anchor=(0.5, 0.0), frameon=False)


def pareto_figure(runs: list[Run], colors: dict[str, str], bases: list[Basis], path: str,
                  scene: str) -> None:
    """Mean FLIP and relMSE against median frame time for one scene: one row of two panels per
    basis (errors against the matched reference, and against the full one when measured)."""
    fig, axes = plt.subplots(len(bases), 2, figsize=(10.0, 3.7 * len(bases)), squeeze=False,
                             gridspec_kw={"wspace": 0.28, "hspace": 0.42})
    for row, basis in zip(axes, bases):
        _scatter_panel(row[0], runs, colors, basis, basis.flip, basis.flip_sigma,
                       "mean FLIP (HDR-FLIP) ↓")
        _scatter_panel(row[1], runs, colors, basis, basis.rel_mse, basis.rel_mse_sigma,
                       "relMSE ↓")
        row[0].set_title(f"mean FLIP {basis.caption}", fontsize=9)
        row[1].set_title(f"relMSE {basis.caption}", fontsize=9)
    fig.suptitle(f"{scene}: error against frame time", fontsize=10,
                 y=0.96 if len(bases) == 1 else 0.93)
    _pareto_legend(fig, runs, colors, bases)
    _save(fig, path)


def _sweep_positions(sweep: Sweep) -> tuple[dict[str, float], list[str]]:
    """x position of each value of the swept key (numbers, or 0..n-1 for categories)."""
    runs = [r for members in sweep.series.values() for r in members]
    if sweep.numeric:
        return {text(param_value(r, sweep.key)): sweep_x(r, sweep.key) for r in runs}, []
    labels = sorted({text(param_value(r, sweep.key)) for r in runs})
    return {v: float(i) for i, v in enumerate(labels)}, labels


def _sweep_panel(ax: plt.Axes, sweep: Sweep, color: str, value: Metric, sigma: Metric,
                 positions: dict[str, float], ylabel: str) -> None:
    n = len(sweep.series)
    drawn: list[float] = []
    for i, (others, members) in enumerate(sweep.series.items()):
        tone = shade(color, i, n)
        label = ", ".join(f"{k}={v}" for k, v in zip(sweep.other_keys, others)) or None
        ok = [r for r in members if r.status == "ok" and value(r) is not None]
        xs = [positions[text(param_value(r, sweep.key))] for r in ok]
        ys = [value(r) for r in ok]
        drawn += ys
        ax.errorbar(xs, ys, yerr=_yerr(ok, sigma), fmt="-o", ms=4, lw=1.3, color=tone,
                    elinewidth=0.8, capsize=2, label=label)
        bad = [r for r in members if r.status == "nonfinite" and value(r) is not None]
        if bad:
            drawn += [value(r) for r in bad]
            ax.plot([positions[text(param_value(r, sweep.key))] for r in bad],
                    [value(r) for r in bad], "X", ms=8, color=tone, mec="black", mew=0.8)
    if _wants_log(drawn):
        ax.set_yscale("log")
        _log_axis(ax.yaxis)
    ax.set_ylabel(ylabel)
    ax.set_xlabel(sweep.key)


def _sweep_bounces(sweep: Sweep) -> Optional[int]:
    """The bounce count the swept runs claim, if they all claim the same."""
    claimed = {r.claimed_bounces for members in sweep.series.values() for r in members}
    return claimed.pop() if len(claimed) == 1 else None


def sweep_figure(sweep: Sweep, colors: dict[str, str], path: str,
                 baseline: Optional[Run] = None) -> None:
    """Mean FLIP, relMSE and frame time against the swept parameter (three panels); with a
    baseline run (`direct`), its error against the same reference and its frame time as a
    dashed line."""
    positions, categories = _sweep_positions(sweep)
    color = colors[sweep.technique]
    fig, axes = plt.subplots(1, 3, figsize=(11.0, 3.3), gridspec_kw={"wspace": 0.32})
    bounces = _sweep_bounces(sweep)
    panels = (
        (lambda r: r.final.flip_mean, lambda r: r.final.flip_sigma, "mean FLIP (HDR-FLIP) ↓",
         baseline_value(baseline, bounces, lambda m: m.flip_mean)),
        (lambda r: r.final.rel_mse, lambda r: r.final.rel_mse_sigma, "relMSE ↓",
         baseline_value(baseline, bounces, lambda m: m.rel_mse)),
        (lambda r: r.frame_ms, lambda r: None, "median frame time [ms]",
         baseline.frame_ms if baseline is not None else None),
    )
    for ax, (value, sigma, label, base) in zip(axes, panels):
        _sweep_panel(ax, sweep, color, value, sigma, positions, label)
        if base is not None and baseline is not None:
            ax.axhline(base, ls="--", lw=1.0, color=colors.get(baseline.technique, "#777777"),
                       label=f"{baseline.technique} (same reference)")
        if categories:
            ax.set_xticks(range(len(categories)), categories)
        elif _wants_log(list(positions.values())):
            ax.set_xscale("log", base=2)
            ticks = sorted(set(positions.values()))
            ax.set_xticks(ticks, [f"{t:g}" for t in ticks])
            ax.minorticks_off()
    handles, labels = axes[0].get_legend_handles_labels()
    extra = []
    if any(r.status == "nonfinite" for m in sweep.series.values() for r in m):
        extra = [Line2D([], [], marker="X", ls="none", color="#999999", mec="black",
                        label="nonfinite output")]
    if len(handles) > 1 or extra or baseline is not None:
        fig.legend(handles=handles + extra, loc="upper center",
                   ncol=min(len(handles) + len(extra), 6), bbox_to_anchor=(0.5, -0.04),
                   frameon=False)
    fig.suptitle(f"{sweep.technique} on {sweep.scene}: sweep of {sweep.key}", fontsize=10,
                 color=color, y=1.0)
    _save(fig, path)


def _stacked_bars(ax: plt.Axes, best: list[Run], stacks: list[list[tuple[str, float]]],
                  color: Callable[[Run, str], str]) -> None:
    """One stacked bar per run, its total written above it."""
    for i, (run, stack) in enumerate(zip(best, stacks)):
        bottom = 0.0
        for name, value in stack:
            ax.bar(i, value, bottom=bottom, width=0.6, color=color(run, name),
                   edgecolor="white", linewidth=0.5)
            bottom += value
        if stack:
            ax.text(i, bottom, f"{bottom:.3g}", ha="center", va="bottom", fontsize=8)
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
    _stacked_bars(axes[0], best, frame, lambda run, name: pass_colors[name])
    axes[0].set_ylabel("median GPU time per frame [ms]")
    axes[0].set_title("per-frame GPU time by pass")
    used = list(dict.fromkeys(n for stack in frame for n, _ in stack))
    _legend(axes[0], [(n, pass_colors[n]) for n in reversed(used)])
    _stacked_bars(axes[1], best, setup, setup_color)
    axes[1].set_ylabel("set-up time [ms] (CPU wall clock)")
    axes[1].set_title("one-time set-up by stage")
    entries = [("technique (its colour)", "white")] if any(
        n == "technique" for stack in setup for n, _ in stack) else []
    _legend(axes[1], entries + [(n, stage_colors[n]) for n in reversed(stages)])
    for ax in axes:
        for tick, run in zip(ax.get_xticklabels(), best):
            tick.set_color(tech_colors.get(run.technique, "black"))
    fig.suptitle(f"{scene}: where the time goes (best run per technique)", fontsize=10, y=1.0)
    _save(fig, path)
