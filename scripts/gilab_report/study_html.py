"""Renderings of the cross-technique study (study.py): the error-against-time figure
(SVG for the report, PNG for scripts/findings.py: one drawing function), the report's HTML
section, and the Markdown tables of docs/findings.md. Nothing is computed here that
study.py does not define.
"""
from __future__ import annotations

import html
import sys
import textwrap
from typing import Optional

import matplotlib

if "matplotlib.pyplot" not in sys.modules:  # the caller's backend otherwise (svg or agg)
    matplotlib.use("svg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter  # noqa: E402

from . import cost as C  # noqa: E402
from . import study as S  # noqa: E402
from .analysis import shade, technique_colors  # noqa: E402
from .noise import (NOISY_COLOR, NOISY_GID, NOISY_IQR_FRACTION, NOISY_LABEL,  # noqa: E402
                    noisy_time)
from .templates import Markup, render  # noqa: E402

FRONT_COLOR = "#111111"
STUDY_GID = "study-front-"  # + run key: the ring of a Pareto-front point (SVG id)


def series_colors(series: list[str], tech_colors: Optional[dict[str, str]] = None
                  ) -> dict[str, str]:
    """The technique's colour for its only series; shades of it for several (light to dark)."""
    techs = [s.split(" (")[0] for s in series]
    tech_colors = tech_colors or technique_colors(techs)
    out = {}
    for tech in dict.fromkeys(techs):
        mine = [s for s in series if s.split(" (")[0] == tech]
        base = tech_colors.get(tech, "#888888")
        for i, s in enumerate(mine):
            out[s] = base if len(mine) == 1 else shade(base, i + 1, len(mine) + 1)
    return out


def _log_x(ax) -> None:
    ax.set_xscale("log")
    ax.xaxis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.xaxis.set_minor_formatter(NullFormatter())


def study_figure(st: "S.SceneStudy", colors: dict[str, str], path: str, time_label: str,
                 size: tuple[float, float] = (9.0, 3.8), dpi: int = 100,
                 legend: bool = True) -> None:
    """Left: HDR-FLIP vs full reference against frame time (log), one line per series through
    its runs (by time), ±1σ bars where recorded, IQR bars in time, the Pareto front across all
    series as a black step line with ringed points; right: indirect relMSE (log when it spans
    > 10x). The file format follows the extension (.svg or .png)."""
    fig = plt.figure(figsize=size, dpi=dpi, constrained_layout=True)
    grid = fig.add_gridspec(2, 2, height_ratios=[1.0, 0.55 if legend else 0.01])
    ax1, ax2, box = (fig.add_subplot(grid[0, 0]), fig.add_subplot(grid[0, 1]),
                     fig.add_subplot(grid[1, :]))
    box.axis("off")
    ys2 = []
    for s, pts in st.series.items():
        ranked = [p for p in pts if p.ranked]
        if not ranked:
            continue
        c = colors.get(s, "#888888")
        xs = [p.x for p in ranked]
        xerr = [[p.x_iqr / 2 if p.x_iqr else 0.0 for p in ranked]] * 2
        yerr = [p.y_sigma or 0.0 for p in ranked]
        ax1.errorbar(xs, [p.y for p in ranked], xerr=xerr, yerr=yerr if any(yerr) else None,
                     fmt="o-", ms=4, lw=1.2, color=c, ecolor=c, elinewidth=0.7, capsize=0,
                     label=s)
        paper = [p for p in ranked if p.paper]
        if paper:
            ax1.plot([p.x for p in paper], [p.y for p in paper], "D", ms=7, mfc="none",
                     mec=c, mew=1.0)
        with2 = [p for p in ranked if p.y2 is not None and p.y2 > 0]
        if with2:
            ax2.plot([p.x for p in with2], [p.y2 for p in with2], "o-", ms=4, lw=1.2, color=c,
                     label=s)
            ys2 += [p.y2 for p in with2]
    if st.front:
        fx, fy = [p.x for p in st.front], [p.y for p in st.front]
        ax1.step(fx, fy, where="post", color=FRONT_COLOR, lw=1.0, ls="--", zorder=4,
                 label="Pareto front (all series)")
        for p in st.front:
            ring, = ax1.plot([p.x], [p.y], "o", ms=10, mfc="none", mec=FRONT_COLOR, mew=1.0,
                             zorder=5)
            ring.set_gid(f"{STUDY_GID}{p.key}")
    noisy = [p for p in st.points if p.ranked and noisy_time(p.x, p.x_iqr)]
    for p in noisy:  # a red square, as in the report's other error-against-time figures
        mark, = ax1.plot([p.x], [p.y], "s", ms=13, mfc="none", mec=NOISY_COLOR, mew=1.1,
                         ls="none", zorder=6)
        mark.set_gid(f"{NOISY_GID}{p.key}")
    if noisy:
        ax1.plot([], [], "s", ms=11, mfc="none", mec=NOISY_COLOR, ls="none", label=NOISY_LABEL)
    if st.direct_floor is not None:
        ax1.axhline(st.direct_floor.y, color="#777777", lw=0.8, ls=":", zorder=1)
    for ax in (ax1, ax2):
        xs = [p.x for p in st.points if p.ranked]
        if xs and min(xs) > 0:
            _log_x(ax)
        ax.set_xlabel(time_label)
        ax.grid(True, color="#dddddd", lw=0.6)
        ax.set_axisbelow(True)
    basis = "dynamic frame; error: mean over the frames" if st.animated else "static frame"
    ax1.set_ylabel("HDR-FLIP vs full reference")
    ax1.set_title(f"{st.scene} ({basis})", fontsize=8.5)
    ax2.set_ylabel("relMSE, indirect layer")
    ax2.set_title("indirect layer vs the matched indirect", fontsize=8.5)
    if ys2 and max(ys2) > 10 * min(ys2):
        ax2.set_yscale("log")
    if legend:
        handles, labels = ax1.get_legend_handles_labels()
        # Long series names (several distinguishing settings) wrap instead of widening the
        # legend, which would squeeze both panels.
        labels = [textwrap.fill(label, 38) for label in labels]
        box.legend(handles, labels, loc="center", ncol=2 if size[0] < 8 else 3, fontsize=6,
                   frameon=False)
    fmt = "png" if path.endswith(".png") else "svg"
    fig.savefig(path, format=fmt, dpi=dpi, metadata={"Date": None} if fmt == "svg" else None)
    plt.close(fig)
    if fmt == "png":
        _quantize(path)


def _quantize(path: str) -> None:
    """A 128-colour palette PNG (a third of the size; plots have few colours)."""
    try:
        from PIL import Image
    except ImportError:
        return
    with Image.open(path) as im:
        small = im.convert("RGB").quantize(colors=128)
    small.save(path, optimize=True)


# ------------------------------------------------------------------------------------------------
# HTML (the report): the data for templates/study_*.html.j2
# ------------------------------------------------------------------------------------------------
def _e(x: object) -> str:
    return html.escape(str(x), quote=True)


def _sw(s: str, colors: dict[str, str]) -> str:
    return (f'<span class="sw" style="background:{colors.get(s, "#888")}"></span>{_e(s)}')


def _cell(c: "S.Cell", value: str, tip: str) -> Optional[dict]:
    """A table cell for study_table.html.j2: None ("—") or its class, title, key, value, mark."""
    if c.point is None:
        return None
    cls = "best" if c.best else ("tie" if c.tie else ("comp" if c.compensating else ""))
    mark = " (best)" if c.best else (" (tie)" if c.tie else
                                     (" (compensating)" if c.compensating else ""))
    if c.compensating:
        tip += "; compensating: " + "; ".join(c.point.entry.compensation)
    return {"cls": cls, "title": tip, "key": c.point.key, "value": Markup(value), "mark": mark}


def _point_tip(p: "S.Point") -> str:
    return (f"{p.series} {p.rung}: HDR-FLIP {S.sig3(p.y)}"
            + (f" ± {S.sig3(p.y_sigma)}" if p.y_sigma else "") + f", {S.ms(p.x)}"
            + (f" (IQR {S.ms(p.x_iqr)})" if p.x_iqr else "")).replace("  ", " ")


def _table_data(columns: list["S.Column"], series: list[str], colors: dict[str, str],
                caption: str, head: str, value) -> Optional[dict]:
    """study_table.html.j2's t (None without columns); caption and value(point): HTML."""
    if not columns:
        return None
    rows = []
    for s in series:
        cells = []
        for c in columns:
            cell = c.cells.get(s)
            p = cell.point if cell else None
            cells.append(_cell(cell or S.Cell(), value(p) if p else "—",
                               _point_tip(p) if p else ""))
        rows.append((Markup(_sw(s, colors)), cells))
    return {"caption": Markup(caption), "head": head, "heads": [c.label for c in columns],
            "rows": rows,
            "winners": [("; ".join(c.borderline_why), winners_text(c)) for c in columns],
            "matched": [matched_text(c) for c in columns]}


def _table(columns: list["S.Column"], series: list[str], colors: dict[str, str], caption: str,
           head: str, value) -> str:
    t = _table_data(columns, series, colors, caption, head, value)
    return render("study_table.html.j2", t=t) if t else ""


def _breaks_data(study: "S.Study", colors: dict[str, str], caption: str, device: str) -> dict:
    """study_breaks.html.j2's b; caption: HTML."""
    rows = []
    for b in study.breaks:
        temporal = "; ".join(f"{sc} {S.sig3(v)}" + (f" (floor {S.sig3(f)})" if f else "")
                             for sc, v, f in b.temporal) or "—"
        fails = "; ".join([f"unsupported: {x}" for x in b.unsupported]
                          + [f"NaN/Inf: {x}" for x in b.nonfinite]
                          + [f"validation: {x}" for x in b.invalid]) or "—"
        rows.append({"swatch": Markup(_sw(b.series, colors)),
                     "leak": {None: "—", True: "leaks", False: "no"}[b.leak],
                     "leak_flag": bool(b.leak), "leak_words": b.leak_words,
                     "energy": energy_range(b), "energy_flag": bool(b.energy_flag),
                     "temporal": temporal, "temporal_flag": bool(b.temporal_flag),
                     "setup": setup_range(b), "fails": fails, "fails_flag": fails != "—",
                     "audit": "; ".join(b.audit) or "—"})
    return {"caption": Markup(caption), "device": device, "leak_closed": S.LEAK_CLOSED,
            "leak_open": S.LEAK_OPEN, "rows": rows}


def breaks_table(study: "S.Study", colors: dict[str, str], caption: str, device: str) -> str:
    return render("study_breaks.html.j2", b=_breaks_data(study, colors, caption, device))


def _rules_values(study: "S.Study") -> dict[str, str]:
    return {"fractions": "/".join(f"{f:g}" for f in study.fractions),
            "ratio": f"{S.LEAK_RATIO:g}", "flip": f"{S.LEAK_FLIP:g}",
            "share": f"{100 * S.LEAK_SHARE:g}", "e0": f"{S.ENERGY_BAND[0]:g}",
            "e1": f"{S.ENERGY_BAND[1]:g}", "tf": f"{S.TEMPORAL_FACTOR:g}"}


def rules_html(study: "S.Study") -> str:
    """The study's rules paragraph (templates/study_rules.html.j2)."""
    return render("study_rules.html.j2", **_rules_values(study))


def _floor_values(st: "S.SceneStudy") -> dict[str, str]:
    """The numbers of a scene's "Direct floor" paragraph, formatted."""
    floor = st.direct_floor
    return {"flip": S.sig3(floor.y) if floor else "—", "ms": S.ms(floor.x) if floor else "—",
            "light_flip": S.sig3(st.direct_light_flip),
            "light_energy": S.sig3(st.direct_light_energy),
            "light_leak": (S.sig3(100 * st.direct_light_leak)
                           if st.direct_light_leak is not None else "—"),
            "spp": ", ".join(f"{v:g}" for v in st.reference_spp) or "—",
            "noise_floor": S.sig3(st.rel_mse_noise_floor),
            "flip_floor": (S.sig3(st.flip_floor) if st.flip_floor is not None
                           else "not recorded"),
            "flip_noise": (S.sig3(st.flip_noise) if st.flip_noise is not None
                           else "not recorded")}


NOISY_TIP = (f"noisy timing: the frame time's interquartile range is more than "
             f"{100 * NOISY_IQR_FRACTION:.0f} % of its median (see noisy timings)")


def noisy_mark(p: "S.Point") -> Markup:
    """'⚠ 35 %' after a point's time when its IQR is above NOISY_IQR_FRACTION of it."""
    if not noisy_time(p.x, p.x_iqr):
        return Markup("")
    share = 100.0 * p.x_iqr / p.x
    return Markup(' <span class="noisy" data-noisy="{:.1f}" title="{}">\u26a0 {:.0f} %'
                  "</span>").format(share, NOISY_TIP, share)


def _time_value(p: "S.Point") -> Markup:
    return Markup("{} <small>({}{})</small>").format(S.sig3(p.y), S.ms(p.x), noisy_mark(p))


def _error_value(p: "S.Point") -> Markup:
    return Markup("{}{} <small>({})</small>").format(S.ms(p.x), noisy_mark(p), S.sig3(p.y))


def study_section_html(study: "S.Study", colors: dict[str, str],
                       figures: dict[str, str], figure_url, device_label: str,
                       first: bool = True) -> str:
    """The report's cross-technique section (id="study" on the first device's block);
    figures: scene -> SVG path; figure_url: path -> relative URL; device_label: the time
    headers' device words. '' when no scene has two measured series.
    templates/study_section.html.j2."""
    shown = [sc for sc, st in study.scenes.items()
             if len({p.series for p in st.points if p.ranked}) >= 2]
    if not shown:
        return ""
    caption = Markup("timed on {}; machine {}").format(study.device, study.machine)
    scenes = []
    for scene, st in study.scenes.items():
        if scene not in shown:
            continue
        series = [s for s in study.series if s in st.series]
        scenes.append({
            "name": scene, "leak_test": scene in S.NOT_QUALITY, "floor": _floor_values(st),
            "figure": figure_url(figures[scene]) if scene in figures else None,
            "noisy": sum(1 for p in st.points if p.ranked and noisy_time(p.x, p.x_iqr)),
            "noisy_percent": f"{100 * NOISY_IQR_FRACTION:.0f}",
            "equal_time": _table_data(st.equal_time, series, colors, caption, "series",
                                      _time_value),
            "equal_error": _table_data(st.equal_error, series, colors, caption, "series",
                                       _error_value)})
    return render("study_section.html.j2", first=first,
                  rules=Markup(rules_html(study)) if first else "", device=study.device,
                  machine=study.machine, caption=caption, scenes=scenes,
                  device_label=device_label, cost=_cost_data(study, colors, device_label),
                  breaks=_breaks_data(study, colors, caption, device_label))


# ------------------------------------------------------------------------------------------------
# Markdown (docs/findings.md)
# ------------------------------------------------------------------------------------------------
def winners_text(c: "S.Column") -> str:
    """'a, b (borderline); compensating: c': the column's verdict with its marks."""
    out = ", ".join(c.winners) or "—"
    if c.borderline:
        out += " (borderline)"
    if c.compensating:
        out += "; compensating: " + ", ".join(c.compensating)
    return out


def matched_text(c: "S.Column") -> str:
    """The matched-basis winner, and whether it disagrees with the headline's."""
    if c.matched_winner is None:
        return "—"
    agree = c.winners and c.matched_winner == c.winners[0]
    return c.matched_winner + ("" if agree else " (differs)")


def _md_cell(c: "S.Cell", value: str) -> str:
    if c.point is None:
        return "—"
    return f"**{value}**" if c.best else (f"{value} (tie)" if c.tie else
                                          (f"{value} (compensating)" if c.compensating
                                           else value))


def md_table(columns: list["S.Column"], series: list[str], value) -> str:
    if not columns:
        return "(no targets: no direct floor)\n"
    out = ["| series | " + " | ".join(c.label for c in columns) + " |",
           "|---|" + "---|" * len(columns)]
    for s in series:
        out.append(f"| {s} | " + " | ".join(
            _md_cell(c.cells.get(s, S.Cell()), value(c.cells[s].point)
                     if c.cells.get(s) and c.cells[s].point else "—") for c in columns) + " |")
    out.append("| best (and ties) | " + " | ".join(winners_text(c) for c in columns) + " |")
    out.append("| best on the matched basis | " + " | ".join(matched_text(c) for c in columns)
               + " |")
    return "\n".join(out) + "\n"


def setup_range(b: "S.Breaks") -> str:
    """'a – b' over the runs that built everything, then '(cached: c – d)' where a run loaded
    its precomputation from the cache (topovpl's topology)."""
    out = f"{S.sig3(b.setup_min)} – {S.sig3(b.setup_max)}" if b.setup_min is not None else ""
    if b.cached_setup_min is not None:
        out += (" " if out else "") + (f"(cached: {S.sig3(b.cached_setup_min)} – "
                                        f"{S.sig3(b.cached_setup_max)})")
    return out or "—"


def energy_range(b: "S.Breaks") -> str:
    """'0.3 (scene) – 2.2 (scene)': the extremes of the energy ratio and where."""
    if b.energy_min is None:
        return "—"
    return (f"{S.sig3(b.energy_min)} ({b.energy_min_scene}) – "
            f"{S.sig3(b.energy_max)} ({b.energy_max_scene})")


def md_breaks(study: "S.Study") -> str:
    out = ["| series | leak (rooms_closed) | energy ratio range | temporal instability (matched) | "
           "set-up ms | unsupported / NaN / invalid | audit thin-wall/leak cells |",
           "|---|---|---|---|---|---|---|"]
    for b in study.breaks:
        leak = {None: "—", True: "**leaks**", False: "no"}[b.leak]
        out.append(
            f"| {b.series} | {leak} ({b.leak_words}) | "
            + (energy_range(b) + (" **outside**" if b.energy_flag else "")
               if b.energy_min is not None else "—")
            + " | " + ("; ".join(f"{sc} {S.sig3(v)} (floor {S.sig3(f)})"
                                  for sc, v, f in b.temporal) or "—")
            + (" **unstable**" if b.temporal_flag else "") + " | "
            + (setup_range(b) if b.setup_min is not None or b.cached_setup_min is not None
               else "—") + " | "
            + ("; ".join([f"unsupported: {x}" for x in b.unsupported]
                         + [f"NaN/Inf: {x}" for x in b.nonfinite]
                         + [f"validation: {x}" for x in b.invalid]) or "—").replace("|", "/")
            + " | " + ("; ".join(b.audit) or "—") + " |")
    return "\n".join(out) + "\n"


# ------------------------------------------------------------------------------------------------
# The first screen (report and findings): the verdict table, then a line per scene
# ------------------------------------------------------------------------------------------------
def _noise_words(study: "S.Study", series: str) -> str:
    tech = series.partition(" (")[0]
    t, k = study.time_spread.get(tech), study.seed_spread.get(tech)
    return (f"time ±{100 * t:.0f} %" if t is not None else "time: own IQR") + ", " + \
        (f"seeds ±{S.sig3(k)}" if k is not None else "seeds: not run")


def _reach_words(reach: Optional[tuple[float, float, int]]) -> str:
    if reach is None:
        return "—"
    lo, hi, n = reach
    return f"{S.sig3(lo)} – {S.sig3(hi)} ms ({n} scene{'' if n == 1 else 's'})"


def verdict_screen_html(study: "S.Study", colors: dict[str, str]) -> str:
    """The first screen's verdict: technique x budget on the full basis, marks, per-scene
    lines; '' when no quality scene has two ranked series."""
    table = S.verdict_table(study)
    reach = S.ladder_reach(study)
    if not any(c.wins for cells in table.values() for c in cells):
        return ""
    rows = []
    for s in study.series:
        cells = [(("best" if c.wins else ("tie" if c.ties else ""))
                  + (" comp" if c.compensating and not c.wins else ""),
                  "; ".join(x for x in (
                      f"wins: {', '.join(c.wins)}" if c.wins else "",
                      f"ties: {', '.join(c.ties)}" if c.ties else "",
                      f"borderline: {', '.join(c.borderline)}" if c.borderline else "",
                      f"compensating: {', '.join(c.compensating)}" if c.compensating else "",
                      f"beats the winner: {', '.join(c.beats)}" if c.beats else "")
                           if x), c.text()) for c in table[s]]
        rows.append((Markup(_sw(s, colors)), cells, _reach_words(reach.get(s)),
                     _noise_words(study, s)))
    return render("verdict.html.j2", scenes=len(S.quality_scenes(study)), device=study.device,
                  caveat=S.DEVICE_CAVEAT, budgets=[f"{b:g}" for b in study.budgets], rows=rows,
                  lines=S.scene_lines(study))


def md_verdict(study: "S.Study") -> list[str]:
    """The same verdict as Markdown lines (docs/findings.md's first section)."""
    table = S.verdict_table(study)
    reach = S.ladder_reach(study)
    out = ["## Verdict", "",
           f"Lowest HDR-FLIP against the full reference within each frame-time budget, over "
           f"{len(S.quality_scenes(study))} scene"
           f"{'' if len(S.quality_scenes(study)) == 1 else 's'}; timed on {study.device}; "
           f"{S.DEVICE_CAVEAT}. Marks: docs/report.md, \"Verdict rules\".", "",
           "| series | " + " | ".join(f"≤ {b:g} ms" for b in study.budgets)
           + " | ladder reach | noise in the rules |",
           "|---|" + "---|" * (len(study.budgets) + 2)]
    for s in study.series:
        out.append(f"| {s} | " + " | ".join(c.text() for c in table[s])
                   + f" | {_reach_words(reach.get(s))} | {_noise_words(study, s)} |")
    out += ["", "Per scene (time-free verdicts first: equal error, then equal time):", ""]
    out += [f"- {line}" for line in S.scene_lines(study)]
    return out + [""]


# ------------------------------------------------------------------------------------------------
# Whole cost (cost.py)
# ------------------------------------------------------------------------------------------------
TIMED_COST_COLUMNS = ("static frame", "set-up cold", "set-up cached", "light moves",
                      "camera moves", "fixed", "per Mpixel", "at 1920x1080")


def cost_head(device: str) -> list[str]:
    """The whole-cost table's headers; every time column names the device ('…, lavapipe
    (CPU), ms')."""
    timed = {c: f"{c}, {device}, ms" for c in TIMED_COST_COLUMNS}
    return ["series", "rung", "scenes", timed["static frame"], "memory, MiB (own)",
            timed["set-up cold"], timed["set-up cached"], timed["light moves"],
            timed["camera moves"], "payback, frames", timed["fixed"], timed["per Mpixel"],
            timed["at 1920x1080"]]


def cost_cells(c: "C.CostRow") -> list[str]:
    def t(x: Optional[float]) -> str:
        return S.sig3(x)
    series = c.series + (" (CPU path tracer: its CPU clock)"
                         if c.series.partition(" (")[0] == S.PATH_TRACER else "")
    return [series, c.rung or "defaults", str(c.scenes) if c.scenes else "—", t(c.static_ms),
            (f"{S.sig3(c.memory_mib)} ({S.sig3(c.own_memory_mib)})"
             if c.memory_mib is not None else "—"), t(c.setup_ms), t(c.setup_cached_ms),
            t(c.light_ms), t(c.camera_ms), S.sig3(c.payback_frames),
            S.sig3(c.split.fixed_ms) if c.split else "—",
            S.sig3(c.split.per_mpixel_ms) if c.split else "—", t(c.full_hd_ms)]


COST_NOTE = ("static frame: median over the quality scenes; light / camera moves: the dynamic "
             "frame (update included) of an animated scene whose light / camera moves; payback: "
             "set-up / (light-move frame − static frame), the frames a precomputation must stay "
             "valid to cost less than redoing the update each frame; fixed and per-pixel parts "
             "from the rung timed at two image sizes (t = fixed + per-pixel × pixels), "
             "extrapolated to 1920 × 1080 (a negative fixed part is noise or a cost that grows "
             "faster than the pixel count)")


def _cost_data(study: "S.Study", colors: dict[str, str], device: str) -> Optional[dict]:
    """study_cost.html.j2's c (None without rows)."""
    rows = C.whole_cost(study)
    if not rows:
        return None
    cells = [cost_cells(c) for c in rows]
    return {"device": study.device, "machine": study.machine, "heads": cost_head(device),
            "rows": [(Markup(_sw(v[0], colors)), v[1:]) for v in cells], "note": COST_NOTE}


def cost_table_html(study: "S.Study", colors: dict[str, str], device: str) -> str:
    c = _cost_data(study, colors, device)
    return render("study_cost.html.j2", c=c) if c else ""


def _short_device(device: str) -> str:
    return "lavapipe (CPU)" if "lavapipe" in device else device


def md_cost(study: "S.Study") -> list[str]:
    rows = C.whole_cost(study)
    if not rows:
        return []
    out = ["## Whole cost", "", f"Timed on {study.device}, {study.machine}. {COST_NOTE}.", "",
           "| " + " | ".join(cost_head(_short_device(study.device))) + " |",
           "|" + "---|" * len(cost_head(""))]
    out += ["| " + " | ".join(cost_cells(c)) + " |" for c in rows]
    splits = [f"{c.series} {c.rung}: {c.split_where}".replace("  ", " ") for c in rows
              if c.split]
    if splits:
        out += ["", "Two-size pairs: " + "; ".join(splits) + "."]
    return out + [""]
