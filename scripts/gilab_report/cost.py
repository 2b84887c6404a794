"""The whole cost of each series' rungs (issue 44, docs/report.md "Whole cost"): beside the
static frame, the GPU memory, the set-up (cold, and cached where a precomputation is cached),
the frame where the light moves and the frame where the camera moves (animated scenes), the
frames after which the set-up pays back, and the fixed / per-pixel split from one rung timed at
two image sizes (verdicts.cost_split), extrapolated to 1920 x 1080.
"""
from __future__ import annotations

import statistics
from dataclasses import dataclass
from typing import Optional

from . import study as S
from . import verdicts as V

FULL_HD = 1920 * 1080


@dataclass
class CostRow:
    series: str
    rung: str
    scenes: int = 0  # quality scenes with a ranked static frame
    static_ms: Optional[float] = None  # median over those scenes
    memory_mib: Optional[float] = None  # median total Vulkan memory (scene + shared + technique)
    own_memory_mib: Optional[float] = None  # median of the technique's own allocations
    setup_ms: Optional[float] = None  # median cold set-up
    setup_cached_ms: Optional[float] = None  # median set-up that loaded a cached precomputation
    light_ms: Optional[float] = None  # the frame where the light moves (update included)
    camera_ms: Optional[float] = None  # the frame where the camera moves
    payback_frames: Optional[float] = None  # set-up / (light-move frame - static frame)
    split: Optional[V.CostSplit] = None
    split_where: str = ""  # "scene (WxH) vs twin (WxH)"

    @property
    def full_hd_ms(self) -> Optional[float]:
        return self.split.at(FULL_HD) if self.split else None


def _med(values: list[Optional[float]]) -> Optional[float]:
    vals = [v for v in values if v is not None]
    return statistics.median(vals) if vals else None


def _static_ms(row: dict) -> Optional[float]:
    t = S.fnum(row.get("frame_gpu_ms_median"))
    return t if t is not None else S.fnum(row.get("frame_cpu_ms_median"))


def _dynamic_ms(row: dict) -> Optional[float]:
    t = S.fnum(row.get("dynamic_frame_gpu_ms_median"))
    return t if t is not None else S.fnum(row.get("dynamic_frame_cpu_ms_median"))


def whole_cost(study: "S.Study") -> list[CostRow]:
    """One row per (series, rung) that ran a static quality scene or an animated one."""
    rows: dict[tuple[str, str], CostRow] = {}

    def get(p: "S.Point") -> CostRow:
        return rows.setdefault((p.series, p.rung), CostRow(series=p.series, rung=p.rung))

    static: dict[tuple[str, str], list] = {}
    for sc, st in study.scenes.items():
        for p in st.points:
            if p.status != "ok":
                continue
            r = p.row
            if st.animated:
                moves = S.fstr(r.get("animation_moves")).split()
                dyn = _dynamic_ms(r)
                c = get(p)
                if "light" in moves:
                    c.light_ms = _med([c.light_ms, dyn])
                    c.payback_frames = V.payback_frames(S.fnum(r.get("setup_ms")), dyn,
                                                        _static_ms(r))
                elif "camera" in moves:
                    c.camera_ms = _med([c.camera_ms, dyn])
                continue
            if not S.is_quality(study, sc):
                continue
            static.setdefault((p.series, p.rung), []).append(r)
    for key, rs in static.items():
        c = rows.setdefault(key, CostRow(series=key[0], rung=key[1]))
        c.scenes = len(rs)
        c.static_ms = _med([_static_ms(r) for r in rs])
        mem = [S.fnum(r.get("memory_total_bytes")) for r in rs]
        c.memory_mib = _med([m / 2 ** 20 for m in mem if m is not None])
        own = [S.fnum(r.get("memory_technique_bytes")) for r in rs]
        c.own_memory_mib = _med([m / 2 ** 20 for m in own if m is not None])
        c.setup_ms = _med([S.fnum(r.get("setup_ms")) for r in rs if not S.cached_setup(r)])
        c.setup_cached_ms = _med([S.fnum(r.get("setup_ms")) for r in rs if S.cached_setup(r)])
    _splits(study, rows)
    order = {s: i for i, s in enumerate(study.series)}
    return sorted(rows.values(), key=lambda c: (order.get(c.series, 1e9), c.static_ms or 0.0))


def _splits(study: "S.Study", rows: dict[tuple[str, str], CostRow]) -> None:
    """The two-size split of every (series, rung) timed on a scene and on its size twin."""
    for twin, primary in study.size_twins.items():
        small, large = study.scenes.get(primary), study.scenes.get(twin)
        if small is None or large is None:
            continue
        big = {(p.series, p.rung): p for p in large.points if p.ranked}
        for p in small.points:
            q = big.get((p.series, p.rung))
            if not p.ranked or q is None:
                continue
            n1 = S._pixels(p.row.get("resolution"))
            n2 = S._pixels(q.row.get("resolution"))
            if not n1 or not n2:
                continue
            split = V.cost_split((n1, p.x), (n2, q.x))
            c = rows.setdefault((p.series, p.rung), CostRow(series=p.series, rung=p.rung))
            if split is not None and c.split is None:
                c.split = split
                c.split_where = (f"{primary} ({S.fstr(p.row.get('resolution'))}) vs {twin} "
                                 f"({S.fstr(q.row.get('resolution'))})")
