"""Cross-technique analysis of a study (several techniques, each along its quality ladder, on the
same scenes): series, Pareto fronts, equal-time and equal-error tables, the direct floor, and
where each series breaks. Pure functions of the result rows; the report (study_html.py)
and scripts/findings.py render what this module computes. Every rule and threshold is defined
here once and documented in docs/report.md ("Cross-technique study").

A **row** is one run as the runner's results.csv / results.jsonl row (experiments/runner/
run_store.cpp `resultRow`, the same column names): `scene`, `technique`, `status`, `swept`
(space-separated swept keys), `param.<key>`, `frame_gpu_ms_median`, `full.flip`, ... Values may be
numbers or strings (a csv row) or missing/None; nothing here raises on a bad value.
`row_from_result` makes such a row from a result.json (plus `host`, `cpu`, `direct.energy_ratio`,
`direct.shadow_leak`, which the csv does not have).
"""
from __future__ import annotations

import json
import math
import os
import statistics
from dataclasses import dataclass, field
from typing import Any, Iterable, Optional

from . import paper_facts as PF
from . import verdicts as V
from .data import dig

# ------------------------------------------------------------------------------------------------
# Rules and thresholds (docs/report.md, "Cross-technique study")
# ------------------------------------------------------------------------------------------------
BUDGETS_MS = (50.0, 200.0, 1000.0)  # equal-time budgets (frame time <= budget)
# Equal-error targets: these fractions of the scene's direct floor (the `direct` run's HDR-FLIP
# vs the full reference: the error of leaving out all indirect light).
ERROR_FRACTIONS = (0.9, 0.75, 0.6, 0.45)
BASELINE = "direct"
LEAK_CLOSED, LEAK_OPEN = "rooms_closed", "rooms_open"  # door closed / open, same camera
LEAK_RATIO = 2.0  # energy_ratio(closed) / energy_ratio(open) above this: a leak
LEAK_FLIP = 0.01  # HDR-FLIP vs the closed scene's (black) full reference above this: a leak
LEAK_SHARE = 0.01  # indirect light seen with the door closed / the open reference's: a leak
ENERGY_BAND = (0.5, 2.0)  # energy ratio outside: flagged (the audit's amber band, docs/audit.md)
# Temporal instability against the bounce-matched frames (flicker and lag of the light the
# technique claims; vs the full frames the missing bounces' change would dominate): flagged
# above this x the lowest instability of any GI series on the same scene. Every GI series
# measured 2.5-6.2x the reference noise floor on the study's sequences, so an absolute floor
# rule would flag them all.
TEMPORAL_FACTOR = 1.5
# Scenes that test a failure, not quality: the door-closed rooms' reference is black, so an
# error there is a leak; they are left out of the findings' winners and the glance table.
NOT_QUALITY = (LEAK_CLOSED,)
THIN_WALL_CASES = ("thin_wall", "light_through_wall")  # audit cases shown (name prefixes)
# Paper facts (the paper rung, our choices against the paper's) come from each technique's
# techniques/<id>/paper.json (paper_facts.py); none is typed here.


def paper_rungs() -> dict[str, dict[str, object]]:
    """technique -> its paper rung (paper_facts.PaperFacts.paper_rung)."""
    return {t: f.paper_rung for t, f in PF.load_all().items()}


def our_choices() -> list[tuple[str, dict[str, object], dict[str, object]]]:
    """(technique, our values, the paper's values) of each technique's design choices, together:
    findings ask whether a winner changes when only the paper's variant is allowed."""
    out = []
    for t, f in PF.load_all().items():
        if f.design_choices:
            out.append((t, {c.param: c.ours for c in f.design_choices},
                        {c.param: c.paper for c in f.design_choices}))
    return out


def _same_value(a: object, b: object) -> bool:
    """Parameter values as the rows spell them: '1.5' == 1.5, '0.0' == 0, 'paper' == 'paper'."""
    try:
        return float(str(a)) == float(str(b))
    except ValueError:
        return str(a) == str(b)


def series_params(series: str) -> tuple[str, dict[str, str]]:
    """'vct (lift=0.0)' -> ('vct', {'lift': '0.0'})."""
    tech, _, rest = series.partition(" (")
    parts = [p.split("=", 1) for p in rest.rstrip(")").split(", ") if "=" in p]
    return tech, {k: v for k, v in parts}


def our_choice_pairs(series: Iterable[str]) -> list[tuple[str, str]]:
    """(our series, the paper's series) of each our_choices() entry that the study ran both of:
    the series whose series parameters hold every one of our values, and the one that holds
    every one of the paper's."""
    def find(tech: str, want: dict[str, object]) -> Optional[str]:
        for s in series:
            t, ps = series_params(s)
            if t == tech and all(k in ps and _same_value(ps[k], v) for k, v in want.items()):
                return s
        return None
    out = []
    for tech, ours, paper in our_choices():
        a, b = find(tech, ours), find(tech, paper)
        if a and b:
            out.append((a, b))
    return out


def fnum(value: Any) -> Optional[float]:
    """A finite float from a number or a numeric string, else None."""
    if isinstance(value, bool) or value is None:
        return None
    if isinstance(value, str):
        try:
            value = float(value)
        except ValueError:
            return None
    if not isinstance(value, (int, float)):
        return None
    value = float(value)
    return value if math.isfinite(value) else None


def fstr(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    return str(value)


def sig3(x: Optional[float], digits: int = 3) -> str:
    """3 significant digits ('—' for None); no exponent between 1e-3 and 1e5."""
    if x is None:
        return "—"
    if x == 0:
        return "0"
    x = float(f"{x:.{digits}g}")  # rounded first: 0.99983 is 1.00, not 1.000
    if 1e-3 <= abs(x) < 1e5:
        decimals = max(0, digits - 1 - int(math.floor(math.log10(abs(x)))))
        return f"{x:.{decimals}f}"
    return f"{x:.{digits - 1}e}"


def ms(x: Optional[float]) -> str:
    return "—" if x is None else f"{sig3(x)} ms"


# ------------------------------------------------------------------------------------------------
# Rows
# ------------------------------------------------------------------------------------------------


def _metric_columns(row: dict, prefix: str, m: Any) -> None:
    if not isinstance(m, dict):
        return
    row[f"{prefix}.flip"] = dig(m, "flip", "mean")
    row[f"{prefix}.flip_noise"] = dig(m, "error_bars", "flip", "spread")
    # The HDR-FLIP of the reference's own noise (an exact image would score this).
    row[f"{prefix}.flip_floor"] = dig(m, "error_bars", "flip", "floor_mean")
    row[f"{prefix}.rel_mse"] = m.get("rel_mse")
    row[f"{prefix}.rel_mse_noise_floor"] = dig(m, "error_bars", "rel_mse_noise_floor")


def row_from_result(data: dict) -> dict:
    """The runner's row (run_store.cpp resultRow, the columns this module reads) of a
    result.json, plus host, cpu and the direct light's energy ratio and shadow leak."""
    d = data if isinstance(data, dict) else {}
    params = dig(d, "technique", "params")
    swept = dig(d, "technique", "swept")
    row: dict = {
        "key": d.get("key"), "scene": dig(d, "scene", "label"),
        "technique": dig(d, "technique", "id"), "status": d.get("status"),
        "bounces": dig(d, "technique", "indirect_bounces"),
        "reason": d.get("reason"), "swept": " ".join(swept) if isinstance(swept, dict) else "",
        "setup_ms": dig(d, "timing", "setup_ms", "total"),
        "topology_cache_hit": dig(d, "stats", "topology_cache_hit"),
        "frame_gpu_ms_median": dig(d, "timing", "frame_gpu_ms", "median"),
        "frame_gpu_ms_iqr": dig(d, "timing", "frame_gpu_ms", "iqr"),
        "frame_cpu_ms_median": dig(d, "timing", "frame_cpu_ms", "median"),
        "frame_cpu_ms_iqr": dig(d, "timing", "frame_cpu_ms", "iqr"),
        "reference_samples": dig(d, "reference", "samples"),
        "resolution": "x".join(str(v) for v in dig(d, "scene", "resolution") or []) or None,
        "scene_source": (f"{dig(d, 'scene', 'path') or ''}#{dig(d, 'scene', 'variant') or ''}"
                         if dig(d, "scene", "path") is not None else None),
        "animation_moves": " ".join(m for m in dig(d, "animation", "moves") or []
                                    if isinstance(m, str)) or None,
        "memory_total_bytes": dig(d, "memory", "total_bytes"),
        # The technique's own allocations: every owner but the scene and the shared passes.
        "memory_technique_bytes": sum(v for k, v in (dig(d, "memory", "by_owner") or {}).items()
                                      if k not in ("scene", "shared")
                                      and isinstance(v, (int, float)))
        if isinstance(dig(d, "memory", "by_owner"), dict) else None,
        "reference_matched": dig(d, "reference", "matched"),
        "energy_ratio": dig(d, "metrics", "energy_ratio"),
        "direct.energy_ratio": dig(d, "metrics", "direct", "energy_ratio"),
        "direct.shadow_leak": dig(d, "metrics", "direct", "shadow_leak"),
        "device": dig(d, "device", "name"), "device_type": dig(d, "device", "type"),
        "host": d.get("host") or dig(d, "provenance", "host"),
        "cpu": dig(d, "provenance", "cpu"),
        "hardware_threads": dig(d, "provenance", "hardware_threads"),
        "git_commit": dig(d, "provenance", "git_commit"), "date": dig(d, "provenance", "date"),
    }
    for key, value in (params.items() if isinstance(params, dict) else []):
        row[f"param.{key}"] = value
    if isinstance(d.get("repeat"), int):  # the runner's repeat index (REPEAT_KEYS)
        row["param.repeat"] = d["repeat"]
    for prefix, path in (("full", "final_vs_full"), ("matched", "final"),
                         ("indirect", "indirect"), ("direct", "direct")):
        _metric_columns(row, prefix, dig(d, "metrics", path))
    # The bounce floors: the exact 0/1/2-bounce images against the full reference.
    for b in FLOOR_BOUNCES:
        _metric_columns(row, f"floor{b}", dig(d, "metrics", "bounce_floors", str(b)))
    nonfinite = d.get("nonfinite")
    if isinstance(nonfinite, dict):
        row["nan_pixels"] = sum(fnum(dig(c, "nan_pixels")) or 0 for c in nonfinite.values())
        row["inf_pixels"] = sum(fnum(dig(c, "inf_pixels")) or 0 for c in nonfinite.values())
    if isinstance(d.get("animation"), dict):
        row["animation_frames"] = dig(d, "animation", "frames")
        row["update_kind"] = dig(d, "animation", "update")
        row["dynamic_frame_gpu_ms_median"] = dig(d, "timing", "dynamic_frame_gpu_ms", "median")
        row["dynamic_frame_gpu_ms_iqr"] = dig(d, "timing", "dynamic_frame_gpu_ms", "iqr")
        row["dynamic_frame_cpu_ms_median"] = dig(d, "timing", "dynamic_frame_cpu_ms", "median")
        seq = dig(d, "metrics", "sequence")
        row["sequence.full.flip_mean"] = dig(seq, "full_flip_mean")
        row["sequence.temporal.instability"] = dig(seq, "temporal", "temporal_instability")
        row["sequence.temporal.noise_floor"] = dig(seq, "temporal", "noise_floor")
        row["sequence.temporal_matched.instability"] = dig(seq, "temporal_matched",
                                                           "temporal_instability")
        row["sequence.temporal_matched.noise_floor"] = dig(seq, "temporal_matched",
                                                           "noise_floor")
    return row


def rows_from_runs(runs: Iterable[Any]) -> list[dict]:
    """Rows of data.py Run records (their result.json in run.data)."""
    out = []
    for run in runs:
        row = row_from_result(getattr(run, "data", {}) or {})
        row["status"] = getattr(run, "status", row.get("status"))
        row["_folder"] = getattr(run, "folder", None)
        out.append(row)
    return out


LEAK_MAX_PIXELS = 262144  # EXRs read for the leak share (larger ones are left unread)


def _luminance_sum(path: Optional[str], layer: str) -> Optional[float]:
    """Σ Rec. 709 luminance of an EXR's '<layer>.R/G/B' (layer '' : R, G, B), finite pixels."""
    if not path or not os.path.isfile(path):
        return None
    from .exr import ExrImage, read_exr

    prefix = f"{layer}." if layer else ""
    image = read_exr(path, LEAK_MAX_PIXELS, {prefix + c for c in "RGB"})
    if not isinstance(image, ExrImage) or not all(prefix + c in image.channels for c in "RGB"):
        return None
    r, g, b = (image.channels[prefix + c] for c in "RGB")
    total = 0.0
    for y in (0.2126 * x + 0.7152 * yy + 0.0722 * z for x, yy, z in zip(r, g, b)):
        if math.isfinite(y):
            total += y
    return total


def add_leak_shares(rows: list[dict], runs: Iterable[Any]) -> None:
    """Sets `leak.share` on the door-closed scene's rows: Σ luminance of the run's indirect
    layer (outputs.exr) over Σ luminance of the door-open reference's indirect light (full.exr
    minus emission+direct.exr); same camera and resolution. Left unset when a file is missing
    or unreadable."""
    runs = list(runs)
    open_ref = None
    for run in runs:
        if getattr(run, "scene", None) == LEAK_OPEN and hasattr(run, "reference_path"):
            full = _luminance_sum(run.reference_path("full_exr"), "")
            base = run.reference_path("full_exr")
            direct = _luminance_sum(os.path.join(os.path.dirname(base), "emission+direct.exr")
                                    if base else None, "")
            if full is not None and direct is not None and full - direct > 0:
                open_ref = full - direct
                break
    if open_ref is None:
        return
    for row, run in zip(rows, runs):
        if row.get("scene") == LEAK_CLOSED and row.get("status") in ("ok", "nonfinite"):
            seen = _luminance_sum(run.output_path("exr"), "indirect")
            if seen is not None:
                row["leak.share"] = seen / open_ref


def load_rows(dirs: list[str], unreadable: Optional[list[str]] = None) -> list[dict]:
    """Every committed run of the folders (data.py's reader: shards merged, in-progress
    folders ignored) as rows; an unreadable run folder is left out and, given `unreadable`,
    added to it as 'path: why'."""
    from .data import load_results

    results = load_results(dirs)
    if unreadable is not None:
        unreadable += [f"{u.path}: {u.why}" for u in results.unreadable]
    runs = results.runs
    rows = rows_from_runs(runs)
    add_leak_shares(rows, runs)
    return rows


# ------------------------------------------------------------------------------------------------
# Series and points
# ------------------------------------------------------------------------------------------------
# Parameters that never change the image (caches, diagnostics): runs that differ only in them
# belong to one series (topovpl's topology_cache = off times the cold set-up, docs/report.md).
NOT_SERIES_KEYS = {"topology_cache", "same_cluster_stat"}
# Parameters whose runs are repeats of one configuration: a technique's sampling seed (the error
# spread it causes) and a repeat index (timing). Their runs are pooled into one point (means)
# and give the pooled seed and time spreads of verdicts.py.
REPEAT_KEYS = {"seed", "repeat"}
FLOOR_BOUNCES = (0, 1, 2)


def cached_setup(row: dict) -> bool:
    """The set-up loaded a cached precomputation (topovpl's topology) instead of building it."""
    return fnum(row.get("topology_cache_hit")) == 1.0


def ladder_keys(rows: list[dict]) -> dict[str, set[str]]:
    """technique -> the union of its runs' swept keys (its ladder's knobs), repeat keys (a
    sweep over `seed`) left out: they repeat a rung, they are not one."""
    out: dict[str, set[str]] = {}
    for r in rows:
        keys = [k for k in fstr(r.get("swept")).split() if k not in REPEAT_KEYS]
        out.setdefault(fstr(r.get("technique")), set()).update(keys)
    return out


def _params(row: dict) -> dict[str, str]:
    return {k[len("param."):]: fstr(v) for k, v in row.items()
            if k.startswith("param.") and v is not None and fstr(v) != ""}


def series_keys(rows: list[dict]) -> dict[str, list[str]]:
    """technique -> the parameters that tell its blocks apart: not on its ladder and with more
    than one value among its runs of one scene (e.g. cvgi's `gather`)."""
    ladders = ladder_keys(rows)
    values: dict[tuple[str, str, str], set[str]] = {}
    for r in rows:
        tech = fstr(r.get("technique"))
        for k, v in _params(r).items():
            if (k not in ladders.get(tech, set()) and k not in NOT_SERIES_KEYS
                    and k not in REPEAT_KEYS):
                values.setdefault((tech, fstr(r.get("scene")), k), set()).add(v)
    out: dict[str, set[str]] = {}
    for (tech, _, k), vs in values.items():
        if len(vs) > 1:
            out.setdefault(tech, set()).add(k)
    return {t: sorted(ks) for t, ks in out.items()}


def series_name(row: dict, keys: dict[str, list[str]]) -> str:
    tech = fstr(row.get("technique")) or "?"
    ps = _params(row)
    parts = [f"{k}={ps[k]}" for k in keys.get(tech, []) if k in ps]
    return f"{tech} ({', '.join(parts)})" if parts else tech


def rung_text(row: dict, ladders: dict[str, set[str]]) -> str:
    """The run's ladder values, 'voxel_resolution=128 diffuse_cones=3' ('' without a ladder)."""
    ps = _params(row)
    return " ".join(f"{k}={ps[k]}" for k in sorted(ladders.get(fstr(row.get("technique")), ()))
                    if k in ps)


def is_paper_rung(row: dict, series: str) -> Optional[bool]:
    """Whether the run is at the paper's settings (None: no paper rung defined)."""
    rung = paper_rungs().get(series.partition(" (")[0])
    if rung is None:
        return None
    ps = _params(row)
    return all(k in ps and _same_value(ps[k], v) for k, v in rung.items())


def animated_scene(rows: list[dict]) -> bool:
    return any(r.get("animation_frames") is not None or
               fnum(r.get("dynamic_frame_gpu_ms_median")) is not None or
               fnum(r.get("dynamic_frame_cpu_ms_median")) is not None for r in rows)


@dataclass
class Point:
    """One configuration of a series on a scene (its seed / repeat runs pooled into one: mean
    time and error, REPEAT_KEYS)."""

    row: dict
    series: str
    status: str
    x: Optional[float]  # frame time, ms (static; dynamic on an animated scene)
    x_iqr: Optional[float]
    y: Optional[float]  # HDR-FLIP vs full reference (mean over the frames when animated)
    y_sigma: Optional[float]  # its ±1σ from the reference noise (None: not recorded)
    y2: Optional[float]  # indirect relMSE
    rung: str = ""
    paper: Optional[bool] = None
    cpu_clock: bool = False  # x is a CPU-clock time (no timestamps)
    repeats: int = 1  # runs pooled into this point
    entry: V.Entry = field(default_factory=lambda: V.Entry("", "", None, None))

    @property
    def ranked(self) -> bool:
        return self.status == "ok" and self.x is not None and self.y is not None

    @property
    def key(self) -> str:
        return fstr(self.row.get("key"))

    @property
    def compensating(self) -> bool:
        return self.entry.compensating


def _bounces(row: dict) -> Optional[int]:
    b = fnum(row.get("bounces"))
    return None if b is None else int(b)


def make_point(row: dict, series: str, animated: bool, ladders: dict[str, set[str]]) -> Point:
    prefix = "dynamic_frame" if animated else "frame"
    x, iqr = fnum(row.get(f"{prefix}_gpu_ms_median")), fnum(row.get(f"{prefix}_gpu_ms_iqr"))
    cpu = False
    if x is None:
        x, iqr = fnum(row.get(f"{prefix}_cpu_ms_median")), fnum(row.get(f"{prefix}_cpu_ms_iqr"))
        cpu = x is not None
    y = fnum(row.get("sequence.full.flip_mean")) if animated else None
    sigma = None
    if y is None:
        y, sigma = fnum(row.get("full.flip")), fnum(row.get("full.flip_noise"))
    p = Point(row=row, series=series, status=fstr(row.get("status")) or "?", x=x, x_iqr=iqr,
              y=y, y_sigma=sigma, y2=fnum(row.get("indirect.rel_mse")),
              rung=rung_text(row, ladders), paper=is_paper_rung(row, series), cpu_clock=cpu)
    p.entry = _entry(p)
    return p


def _entry(p: Point) -> V.Entry:
    """The verdict rules' view of a point (verdicts.Entry); spreads are set by analyse()."""
    b = _bounces(p.row)
    floor = floor_sigma = None
    if b is not None and b in FLOOR_BOUNCES:
        floor, floor_sigma = (fnum(p.row.get(f"floor{b}.flip")),
                              fnum(p.row.get(f"floor{b}.flip_noise")))
    return V.Entry(key=p.key, series=p.series, time=p.x if p.ranked else None,
                   error=p.y if p.ranked else None, error_sigma=p.y_sigma or 0.0,
                   matched=fnum(p.row.get("matched.flip")),
                   energy=fnum(p.row.get("energy_ratio")),
                   matched_sigma=fnum(p.row.get("matched.flip_noise")) or 0.0,
                   bounces=b, floor=floor, floor_sigma=floor_sigma or 0.0)


def _config_key(row: dict) -> tuple:
    """What makes runs repeats of one configuration: scene, technique and every parameter but
    REPEAT_KEYS."""
    return (fstr(row.get("scene")), fstr(row.get("technique")),
            tuple(sorted((k, v) for k, v in _params(row).items() if k not in REPEAT_KEYS)))


def pool_repeats(points: list[Point]) -> list[Point]:
    """One point per configuration: its repeats' mean time and error (the first run's row).
    A configuration with a failed repeat keeps that failure's status."""
    groups: dict[tuple, list[Point]] = {}
    for i, p in enumerate(points):
        repeat = any(k in _params(p.row) for k in REPEAT_KEYS)  # else never pooled
        groups.setdefault((p.series,) + _config_key(p.row) + (() if repeat else (i,)),
                          []).append(p)
    out = []
    for pts in groups.values():
        if len(pts) == 1:
            out.append(pts[0])
            continue
        bad = [p for p in pts if p.status != "ok"]
        p = bad[0] if bad else pts[0]
        if not bad:
            xs = [q.x for q in pts if q.x is not None]
            ys = [q.y for q in pts if q.y is not None]
            p = Point(**{**p.__dict__, "x": statistics.fmean(xs) if xs else None,
                         "y": statistics.fmean(ys) if ys else None, "repeats": len(pts)})
            p.entry = _entry(p)
            for attr in ("matched", "floor"):  # means of the repeats too
                vals = [getattr(q.entry, attr) for q in pts if getattr(q.entry, attr) is not None]
                setattr(p.entry, attr, statistics.fmean(vals) if vals else None)
        out.append(p)
    return out


def noise_spreads(rows: list[dict]) -> tuple[dict[str, float], dict[str, float]]:
    """Per technique: the pooled relative between-run spread of the static frame time and the
    pooled spread of the full-basis HDR-FLIP, over groups of runs that differ only in
    REPEAT_KEYS (verdicts.pooled_relative_spread / pooled_spread). A technique with no repeats
    is absent (its spread is unmeasured: 0 in the rules, said in the report)."""
    times: dict[str, dict[tuple, list[float]]] = {}
    errors: dict[str, dict[tuple, dict[str, list[float]]]] = {}  # tech -> config -> seed -> e
    for r in rows:
        if fstr(r.get("status")) != "ok":
            continue
        tech, key = fstr(r.get("technique")), _config_key(r)
        t = fnum(r.get("frame_gpu_ms_median"))
        if t is None:
            t = fnum(r.get("frame_cpu_ms_median"))
        if t is not None:
            times.setdefault(tech, {}).setdefault(key, []).append(t)
        e = fnum(r.get("full.flip"))
        if "seed" in _params(r) and e is not None:
            errors.setdefault(tech, {}).setdefault(key, {}).setdefault(
                _params(r)["seed"], []).append(e)
    time_spread = {t: v for t, g in times.items()
                   if (v := V.pooled_relative_spread(g.values())) is not None}
    # One error per seed (timing repeats of one seed give the same image), groups of >= 2 seeds
    seed_spread = {t: v for t, g in errors.items()
                   if (v := V.pooled_spread([statistics.fmean(es) for es in by_seed.values()]
                                            for by_seed in g.values())) is not None}
    return time_spread, seed_spread


# ------------------------------------------------------------------------------------------------
# Rules: verdicts.py defines them; these adapt its verdicts to the tables' columns
# ------------------------------------------------------------------------------------------------
def pareto(points: list[Point]) -> list[Point]:
    """verdicts.pareto over the ranked points; sorted by time."""
    by_entry = {id(p.entry): p for p in points if p.ranked}
    return [by_entry[id(e)] for e in V.pareto(p.entry for p in points if p.ranked)]


def error_tie(a: Point, best: Point) -> bool:
    """verdicts.error_tie: |e_a - e_best| <= sqrt(σ_a² + σ_best² + seed spreads²)."""
    return V.error_tie(a.entry, best.entry)


def time_tie(a: Point, best: Point) -> bool:
    """verdicts.time_tie: within the pooled relative time spreads of both."""
    return V.time_tie(a.entry, best.entry)


@dataclass
class Cell:
    """One table cell: a series' best point for a budget/target (None: none qualifies)."""

    point: Optional[Point] = None
    best: bool = False  # the column's best
    tie: bool = False  # not the best but inseparable from it
    compensating: bool = False  # would beat the best, but by an energy error (never the best)


@dataclass
class Column:
    label: str  # "≤ 50 ms" or "FLIP ≤ 0.700"
    limit: float
    cells: dict[str, Cell] = field(default_factory=dict)  # series -> cell
    winners: list[str] = field(default_factory=list)  # best first, then the ties
    by_time: bool = False  # ranked by time (equal error) instead of by error (equal time)
    borderline: bool = False  # the winner could change within the timing or error noise
    borderline_why: list[str] = field(default_factory=list)
    compensating: list[str] = field(default_factory=list)  # would win, but compensate
    calibration: dict[str, str] = field(default_factory=dict)  # path tracer vs the winner
    matched_winner: Optional[str] = None  # the winner on the bounce-matched basis

    def rank(self, cells: dict[str, Cell]) -> list[str]:
        """The winners among `cells` (verdicts.verdict on their points)."""
        series = {s: [c.point] for s, c in cells.items() if c.point is not None}
        return V.verdict({s: [p.entry for p in ps] for s, ps in series.items()}, self.limit,
                         self.by_time, calibration=calibration_series(series)).winners


def calibration_series(series: Iterable[str]) -> list[str]:
    """The series that calibrate rather than compete: the equal-time path tracer's."""
    return [s for s in series if s.partition(" (")[0] == PATH_TRACER]


def _columns(series_points: dict[str, list[Point]], limits: Iterable[float],
             by_time: bool) -> list[Column]:
    """One column per limit from verdicts.verdict (equal time: the lowest error with time <=
    the budget; equal error: the least time with error <= the target)."""
    out = []
    by_entry = {id(p.entry): p for pts in series_points.values() for p in pts}
    entries = {s: [p.entry for p in pts if p.ranked] for s, pts in series_points.items()}
    for lim in limits:
        label = f"HDR-FLIP ≤ {sig3(lim)}" if by_time else f"≤ {lim:g} ms"
        v = V.verdict(entries, lim, by_time, calibration=calibration_series(series_points))
        col = Column(label=label, limit=lim, by_time=by_time, winners=v.winners,
                     borderline=v.borderline, borderline_why=v.borderline_why,
                     compensating=v.compensating, calibration=v.calibration,
                     matched_winner=V.matched_winner(
                         V.Verdict(limit=lim, by_time=by_time,
                                   best={k: e for k, e in v.best.items()
                                         if k not in v.calibration})))
        for s in series_points:
            e = v.best.get(s)
            col.cells[s] = Cell(by_entry[id(e)] if e is not None else None,
                                best=bool(v.winners) and s == v.winners[0],
                                tie=s in v.winners[1:], compensating=s in v.compensating)
        out.append(col)
    return out


def equal_time(series_points: dict[str, list[Point]], budgets: Iterable[float]) -> list[Column]:
    """Per budget B: each series' lowest error among its ranked points with time <= B."""
    return _columns(series_points, budgets, by_time=False)


def error_targets(floor: Optional[float], fractions: Iterable[float]) -> list[float]:
    """fraction x the direct floor, each once; none without a positive floor (the door-closed
    scene's black reference gives the floor 0)."""
    if floor is None or floor <= 0:
        return []
    return sorted({f * floor for f in fractions if f > 0}, reverse=True)


def equal_error(series_points: dict[str, list[Point]], targets: Iterable[float]
                ) -> list[Column]:
    """Per target E: each series' least time among its ranked points with error <= E."""
    return _columns(series_points, targets, by_time=True)


# ------------------------------------------------------------------------------------------------
# Scenes
# ------------------------------------------------------------------------------------------------
@dataclass
class SceneStudy:
    scene: str
    animated: bool
    points: list[Point]
    series: dict[str, list[Point]]  # series -> its points (all statuses), by time
    front: list[Point]
    equal_time: list[Column]
    equal_error: list[Column]
    direct_floor: Optional[Point]  # the baseline's best ranked point
    direct_light_flip: Optional[float]  # direct.flip: emission+direct vs the reference's
    direct_light_energy: Optional[float]
    direct_light_leak: Optional[float]
    reference_spp: list[float]
    flip_noise: Optional[float]  # median full.flip_noise of the scene's runs (None: none)
    rel_mse_noise_floor: Optional[float]  # median full.rel_mse_noise_floor
    flip_floor: Optional[float]  # median full.flip_floor: HDR-FLIP of the noise alone
    device: str
    # bounces -> HDR-FLIP of the exact image with that many bounces vs the full reference
    bounce_floors: dict[int, float] = field(default_factory=dict)
    # bounces -> that floor's 1 sigma error bar from the reference's noise (resampled FLIP)
    bounce_floor_noise: dict[int, float] = field(default_factory=dict)

    @property
    def compensating(self) -> list[Point]:
        return [p for p in self.points if p.ranked and p.compensating]

    def best(self, series: str) -> Optional[Point]:
        ranked = [p for p in self.series.get(series, []) if p.ranked]
        return min(ranked, key=lambda p: (p.y, p.x)) if ranked else None


def _median(values: list[Optional[float]]) -> Optional[float]:
    vals = [v for v in values if v is not None]
    return statistics.median(vals) if vals else None


def device_name(rows: list[dict]) -> str:
    """'llvmpipe (…) (lavapipe, CPU)' / 'NVIDIA H200 (GPU)'; several joined by ' and '."""
    names = []
    for r in rows:
        name = fstr(r.get("device"))
        if not name:
            continue
        kind = fstr(r.get("device_type"))
        label = f"{name} (lavapipe, CPU)" if kind == "cpu" else name \
            if kind == "cpu_path_tracer" else f"{name} (GPU)" \
            if kind in ("discrete", "integrated", "gpu", "virtual") else \
            (f"{name} ({kind})" if kind else name)
        if label not in names:
            names.append(label)
    return " and ".join(names) or "unknown device"


def machine_label(rows: list[dict]) -> str:
    """Hosts with their CPU: 'vm (AMD EPYC, 2 threads)'."""
    out = []
    for r in rows:
        host = fstr(r.get("host")).split(".")[0]
        if not host:
            continue
        cpu, threads = fstr(r.get("cpu")), fnum(r.get("hardware_threads"))
        extra = ", ".join(x for x in (cpu, f"{threads:.0f} threads" if threads else "") if x)
        label = f"{host} ({extra})" if extra else host
        if label not in out:
            out.append(label)
    return ", ".join(out) or "unknown machine"


def analyse_scene(scene: str, rows: list[dict], names: dict[str, list[str]],
                  ladders: dict[str, set[str]], budgets: Iterable[float],
                  fractions: Iterable[float],
                  spreads: tuple[dict[str, float], dict[str, float]] = ({}, {})) -> SceneStudy:
    animated = animated_scene(rows)
    points = pool_repeats([make_point(r, series_name(r, names), animated, ladders)
                           for r in rows])
    time_spread, seed_spread = spreads
    for p in points:
        tech = fstr(p.row.get("technique"))
        # Without repeats, the run's own frame-to-frame IQR (as a half-width) stands in for
        # the between-run spread: a lower bound (runs that should cost the same differed by
        # 12-29 % between runs, issue 44).
        own = (p.x_iqr / 2.0 / p.x) if p.x_iqr and p.x else 0.0
        p.entry.time_spread = time_spread.get(tech, own)
        p.entry.seed_sigma = seed_spread.get(tech, 0.0)
    # The shared direct light's own displacement of the full-basis score (verdicts.Entry
    # .floor_margin): the `direct` run's error against floor 0, on this scene.
    shift = [abs(p.y - p.entry.floor) for p in points
             if p.ranked and fstr(p.row.get("technique")) == BASELINE and p.entry.floor is not None]
    for p in points:
        p.entry.floor_margin = max(shift) if shift else 0.0
    V.flag_compensation([p.entry for p in points if p.ranked])
    series: dict[str, list[Point]] = {}
    for p in sorted(points, key=lambda p: (p.x is None, p.x or 0.0, p.y or 0.0)):
        series.setdefault(p.series, []).append(p)
    series = dict(sorted(series.items()))
    baseline = [p for p in points if fstr(p.row.get("technique")) == BASELINE and p.ranked]
    floor = min(baseline, key=lambda p: (p.y, p.x)) if baseline else None
    dl = next((p.row for p in baseline), None) or next(
        (r for r in rows if fnum(r.get("direct.flip")) is not None), {})
    return SceneStudy(
        scene=scene, animated=animated, points=points, series=series,
        front=pareto([p for p in points if not p.compensating]),
        equal_time=equal_time(series, budgets),
        equal_error=equal_error(series, error_targets(floor.y if floor else None, fractions)),
        direct_floor=floor, direct_light_flip=fnum(dl.get("direct.flip")),
        direct_light_energy=fnum(dl.get("direct.energy_ratio")),
        direct_light_leak=fnum(dl.get("direct.shadow_leak")),
        reference_spp=sorted({v for v in (fnum(r.get("reference_samples")) for r in rows)
                              if v is not None}),
        flip_noise=_median([fnum(r.get("full.flip_noise")) for r in rows]),
        rel_mse_noise_floor=_median([fnum(r.get("full.rel_mse_noise_floor")) for r in rows]),
        flip_floor=_median([fnum(r.get("full.flip_floor")) for r in rows]),
        device=device_name(rows),
        bounce_floors={b: v for b in FLOOR_BOUNCES
                       if (v := _median([fnum(r.get(f"floor{b}.flip")) for r in rows]))
                       is not None},
        bounce_floor_noise={b: v for b in FLOOR_BOUNCES
                            if (v := _median([fnum(r.get(f"floor{b}.flip_noise"))
                                              for r in rows])) is not None})


# ------------------------------------------------------------------------------------------------
# Where it breaks
# ------------------------------------------------------------------------------------------------
@dataclass
class Breaks:
    series: str
    leak: Optional[bool] = None  # None: not measured (rooms_closed not run)
    leak_words: str = ""
    energy_min: Optional[float] = None
    energy_max: Optional[float] = None
    energy_min_scene: str = ""
    energy_max_scene: str = ""
    energy_flag: bool = False
    temporal: list[tuple[str, float, Optional[float]]] = field(default_factory=list)
    temporal_flag: bool = False
    setup_min: Optional[float] = None  # runs that built everything (no cached precomputation)
    setup_max: Optional[float] = None
    cached_setup_min: Optional[float] = None  # runs that loaded it from the cache
    cached_setup_max: Optional[float] = None
    unsupported: list[str] = field(default_factory=list)  # "scene: reason"
    nonfinite: list[str] = field(default_factory=list)
    invalid: list[str] = field(default_factory=list)
    audit: list[str] = field(default_factory=list)  # "case: grade (numbers)"

    def flags(self) -> list[str]:
        """Short names of what broke (for the at-a-glance table)."""
        out = []
        if self.leak:
            out.append(f"leak ({LEAK_CLOSED})")
        if self.energy_flag:
            out.append("energy outside [0.5, 2]")
        if self.temporal_flag:
            out.append("temporal instability")
        if self.nonfinite:
            out.append("NaN/Inf")
        if self.unsupported:
            out.append("unsupported")
        if self.invalid:
            out.append("validation")
        return out


def _leak(series: str, closed: list[Point], opened: list[Point]) -> tuple[Optional[bool], str]:
    """The leak rule on the door-closed scene (room B gets no light at all there): per rung,
    energy_ratio(closed) / energy_ratio(open) > LEAK_RATIO where both are finite; else
    (the closed reference is black, its energy ratio undefined) HDR-FLIP vs that black
    reference > LEAK_FLIP; and, where the EXRs were read, the indirect light seen with the door
    closed over the open reference's indirect light > LEAK_SHARE."""
    measured = [p for p in closed if p.status in ("ok", "nonfinite")]
    if not measured:
        return None, "not run" if not closed else "no measured run"
    by_rung = {p.rung: p for p in opened if p.status in ("ok", "nonfinite")}
    words, leak = [], False
    ratios = []
    for p in measured:
        e_closed = fnum(p.row.get("energy_ratio"))
        o = by_rung.get(p.rung)
        e_open = fnum(o.row.get("energy_ratio")) if o is not None else None
        if e_closed is not None and e_open:
            ratios.append(e_closed / e_open)
    if ratios:
        worst = max(ratios)
        leak |= worst > LEAK_RATIO
        words.append(f"energy closed/open ≤ {sig3(worst)}")
    flips = [p.y for p in measured if p.y is not None]
    if flips:
        leak |= max(flips) > LEAK_FLIP
        words.append(f"HDR-FLIP vs black ≤ {sig3(max(flips))}")
    shares = [fnum(p.row.get("leak.share")) for p in measured]
    shares = [s for s in shares if s is not None]
    if shares:
        leak |= max(shares) > LEAK_SHARE
        words.append(f"seen {sig3(100 * max(shares))} % of the open room's indirect")
    if not words:
        return None, "no leak measure"
    return leak, ", ".join(words)


def load_audit(path: Optional[str]) -> dict[str, list[str]]:
    """technique -> its thin-wall / leak cells of an audit.json ('case: grade, leak …');
    {} when the file is missing or unreadable."""
    if not path or not os.path.isfile(path):
        return {}
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except (OSError, ValueError):
        return {}
    out: dict[str, list[str]] = {}
    cells = data.get("cells") if isinstance(data, dict) else None
    for c in cells if isinstance(cells, list) else []:
        if not isinstance(c, dict):
            continue
        case = fstr(c.get("case"))
        if not (case.startswith(THIN_WALL_CASES) or fnum(c.get("leak")) is not None):
            continue
        numbers = [f"{k.replace('_', ' ')} {sig3(fnum(c.get(k)))}"
                   for k in ("leak", "energy_ratio") if fnum(c.get(k)) is not None]
        out.setdefault(fstr(c.get("technique")), []).append(
            f"{case}: {fstr(c.get('grade')) or '?'}" + (f" ({', '.join(numbers)})"
                                                        if numbers else ""))
    return out


def _matched_instability(p: "Point") -> Optional[float]:
    return fnum(p.row.get("sequence.temporal_matched.instability"))


def _lowest_instability(study: "Study") -> dict[str, float]:
    """Per animated scene, the lowest matched temporal instability of any GI (non-baseline)
    run: the reference point of the temporal flag."""
    out: dict[str, float] = {}
    for sc, st in study.scenes.items():
        values = [_matched_instability(p) for s, pts in st.series.items()
                  if not s.startswith(BASELINE) for p in pts if p.status in ("ok", "nonfinite")]
        values = [v for v in values if v is not None]
        if values:
            out[sc] = min(values)
    return out


def breaks(study: "Study", audit: dict[str, list[str]]) -> list[Breaks]:
    out = []
    lowest = _lowest_instability(study)
    for s in study.series:
        b = Breaks(series=s)
        per_scene = {sc: st.series.get(s, []) for sc, st in study.scenes.items()}
        b.leak, b.leak_words = _leak(s, per_scene.get(LEAK_CLOSED, []),
                                     per_scene.get(LEAK_OPEN, []))
        energies: list[tuple[float, str]] = []
        setups, cached = [], []
        for sc, pts in per_scene.items():
            for p in pts:
                where = f"{sc} {p.rung}".strip()
                if p.status == "unsupported":
                    b.unsupported.append(f"{where}: {fstr(p.row.get('reason'))}".rstrip(": "))
                elif p.status == "nonfinite":
                    b.nonfinite.append(where)
                elif p.status == "invalid":
                    b.invalid.append(where)
                if p.status not in ("ok", "nonfinite"):
                    continue
                e = fnum(p.row.get("energy_ratio"))
                if e is not None and sc != LEAK_CLOSED and fnum(p.row.get("bounces")) != 0:
                    energies.append((e, sc))
                if fnum(p.row.get("setup_ms")) is not None:
                    (cached if cached_setup(p.row) else setups).append(fnum(p.row.get("setup_ms")))
                inst = _matched_instability(p)
                if inst is not None:
                    floor = fnum(p.row.get("sequence.temporal_matched.noise_floor"))
                    b.temporal.append((sc, inst, floor))
                    if (not s.startswith(BASELINE) and sc in lowest
                            and inst > TEMPORAL_FACTOR * lowest[sc]):
                        b.temporal_flag = True
        if energies and not s.startswith(BASELINE):
            (b.energy_min, b.energy_min_scene), (b.energy_max, b.energy_max_scene) = (
                min(energies), max(energies))
            b.energy_flag = b.energy_min < ENERGY_BAND[0] or b.energy_max > ENERGY_BAND[1]
        if setups:
            b.setup_min, b.setup_max = min(setups), max(setups)
        if cached:
            b.cached_setup_min, b.cached_setup_max = min(cached), max(cached)
        b.audit = audit.get(s.split(" (")[0], [])
        out.append(b)
    return out


# ------------------------------------------------------------------------------------------------
# The whole study
# ------------------------------------------------------------------------------------------------
@dataclass
class Study:
    scenes: dict[str, SceneStudy]
    series: list[str]
    budgets: tuple[float, ...]
    fractions: tuple[float, ...]
    breaks: list[Breaks]
    device: str
    machine: str
    rows: list[dict]
    statuses: dict[str, int]
    commits: list[str]
    time_spread: dict[str, float] = field(default_factory=dict)  # technique -> pooled, relative
    seed_spread: dict[str, float] = field(default_factory=dict)  # technique -> pooled HDR-FLIP
    # A scene rendered again at a larger image size (same scene file, variant and camera):
    # larger scene -> the scene it repeats. It gives the cost split, not a verdict.
    size_twins: dict[str, str] = field(default_factory=dict)

    def scene_best(self, scene: str, series: str) -> Optional[Point]:
        return self.scenes[scene].best(series)


PATH_TRACER = "pathtracer"  # the equal-time path-tracer baseline (experiments/runner/pt_baseline.h)


def by_device(rows: list[dict]) -> dict[str, list[dict]]:
    """Rows by device model (device_name): times of two models are never compared. The
    path-tracer baseline runs on the host's CPU, so its rows join every device group of the
    same host (the CPU that also runs lavapipe there); alone, they form their own group."""
    out: dict[str, list[dict]] = {}
    baseline = [r for r in rows if fstr(r.get("technique")) == PATH_TRACER]
    for r in rows:
        if fstr(r.get("technique")) != PATH_TRACER:
            out.setdefault(device_name([r]), []).append(r)
    for r in baseline:
        groups = [g for g in out.values() if any(fstr(x.get("host")) == fstr(r.get("host"))
                                                 for x in g)]
        for g in groups or [out.setdefault(device_name([r]), [])]:
            g.append(r)
    return dict(sorted(out.items(), key=lambda kv: -len(kv[1])))


def _pixels(resolution: Any) -> Optional[int]:
    try:
        w, h = (int(v) for v in fstr(resolution).split("x"))
        return w * h
    except ValueError:
        return None


def size_twins(rows: list[dict]) -> dict[str, str]:
    """Scenes that repeat another at a larger image size (the same scene_source): larger ->
    the smallest one of its source."""
    by_source: dict[str, dict[str, int]] = {}
    for r in rows:
        src, px = fstr(r.get("scene_source")), _pixels(r.get("resolution"))
        if src and px:
            by_source.setdefault(src, {})[fstr(r.get("scene"))] = px
    out = {}
    for scenes in by_source.values():
        if len(set(scenes.values())) < 2:
            continue
        primary = min(scenes, key=lambda sc: (scenes[sc], sc))
        for sc, px in scenes.items():
            if px > scenes[primary]:
                out[sc] = primary
    return out


def is_study(rows: list[dict]) -> bool:
    """Two or more techniques measured on one scene: the cross-technique view applies."""
    techs: dict[str, set[str]] = {}
    for r in rows:
        if fstr(r.get("status")) in ("ok", "nonfinite"):
            techs.setdefault(fstr(r.get("scene")), set()).add(fstr(r.get("technique")))
    return any(len(t) >= 2 for t in techs.values())


def analyse(rows: list[dict], budgets: Iterable[float] = BUDGETS_MS,
            fractions: Iterable[float] = ERROR_FRACTIONS,
            audit: Optional[dict[str, list[str]]] = None) -> Study:
    budgets, fractions = tuple(budgets), tuple(fractions)
    names, ladders = series_keys(rows), ladder_keys(rows)
    spreads = noise_spreads(rows)
    by_scene: dict[str, list[dict]] = {}
    for r in rows:
        by_scene.setdefault(fstr(r.get("scene")) or "?", []).append(r)
    scenes = {s: analyse_scene(s, rs, names, ladders, budgets, fractions, spreads)
              for s, rs in by_scene.items()}
    series = sorted({p.series for st in scenes.values() for p in st.points},
                    key=lambda s: (not s.startswith(BASELINE), s))
    statuses: dict[str, int] = {}
    for r in rows:
        statuses[fstr(r.get("status")) or "?"] = statuses.get(fstr(r.get("status")) or "?", 0) + 1
    study = Study(scenes=scenes, series=series, budgets=budgets, fractions=fractions, breaks=[],
                  device=device_name(rows), machine=machine_label(rows), rows=rows,
                  statuses=statuses,
                  commits=sorted({fstr(r.get("git_commit")) for r in rows} - {""}),
                  time_spread=spreads[0], seed_spread=spreads[1], size_twins=size_twins(rows))
    study.breaks = breaks(study, audit or {})
    return study


# ------------------------------------------------------------------------------------------------
# Findings: sentences that only restate the numbers
# ------------------------------------------------------------------------------------------------
def winners_words(col: Column) -> str:
    if not col.winners:
        return "no run qualifies"
    best = col.winners[0]
    p = col.cells[best].point
    out = f"{best} ({sig3(p.y)} at {ms(p.x)})"
    if len(col.winners) > 1:
        out += ", tied within the error bars with " + ", ".join(col.winners[1:]) \
            if "FLIP" not in col.label else ", tied within the timing IQR with " + \
            ", ".join(col.winners[1:])
    return out


def restricted_winner(col: Column, excluded: str) -> Optional[str]:
    """The column's winner when `excluded` is not allowed (None: nothing else qualifies)."""
    cells = {s: Cell(c.point) for s, c in col.cells.items() if s != excluded}
    winners = col.rank(cells)
    return winners[0] if winners else None


def findings(study: Study) -> list[str]:
    """Plain sentences, each a restatement of numbers in the tables."""
    out = []
    for scene, st in study.scenes.items():
        if not is_quality(study, scene):
            continue
        absent = [s for s in study.series if not any(p.ranked for p in st.series.get(s, []))]
        if absent:
            out.append(f"{scene}: no ranked run of {', '.join(absent)} (not run, not finished "
                       "or not measured); the winners below are among the others.")
        for col in st.equal_time:
            out.append(f"{scene}, frame time {col.label}: best HDR-FLIP {winners_words(col)}.")
        for ours, paper in our_choice_pairs(study.series):
            # Only at matched rungs: our variant's runs at the rungs the paper's variant ran.
            paper_rungs_run = {p.rung for p in st.series.get(paper, [])}
            matched = dict(st.series)
            matched[ours] = [p for p in st.series.get(ours, []) if p.rung in paper_rungs_run]
            for col in equal_time(matched, study.budgets):
                if not col.winners or col.winners[0] != ours:
                    continue
                alt = restricted_winner(col, ours)
                has_paper = col.cells.get(paper) and col.cells[paper].point is not None
                if alt is None:
                    out.append(f"{scene}, {col.label}: only {ours} qualifies; without our choice "
                               "no run would (at the rungs both variants ran).")
                elif alt != ours:
                    same = alt.split(" (")[0] == ours.split(" (")[0]
                    out.append(f"{scene}, {col.label}: {ours} wins at the rungs both variants "
                               f"ran; with only {paper} allowed the winner would be {alt}"
                               + (" (the same technique still wins)" if same
                                  else " (another technique: our choice changes the ranking)")
                               + ("" if has_paper else f"; {paper} has no run within it")
                               + ".")
    for s in study.series:
        rows = [(sc, st.best(s), [p for p in st.series.get(s, []) if p.ranked and p.paper])
                for sc, st in study.scenes.items() if is_quality(study, sc)]
        parts = []
        for sc, best, papers in rows:
            if best is None or not papers:
                continue
            paper = min(papers, key=lambda p: (p.y, p.x))
            if paper is best:
                parts.append(f"{sc}: the paper rung is its best ({sig3(best.y)}, {ms(best.x)})")
            else:
                parts.append(f"{sc}: paper rung {sig3(paper.y)} at {ms(paper.x)}, best rung "
                             f"{best.rung} {sig3(best.y)} at {ms(best.x)}")
        if parts:
            out.append(f"{s}, paper rung vs best rung — " + "; ".join(parts) + ".")
    for b in study.breaks:
        if b.leak is not None:
            out.append(f"{b.series} on {LEAK_CLOSED}: {'leaks' if b.leak else 'no leak'} "
                       f"({b.leak_words}).")
    return out


def common_scenes(study: Study) -> list[str]:
    """The quality scenes on which every technique of the study has a ranked run: the one scene
    set cross-scene summaries use, so no technique's median stands on other scenes than
    another's (issue 44)."""
    techniques = {s.partition(" (")[0] for s in study.series}
    out = []
    for sc, st in quality_scenes(study).items():
        ran = {p.series.partition(" (")[0] for p in st.points if p.ranked}
        if techniques <= ran:
            out.append(sc)
    return out


def glance(study: Study) -> list[dict]:
    """Per technique (all its series together), over the common scenes (common_scenes): the
    median of its best HDR-FLIP, the median of that over the direct floor's (how much of the
    error without indirect light it leaves), the scenes and budgets where one of its series wins
    (any quality scene), and what broke (a flag of only some of its series names them)."""
    out = []
    by_series = {b.series: b for b in study.breaks}
    quality = quality_scenes(study)
    common = common_scenes(study)
    techniques = list(dict.fromkeys(s.partition(" (")[0] for s in study.series))
    for tech in techniques:
        series = [s for s in study.series if s.partition(" (")[0] == tech]
        bests, ratios = [], []
        for sc in common:
            st = quality[sc]
            pts = [(st.best(s), s) for s in series if st.best(s)]
            if not pts:
                continue
            p, s = min(pts, key=lambda t: (t[0].y, t[0].x))
            bests.append(p.y)
            floor = st.direct_floor
            if tech != BASELINE and floor is not None and floor.y and floor.y > 0:
                ratios.append(p.y / floor.y)
        wins: dict[str, list[str]] = {}
        for sc, st in quality.items():
            for col in st.equal_time:
                if any(w in series for w in col.winners):
                    wins.setdefault(sc, []).append(col.label.replace("≤ ", "≤").replace(" ms", ""))
        flags: dict[str, list[str]] = {}
        for s in series:
            b = by_series.get(s)
            for f in (b.flags() if b else []):
                flags.setdefault(f, []).append(s)
        breaks = [f if len(who) == len(series) or len(series) == 1 else
                  f"{f} ({'; '.join(w.partition(' (')[2].rstrip(')') or w for w in who)})"
                  for f, who in flags.items()]
        out.append({"technique": tech, "series": series, "scenes": len(common),
                    "median_best": statistics.median(bests) if bests else None,
                    "floor_ratio": statistics.median(ratios) if ratios else None,
                    "wins": wins, "breaks": breaks})
    return out


# ------------------------------------------------------------------------------------------------
# The first screen: one technique x budget table on the headline basis, per-scene lines below
# ------------------------------------------------------------------------------------------------
DEVICE_CAVEAT = ("budgets are frame times on the device named; lavapipe on a 2-core CPU is not a "
                 "GPU: it favours per-scene fixed costs over per-pixel ones at these image sizes")


@dataclass
class VerdictCell:
    """Where one series stands at one budget over the quality scenes."""

    wins: list[str] = field(default_factory=list)  # scenes it wins outright
    ties: list[str] = field(default_factory=list)  # scenes it ties the winner
    beats: list[str] = field(default_factory=list)  # calibration: scenes it beats the winner
    borderline: list[str] = field(default_factory=list)  # of those, where the verdict is
    compensating: list[str] = field(default_factory=list)  # scenes it would win by compensating

    def text(self) -> str:
        parts = []
        if self.wins:
            parts.append(f"wins {len(self.wins)}")
        if self.ties:
            parts.append(f"ties {len(self.ties)}")
        if self.borderline:
            parts.append(f"borderline {len(self.borderline)}")
        if self.compensating:
            parts.append(f"compensating {len(self.compensating)}")
        if self.beats:
            parts.append(f"beats the winner {len(self.beats)}")
        return ", ".join(parts) or "—"


def is_quality(study: Study, scene: str) -> bool:
    """A scene whose errors give verdicts: not a failure test (NOT_QUALITY) and not a larger
    size of another scene (its runs give the cost split)."""
    return scene not in NOT_QUALITY and scene not in study.size_twins


def quality_scenes(study: Study) -> dict[str, SceneStudy]:
    return {sc: st for sc, st in study.scenes.items() if is_quality(study, sc)}


def verdict_table(study: Study) -> dict[str, list[VerdictCell]]:
    """series -> one cell per budget (study.budgets), over the quality scenes."""
    out = {s: [VerdictCell() for _ in study.budgets] for s in study.series}
    for sc, st in quality_scenes(study).items():
        for i, col in enumerate(st.equal_time):
            for rank, s in enumerate(col.winners):
                cell = out[s][i]
                (cell.wins if rank == 0 else cell.ties).append(sc)
                if col.borderline:
                    cell.borderline.append(sc)
            for s in col.compensating:
                out[s][i].compensating.append(sc)
            for s, standing in col.calibration.items():
                (out[s][i].beats if standing == "beats" else
                 out[s][i].ties if standing == "ties" else []).append(sc)
    return out


def ladder_reach(study: Study) -> dict[str, tuple[float, float, int]]:
    """series -> (fastest, slowest static frame time, scenes) of its ranked rungs on the static
    quality scenes: what budgets its ladder can reach."""
    out: dict[str, tuple[float, float, int]] = {}
    for s in study.series:
        static = [st for st in quality_scenes(study).values() if not st.animated]
        times = [p.x for st in static for p in st.series.get(s, []) if p.ranked]
        scenes = sum(1 for st in static if any(p.ranked for p in st.series.get(s, [])))
        if times:
            out[s] = (min(times), max(times), scenes)
    return out


def _column_words(col: Column) -> str:
    w = ", ".join(col.winners) or "no run qualifies"
    if len(col.winners) > 1:
        w = f"{col.winners[0]} (tied: {', '.join(col.winners[1:])})"
    if col.borderline:
        w += " [borderline]"
    if col.compensating:
        w += f" [compensating, not ranked: {', '.join(col.compensating)}]"
    if col.matched_winner and col.winners and col.matched_winner != col.winners[0]:
        w += f" [matched basis: {col.matched_winner}]"
    for s, standing in col.calibration.items():
        w += f" [{s} {standing} it]"
    return w


def scene_lines(study: Study) -> list[str]:
    """Per quality scene: the time-free verdicts first (equal error, the bounce floors), then
    equal time; each with its marks."""
    out = []
    for sc, st in quality_scenes(study).items():
        parts = []
        if st.bounce_floors:
            parts.append("bounce floors " + ", ".join(
                f"{b}: {sig3(v)}" + (f" ± {sig3(st.bounce_floor_noise[b], 2)}"
                                     if b in st.bounce_floor_noise else "")
                for b, v in sorted(st.bounce_floors.items())))
        parts += [f"{c.label}: {_column_words(c)}" for c in st.equal_error]
        parts += [f"{c.label}: {_column_words(c)}" for c in st.equal_time]
        out.append(f"{sc}: " + "; ".join(parts))
    return out


def borderline_lines(study: Study) -> list[str]:
    """Every borderline verdict (equal time and equal error) on the quality scenes, with why and
    the winner's run key: what the study repeats (>= 20 timed frames, interleaved, the config's
    "repeats") before it keeps or drops the mark."""
    out = []
    for sc, st in quality_scenes(study).items():
        for col in st.equal_error + st.equal_time:
            if col.borderline and col.winners:
                p = col.cells[col.winners[0]].point
                out.append(f"{sc}, {col.label}: {col.winners[0]} (run {p.key if p else '?'}); "
                           + "; ".join(col.borderline_why))
    return out
