"""Noise rules: when two runs can be told apart, and what a front or a trend may claim.

The rules are verdicts.py's, the same as the study's: two errors are *separable* when
|e_a − e_b| > sqrt(σ_a² + σ_b²) (σ the metric's 1σ error bar from the reference's noise; 0 when
the metric has none); two frame times when |t_a − t_b| > sqrt(h_a² + h_b²), h the half-width of
each run's interquartile range over its timed frames (0 without quartiles). A difference that is
not separable is never called better, worse, a trend or a ranking: it is a tie (docs/report.md,
"Noise").
"""
from __future__ import annotations

from typing import Callable, Optional

from . import verdicts as V
from .data import Run

Metric = Callable[[Run], Optional[float]]

# A timing whose interquartile range is above this fraction of its median is flagged as noisy
# wherever it is shown (docs/report.md, "Noisy timings").
NOISY_IQR_FRACTION = 0.10
# How figures mark a noisy frame time: a red square, SVG id NOISY_GID + run key, a legend entry.
NOISY_GID = "noisy-time-"
NOISY_COLOR = "#b3261e"
NOISY_LABEL = f"noisy frame time: IQR > {100 * NOISY_IQR_FRACTION:.0f} % of the median"


def noisy_time(median: Optional[float], iqr: Optional[float]) -> bool:
    """Whether a timing's IQR is above NOISY_IQR_FRACTION of its median."""
    return (median is not None and iqr is not None and median > 0
            and iqr > NOISY_IQR_FRACTION * median)


def noisy_run(run: Run) -> bool:
    """Whether the frame time a run is ranked by is noisy."""
    return noisy_time(run.frame_ms, run.frame_iqr)


def time_interval(run: Run) -> tuple[float, float]:
    """[q1, q3] of the frame time (the median where a quartile is missing)."""
    median = run.frame_ms if run.frame_ms is not None else 0.0
    lo = run.frame_q1 if run.frame_q1 is not None else median
    hi = run.frame_q3 if run.frame_q3 is not None else median
    return min(lo, median), max(hi, median)


def clearly_lower(a: float, a_sigma: Optional[float], b: float, b_sigma: Optional[float]
                  ) -> bool:
    """a < b beyond the noise of the difference (verdicts.error_bound's rule)."""
    return b - a > V.error_bound(V.Entry("", "", None, a, error_sigma=abs(a_sigma or 0.0)),
                                 V.Entry("", "", None, b, error_sigma=abs(b_sigma or 0.0)))


def _time_entry(run: Run) -> V.Entry:
    lo, hi = time_interval(run)
    t = run.frame_ms if run.frame_ms is not None else 0.0
    return V.Entry("", "", t, 0.0, time_spread=(hi - lo) / 2.0 / t if t > 0 else 0.0)


def time_separable(a: Run, b: Run) -> bool:
    return not V.time_tie(_time_entry(a), _time_entry(b))


def error_separable(a: Run, b: Run, error: Metric, sigma: Metric) -> bool:
    ea, eb = error(a), error(b)
    if ea is None or eb is None:
        return True
    return not V.error_tie(V.Entry("", "", None, ea, error_sigma=abs(sigma(a) or 0.0)),
                           V.Entry("", "", None, eb, error_sigma=abs(sigma(b) or 0.0)))


def inseparable(a: Run, b: Run, error: Metric, sigma: Metric) -> bool:
    """Neither frame time nor error tells the runs apart: a tie."""
    return not time_separable(a, b) and not error_separable(a, b, error, sigma)


def front_ties(points: list[Run], front: list[Run], error: Metric, sigma: Metric
               ) -> dict[int, Run]:
    """Runs off the front that are inseparable from a front run (id(run) -> that front run):
    within the noise they are as good as the front, so the front marks them as ties."""
    ties: dict[int, Run] = {}
    on_front = {id(r) for r in front}
    for run in points:
        if id(run) in on_front:
            continue
        for member in front:
            if inseparable(run, member, error, sigma):
                ties[id(run)] = member
                break
    return ties


def tied_best(best: Run, runs: list[Run], error: Metric, sigma: Metric) -> list[Run]:
    """The other runs whose error cannot be told apart from the best one's."""
    out = []
    for run in runs:
        if run is best or error(run) is None or error(best) is None:
            continue
        if not error_separable(run, best, error, sigma):
            out.append(run)
    return out


def change_words(first: float, first_sigma: Optional[float], last: float,
                 last_sigma: Optional[float], fmt: Callable[[float], str],
                 floor: Optional[float] = None, seed_sigma: float = 0.0) -> str:
    """'falls from a to b' / 'rises from a to b' only when |b − a| is beyond the noise band,
    else 'unchanged within noise (±band: …)'. The band is the larger of the scene's noise
    floor (floor: the HDR-FLIP of the reference's noise alone; a smaller change of the mean is
    less than the reference's own noise shows) and the 1σ of the difference (error bars and the
    technique's seed spread, verdicts.error_bound)."""
    bars = V.error_bound(V.Entry("", "", None, first, error_sigma=abs(first_sigma or 0.0),
                                 seed_sigma=seed_sigma),
                         V.Entry("", "", None, last, error_sigma=abs(last_sigma or 0.0),
                                 seed_sigma=seed_sigma))
    band = max(floor or 0.0, bars)
    source = ("the reference's noise floor" if floor and floor >= bars else
              "the error bars" + (" and seed spread" if seed_sigma else ""))
    if abs(last - first) > band:
        verb = "falls" if last < first else "rises"
        beyond = f" (beyond ±{fmt(band)}, {source})" if band > 0 else ""
        return f"{verb} from {fmt(first)} to {fmt(last)}{beyond}"
    if band == 0:
        return f"unchanged ({fmt(first)} … {fmt(last)})"
    return (f"unchanged within noise (±{fmt(band)}, {source}: {fmt(first)} … {fmt(last)})")


def time_change_words(first: Run, last: Run, fmt: Callable[[float], str],
                      spread: Optional[float] = None) -> str:
    """The frame-time change between two runs, in words, only beyond their IQRs (and the
    technique's between-run spread, a fraction of the time, where measured: spread)."""
    if first.frame_ms is None or last.frame_ms is None:
        return "unknown"
    a, b = _time_entry(first), _time_entry(last)
    if spread:
        a.time_spread, b.time_spread = max(a.time_spread, spread), max(b.time_spread, spread)
    band = V.time_bound(a, b)
    if abs(last.frame_ms - first.frame_ms) > band:
        verb = "falls" if last.frame_ms < first.frame_ms else "rises"
        return f"{verb} from {fmt(first.frame_ms)} to {fmt(last.frame_ms)} ms"
    what = "IQR and run-to-run spread" if spread else "IQR"
    return (f"unchanged within noise (±{fmt(band)} ms, {what}: {fmt(first.frame_ms)} … "
            f"{fmt(last.frame_ms)} ms)")
