"""The study's verdict rules, defined once: Pareto front, equal time, equal error, ties,
borderline verdicts, compensation, pooled noise and the two-size cost split. `gilab report`
(study.py, study_html.py) and findings.py both call these functions and
nothing else decides a verdict. Pure functions of numbers; docs/report.md ("Verdict rules")
states each rule in words, tests/report/test_verdicts.py checks each on known answers.

An **entry** is one run of one series on one scene, reduced to what a rule needs:

    time          frame time, ms (the static frame, or the moving-light frame where the light
                  moves)
    time_spread   relative between-run spread of the technique's frame time (pooled from
                  repeats of one configuration: runs that differ only in a seed or a repeat
                  index, pooled_relative_spread); 0 = not measured
    error         the headline error: HDR-FLIP against the full reference
    error_sigma   its 1 sigma error bar from resampling the reference (metrics error_bars.flip
                  .spread): the reference's noise in this run's score
    seed_sigma    the technique's pooled seed spread of that error (pooled_spread over runs
                  that differ only in `seed`); 0 = not measured
    matched       the error against the bounce-matched reference (what the technique claims),
                  with matched_sigma
    bounces       the indirect bounces it claims (ALL_BOUNCES = all)
    floor         the full-basis error of the exact image with that many bounces (the path
                  tracer's own bounce layers: metrics.bounce_floors), with floor_sigma

Ties.  Two errors tie when |e_a - e_b| <= sqrt(sa^2 + sb^2 + ka^2 + kb^2) (sigma = resampled
error bar, k = seed spread): the standard deviation of a difference of independent estimates.
Two times tie when |t_a - t_b| <= sqrt((r_a t_a)^2 + (r_b t_b)^2) (r = relative time spread).
The same rule serves every table; with no spread measured only equal values tie.

Compensation.  A run is *compensating* when (a) its full-basis error is below the floor of its
bounce count by more than the noise and the shared direct light's own displacement (a perfect
image of the bounces it claims would score worse: the surplus energy stands in for the bounces
it leaves out), or (b) it beats a rival
that claims the same bounces on the full basis while that rival beats it on the matched basis,
both beyond the noise (the ranking flips with the basis). A compensating run is shown beside
the headline, marked, never as its winner.

Borderline.  An equal-time verdict is borderline when the winner's time is within its time
spread of the budget, or a run with clearly lower error is over the budget by no more than its
time spread; an equal-error verdict when the winner's error is within its noise of the target,
or a faster run misses the target by no more than its noise. The study repeats such
configurations (>= 20 timed frames, interleaved) and keeps the mark if they stay within it.
"""
from __future__ import annotations

import math
import statistics
from dataclasses import dataclass, field
from typing import Iterable, Optional, Sequence

ALL_BOUNCES = -1  # TechniqueInfo::kAllBounces: the technique claims every bounce


@dataclass
class Entry:
    key: str
    series: str
    time: Optional[float]
    error: Optional[float]
    error_sigma: float = 0.0
    time_spread: float = 0.0
    seed_sigma: float = 0.0
    matched: Optional[float] = None
    matched_sigma: float = 0.0
    bounces: Optional[int] = None
    floor: Optional[float] = None
    floor_sigma: float = 0.0
    # How far the shared direct light alone moves the full-basis score: |error of the scene's
    # `direct` run - floor 0| (its shadow maps and light sampling against the path tracer's).
    # Every technique is built on that direct light, so rule (a) does not count it.
    floor_margin: float = 0.0
    # Indirect energy over the matched reference's (metrics.energy_ratio): rule (b) needs a
    # surplus (> 1), the measured cause of a better full-basis rank. None: not measured.
    energy: Optional[float] = None
    compensating: bool = False
    compensation: list[str] = field(default_factory=list)  # why, in words

    @property
    def ranked(self) -> bool:
        return self.time is not None and self.error is not None


# ------------------------------------------------------------------------------------------------
# Noise
# ------------------------------------------------------------------------------------------------
def error_bound(a: Entry, b: Entry) -> float:
    """1 sigma of e_a - e_b: reference resampling and seed spread of both runs."""
    return math.sqrt(a.error_sigma ** 2 + b.error_sigma ** 2 + a.seed_sigma ** 2 +
                     b.seed_sigma ** 2)


def error_tie(a: Entry, b: Entry) -> bool:
    return abs(a.error - b.error) <= error_bound(a, b)


def time_bound(a: Entry, b: Entry) -> float:
    return math.hypot(a.time_spread * a.time, b.time_spread * b.time)


def time_tie(a: Entry, b: Entry) -> bool:
    return abs(a.time - b.time) <= time_bound(a, b)


def pooled_spread(groups: Iterable[Sequence[float]]) -> Optional[float]:
    """Pooled standard deviation of groups of repeats: sqrt(sum (n_i - 1) s_i^2 / sum (n_i - 1));
    None without a group of two or more."""
    num, dof = 0.0, 0
    for g in groups:
        vals = [float(v) for v in g if v is not None and math.isfinite(v)]
        if len(vals) < 2:
            continue
        num += statistics.variance(vals) * (len(vals) - 1)
        dof += len(vals) - 1
    return math.sqrt(num / dof) if dof else None


def pooled_relative_spread(groups: Iterable[Sequence[float]]) -> Optional[float]:
    """pooled_spread of each group divided by its mean (times: a relative spread)."""
    scaled = []
    for g in groups:
        vals = [float(v) for v in g if v is not None and math.isfinite(v) and v > 0]
        if len(vals) >= 2:
            m = statistics.fmean(vals)
            scaled.append([v / m for v in vals])
    return pooled_spread(scaled)


# ------------------------------------------------------------------------------------------------
# Compensation
# ------------------------------------------------------------------------------------------------
def below_floor(e: Entry) -> bool:
    """Rule (a): the full-basis error is below its bounce floor beyond the noise."""
    if e.error is None or e.floor is None or e.bounces in (None, ALL_BOUNCES):
        return False
    noise = math.sqrt(e.error_sigma ** 2 + e.floor_sigma ** 2 + e.seed_sigma ** 2)
    return e.error < e.floor - noise - e.floor_margin


def _matched_noise(a: Entry, b: Entry) -> float:
    return math.sqrt(a.matched_sigma ** 2 + b.matched_sigma ** 2 + a.seed_sigma ** 2 +
                     b.seed_sigma ** 2)


def basis_ranks(e: Entry, group: list[Entry]) -> tuple[int, int]:
    """Rule (b)'s ranks of e among `group` (entries claiming its bounces, so one matched
    reference): (rivals clearly better on the full basis, rivals clearly better on the matched
    basis), "clearly" meaning beyond the noise of the difference."""
    full = sum(1 for q in group if q is not e and e.error - q.error > error_bound(e, q))
    matched = sum(1 for q in group
                  if q is not e and e.matched - q.matched > _matched_noise(e, q))
    return full, matched


def flag_compensation(entries: list[Entry]) -> list[Entry]:
    """Sets `compensating` and `compensation` (the reasons) on every entry of one scene: rule
    (a), below its bounce floor; rule (b), it ranks better on the full basis than on the
    matched one among the runs that claim its bounces (beyond the noise)."""
    for e in entries:
        e.compensating, e.compensation = False, []
        if below_floor(e):
            e.compensation.append(f"full-basis error {e.error:.3g} below the {e.bounces}-bounce "
                                  f"floor {e.floor:.3g}")
    groups: dict[int, list[Entry]] = {}
    for e in entries:
        if e.bounces is not None and e.error is not None and e.matched is not None:
            groups.setdefault(e.bounces, []).append(e)
    for group in groups.values():
        for e in group:
            full, matched = basis_ranks(e, group)
            if full < matched and (e.energy is None or e.energy > 1.0):
                e.compensation.append(
                    f"ranks {full + 1} of {len(group)} on the full basis but {matched + 1} on "
                    f"the matched one (runs claiming {e.bounces} bounce"
                    f"{'' if e.bounces == 1 else 's'})"
                    + (f", with {e.energy:.3g}x the matched indirect energy"
                       if e.energy is not None else ""))
    for e in entries:
        e.compensating = bool(e.compensation)
    return entries


# ------------------------------------------------------------------------------------------------
# Fronts and tables
# ------------------------------------------------------------------------------------------------
def pareto(entries: Iterable[Entry]) -> list[Entry]:
    """Ranked entries no other beats in both respects (time <= and error <, or time < and
    error <=), by time; of entries with the same time and error only the first is on the front
    (the others are its ties)."""
    ranked = [e for e in entries if e.ranked]
    front, seen = [], set()
    for e in ranked:
        if (e.time, e.error) in seen or any(
                (q.time <= e.time and q.error < e.error) or (q.time < e.time and q.error <= e.error)
                for q in ranked):
            continue
        seen.add((e.time, e.error))
        front.append(e)
    return sorted(front, key=lambda e: (e.time, e.error))


@dataclass
class Verdict:
    """One column of a technique x budget (or target) table."""

    limit: float
    by_time: bool  # equal error (rank by time) instead of equal time (rank by error)
    best: dict[str, Entry] = field(default_factory=dict)  # series -> its best entry within limit
    winners: list[str] = field(default_factory=list)  # the winner, then its ties (by name)
    compensating: list[str] = field(default_factory=list)  # compensating series that beat it
    # Calibration series (the equal-time path tracer) never win; each one's standing against
    # the winner: "beats" (clearly better), "ties" (within the noise) or "loses".
    calibration: dict[str, str] = field(default_factory=dict)
    borderline: bool = False
    borderline_why: list[str] = field(default_factory=list)

    @property
    def winner(self) -> Optional[str]:
        return self.winners[0] if self.winners else None


def _best_within(entries: list[Entry], limit: float, by_time: bool) -> Optional[Entry]:
    ok = [e for e in entries if e.ranked and (e.error if by_time else e.time) <= limit]
    order = (lambda e: (e.time, e.error)) if by_time else (lambda e: (e.error, e.time))
    return min(ok, key=order) if ok else None


def _rank(best: dict[str, Entry], by_time: bool) -> list[str]:
    if not best:
        return []
    value = (lambda e: (e.time, e.error)) if by_time else (lambda e: (e.error, e.time))
    name = min(best, key=lambda s: (value(best[s]), s))
    tie = time_tie if by_time else error_tie
    return [name] + sorted(s for s, e in best.items() if s != name and tie(e, best[name]))


def verdict(series: dict[str, list[Entry]], limit: float, by_time: bool = False,
            calibration: Iterable[str] = ()) -> Verdict:
    """Equal time (by_time False: the lowest error with time <= limit) or equal error (the
    least time with error <= limit) over each series' best entry; compensating entries never
    win, and those that would beat the winner are listed. `calibration` series (the
    equal-time path tracer) are not candidates: each is compared with the winner instead."""
    calibration = set(calibration)
    v = Verdict(limit=limit, by_time=by_time)
    for s, pts in series.items():
        b = _best_within(pts, limit, by_time)
        if b is not None:
            v.best[s] = b
    honest = {s: e for s, e in v.best.items() if not e.compensating and s not in calibration}
    v.winners = _rank(honest, by_time)
    if not v.winners:
        v.compensating = sorted(s for s, e in v.best.items()
                                if e.compensating and s not in calibration)
        v.calibration = {s: "beats" for s in calibration if s in v.best}
        return v
    w = v.best[v.winners[0]]
    key = (lambda e: e.time) if by_time else (lambda e: e.error)
    v.compensating = sorted(s for s, e in v.best.items()
                            if e.compensating and key(e) < key(w) and s not in calibration)
    tie = time_tie if by_time else error_tie
    for s in calibration:
        c = v.best.get(s)
        if c is not None:
            v.calibration[s] = ("ties" if tie(c, w) else
                                "beats" if key(c) < key(w) else "loses")
    _mark_borderline(v, {s: pts for s, pts in series.items() if s not in calibration}, w)
    return v


def _mark_borderline(v: Verdict, series: dict[str, list[Entry]], w: Entry) -> None:
    if not v.by_time:  # equal time: the budget edge is a time
        if w.time + w.time_spread * w.time > v.limit:
            v.borderline_why.append(f"{v.winners[0]}'s {w.time:.3g} ms is within its time "
                                    f"spread of the {v.limit:g} ms budget")
        for s, pts in series.items():
            for e in pts:
                if (e.ranked and not e.compensating and e.time > v.limit
                        and e.time - e.time_spread * e.time <= v.limit
                        and w.error - e.error > error_bound(e, w)):
                    v.borderline_why.append(f"{s} ({e.error:.3g} at {e.time:.3g} ms) is over "
                                            "the budget by less than its time spread")
                    break
    else:  # equal error: the target is an error
        noise = math.hypot(w.error_sigma, w.seed_sigma)
        if w.error + noise > v.limit:
            v.borderline_why.append(f"{v.winners[0]}'s error {w.error:.3g} is within its noise "
                                    f"of the target {v.limit:.3g}")
        for s, pts in series.items():
            for e in pts:
                if (e.ranked and not e.compensating and e.error > v.limit
                        and e.error - math.hypot(e.error_sigma, e.seed_sigma) <= v.limit
                        and w.time - e.time > time_bound(e, w)):
                    v.borderline_why.append(f"{s} ({e.time:.3g} ms) misses the target by less "
                                            "than its noise")
                    break
    v.borderline = bool(v.borderline_why)


def equal_time(series: dict[str, list[Entry]], budgets: Iterable[float]) -> list[Verdict]:
    return [verdict(series, b, by_time=False) for b in budgets]


def equal_error(series: dict[str, list[Entry]], targets: Iterable[float]) -> list[Verdict]:
    return [verdict(series, t, by_time=True) for t in targets]


def matched_winner(v: Verdict) -> Optional[str]:
    """The column's winner on the matched basis (lowest matched error among the same best
    entries, compensating ones included: the matched basis does not reward surplus energy).
    Entries that claim no indirect bounce are left out: their matched reference has no
    indirect light, so they are exact on it by construction."""
    have = {s: e for s, e in v.best.items() if e.matched is not None and e.bounces != 0}
    if not have:
        return None
    return min(have, key=lambda s: (have[s].matched, s))


# ------------------------------------------------------------------------------------------------
# Cost
# ------------------------------------------------------------------------------------------------
@dataclass
class CostSplit:
    fixed_ms: float  # per-frame cost that does not grow with the image (per scene, per pass)
    per_mpixel_ms: float  # cost per million pixels

    def at(self, pixels: float) -> float:
        return self.fixed_ms + self.per_mpixel_ms * pixels / 1e6


def cost_split(small: tuple[float, float], large: tuple[float, float]) -> Optional[CostSplit]:
    """From (pixels, ms) at two image sizes: t = fixed + per_pixel * pixels. None when the sizes
    are equal. A negative fixed part (noise, or a cost that grows faster than the pixel count)
    is kept as measured: the caller shows it."""
    (n1, t1), (n2, t2) = small, large
    if n1 == n2 or None in (t1, t2):
        return None
    slope = (t2 - t1) / (n2 - n1)
    return CostSplit(fixed_ms=t1 - slope * n1, per_mpixel_ms=slope * 1e6)


def payback_frames(setup_ms: Optional[float], update_ms: Optional[float],
                   static_ms: Optional[float]) -> Optional[float]:
    """Frames after which a precomputation pays back: set-up / (update frame - static frame),
    the frames a technique must stay static for its set-up to cost less than redoing the
    update every frame. None when the update is not dearer than the static frame."""
    if None in (setup_ms, update_ms, static_ms) or update_ms <= static_ms:
        return None
    return setup_ms / (update_ms - static_ms)
