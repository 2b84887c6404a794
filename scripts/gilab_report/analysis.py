"""The report's derived quantities: colours, best runs, Pareto fronts, sweeps, equal-time and
equal-error tables. Every definition here is restated in docs/report.md.
"""
from __future__ import annotations

import hashlib
import math
import re
from dataclasses import dataclass
from typing import Any, Callable, Optional

from .data import Animation, MetricView, Run, num, text
from .device import device_group, device_groups
from . import verdicts as V
from .noise import front_ties

# Okabe & Ito's colour-blind-safe palette (without yellow, hard to see on white), then more.
TECHNIQUE_PALETTE = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9",
                     "#882255", "#117733", "#332288", "#AA4499", "#44AA99", "#999933")
BASELINE_COLOR = "#4d4d4d"  # the "direct" technique (no indirect light)
BASELINE_TECHNIQUES = ("direct",)
# Shared passes and set-up stages are grey; a technique's own passes are shades of its colour.
GREYS = ("#cfcfcf", "#a6a6a6", "#7d7d7d", "#bababa", "#919191", "#e3e3e3", "#686868")
BUDGET_STEPS = (1.0, 2.0, 5.0)
ERROR_QUANTILES = (0.9, 0.75, 0.5, 0.25, 0.1)
MIN_COMPARED = 2  # a reference group needs this many ok runs for a front / equal-time table


def technique_colors(techniques: list[str]) -> dict[str, str]:
    """One colour per technique id (sorted order), the same in every figure and table."""
    colors: dict[str, str] = {}
    others = [t for t in sorted(set(techniques)) if t not in BASELINE_TECHNIQUES]
    for i, tech in enumerate(others):
        colors[tech] = TECHNIQUE_PALETTE[i % len(TECHNIQUE_PALETTE)]
    for tech in set(techniques) & set(BASELINE_TECHNIQUES):
        colors[tech] = BASELINE_COLOR
    return colors


def shade(color: str, i: int, n: int) -> str:
    """Member i of n in one hue, light to dark ('#rrggbb' in and out)."""
    r, g, b = (int(color[k:k + 2], 16) / 255.0 for k in (1, 3, 5))
    t = 0.5 if n <= 1 else i / (n - 1)
    if t < 0.5:
        a = (0.5 - t) * 1.1  # toward white
        r, g, b = (c + (1.0 - c) * a for c in (r, g, b))
    else:
        a = (t - 0.5) * 0.9  # toward black
        r, g, b = (c * (1.0 - a) for c in (r, g, b))
    return "#" + "".join(f"{round(c * 255):02x}" for c in (r, g, b))


def pass_owner(name: str, techniques: dict[str, str]) -> Optional[str]:
    """The technique a pass belongs to ('<id>/<pass>'), None for a shared pass."""
    for sep in ("/", "."):
        prefix = name.split(sep, 1)[0]
        if sep in name and prefix in techniques:
            return prefix
    return None


def pass_colors(names: list[str], tech_colors: dict[str, str]) -> dict[str, str]:
    """Shared passes in greys; each technique's passes in shades of its colour."""
    unique = list(dict.fromkeys(names))
    owned: dict[Optional[str], list[str]] = {}
    for name in unique:
        owned.setdefault(pass_owner(name, tech_colors), []).append(name)
    colors = {n: GREYS[i % len(GREYS)] for i, n in enumerate(owned.pop(None, []))}
    for tech, members in owned.items():
        for i, name in enumerate(members):
            colors[name] = shade(tech_colors[tech], i, len(members))
    return colors


def slug(label: str) -> str:
    """A file-name-safe version of a label; a short hash keeps distinct labels distinct."""
    safe = re.sub(r"[^A-Za-z0-9_.-]+", "_", label).strip("_.") or "x"
    if safe == label:
        return safe
    return f"{safe}-{hashlib.sha1(label.encode('utf-8')).hexdigest()[:6]}"


def ordered_unique(values: list[str]) -> list[str]:
    return list(dict.fromkeys(values))


def _none_last(value: Optional[float]) -> tuple[bool, float]:
    return (value is None, value if value is not None else 0.0)


def best_key(run: Run, basis: "Basis") -> tuple:
    """Ordering of 'best': lowest mean FLIP of the basis, then its relMSE, then fastest (None
    last)."""
    return (_none_last(basis.flip(run)), _none_last(basis.rel_mse(run)),
            _none_last(run.frame_ms), run.key)


def best_run(runs: list[Run], basis: "Basis") -> Optional[Run]:
    """The best ok run (best_key on the basis); a nonfinite one only if there is no ok run."""
    for status in ("ok", "nonfinite"):
        candidates = [r for r in runs if r.status == status]
        if candidates:
            return min(candidates, key=lambda r: best_key(r, basis))
    return None


def best_runs(runs: list[Run], basis: "Basis") -> list[Run]:
    """The best run of each technique and reference group of the basis (one per technique on
    the full basis: every run is compared with the same reference)."""
    out = []
    for tech_runs in by_technique(runs).values():
        groups: dict[str, list[Run]] = {}
        for run in tech_runs:
            groups.setdefault(basis.group(run), []).append(run)
        out += [b for b in (best_run(g, basis) for _, g in sorted(groups.items())) if b]
    return out


def by_scene(runs: list[Run]) -> dict[str, list[Run]]:
    out: dict[str, list[Run]] = {}
    for run in runs:
        out.setdefault(run.scene, []).append(run)
    return out


def by_technique(runs: list[Run]) -> dict[str, list[Run]]:
    out: dict[str, list[Run]] = {}
    for run in sorted(runs, key=lambda r: r.technique):
        out.setdefault(run.technique, []).append(run)
    return out


def pareto_front(runs: list[Run], error: Callable[[Run], Optional[float]]) -> list[Run]:
    """Ok runs not dominated by another ok run (verdicts.pareto: none is both faster-or-equal
    and lower-error; of identical points the first). Sorted by frame time."""
    ok = [r for r in runs if r.status == "ok" and r.frame_ms is not None and error(r) is not None]
    entries = [V.Entry(key=str(i), series="", time=r.frame_ms, error=error(r))
               for i, r in enumerate(ok)]
    return [ok[int(e.key)] for e in V.pareto(entries)]


@dataclass(frozen=True)
class Basis:
    """Which reference errors are measured against, for ranking runs against each other.

    "full": metrics.final_vs_full, against all the light paths, so every run of a scene is
    comparable: the headline basis. "matched": metrics.final, against the reference with the
    light paths the technique claims (the error of what it claims; runs are only ranked against
    runs compared with the same reference). "one_bounce": metrics.final_vs_bounces.1.
    """

    name: str
    caption: str  # "vs. the full reference (all light paths)"
    reference: str  # "full reference", for labels: "HDR-FLIP vs full reference"
    flip: Callable[[Run], Optional[float]]
    flip_sigma: Callable[[Run], Optional[float]]
    rel_mse: Callable[[Run], Optional[float]]
    rel_mse_sigma: Callable[[Run], Optional[float]]
    group: Callable[[Run], str]
    suffix: str = ""  # ", mean over the 5 measured frames" on an animated scene
    # The second view of the scene (the bounce-matched errors): MATCHED when None.
    second: Optional["Basis"] = None

    def label(self, metric: str = "HDR-FLIP", group: str = "") -> str:
        """'HDR-FLIP vs full reference', 'relMSE vs bounce-matched reference (emission+direct)',
        'HDR-FLIP vs full reference, mean over the 5 measured frames'."""
        detail = f" ({group})" if group and self.name == "matched" else ""
        return f"{metric} vs {self.reference}{detail}{self.suffix}"

    @property
    def matched_view(self) -> "Basis":
        """The bounce-matched basis shown next to this one (frame means on an animated scene)."""
        return self.second or MATCHED


MATCHED = Basis("matched", "vs. the bounce-matched reference (the light paths the technique "
                "claims)", "bounce-matched reference", lambda r: r.final.flip_mean,
                lambda r: r.final.flip_sigma, lambda r: r.final.rel_mse,
                lambda r: r.final.rel_mse_sigma, lambda r: r.reference_label())
FULL = Basis("full", "vs. the full reference (all light paths)", "full reference",
             lambda r: r.vs_full.flip_mean, lambda r: r.vs_full.flip_sigma,
             lambda r: r.vs_full.rel_mse, lambda r: r.vs_full.rel_mse_sigma, lambda r: "full")


def _one_bounce(run: Run) -> MetricView:
    return run.vs_bounces.get("1") or MetricView()


ONE_BOUNCE = Basis("one_bounce", "vs. the one-bounce reference (emission + direct + bounce 1)",
                   "one-bounce reference", lambda r: _one_bounce(r).flip_mean,
                   lambda r: _one_bounce(r).flip_sigma, lambda r: _one_bounce(r).rel_mse,
                   lambda r: _one_bounce(r).rel_mse_sigma, lambda r: "emission+direct+bounce1")


def scene_noise_floor(runs: list[Run], basis: Basis) -> Optional[float]:
    """The scene's HDR-FLIP noise floor on the basis: the median over its measured runs of
    error_bars.flip.floor_mean (the HDR-FLIP of the reference's noise alone, what an exact
    image scores); frame 0's on an animated scene. None when no run recorded it."""
    view = (lambda r: r.final) if basis.name == "matched" else (lambda r: r.vs_full)
    values = sorted(v for v in (view(r).flip_floor for r in runs if r.measured) if v is not None)
    if not values:
        return None
    mid = len(values) // 2
    return values[mid] if len(values) % 2 else 0.5 * (values[mid - 1] + values[mid])


def has_one_bounce(runs: list[Run]) -> bool:
    """Whether a one-bounce technique ran next to others (then every run is also ranked against
    the one-bounce reference, so `direct` and 1-bounce GI share one yardstick)."""
    measured = [r for r in runs if r.measured]
    return (any(r.claimed_bounces == 1 for r in measured)
            and any(r.claimed_bounces != 1 for r in measured)
            and any(ONE_BOUNCE.flip(r) is not None for r in measured))


def baseline_value(baseline: Optional[Run], bounces: Optional[int],
                   metric: Callable[[MetricView], Optional[float]]) -> Optional[float]:
    """`metric` of the baseline run against the reference with `bounces` indirect bounces
    (the full reference for -1 / None)."""
    if baseline is None:
        return None
    if bounces is None or bounces < 0 or bounces > 2:
        return metric(baseline.vs_full)
    view = baseline.vs_bounces.get(str(bounces))
    return metric(view) if view is not None else None


def _anim(run: Run) -> Any:
    return run.anim if run.anim is not None else _NO_ANIMATION


_NO_ANIMATION = Animation()


def frames_phrase(runs: list[Run]) -> str:
    """', mean over the 5 measured frames' (or each run's, when the runs differ)."""
    counts = {_anim(r).measured_count for r in runs if r.measured and r.animated} - {None}
    if len(counts) == 1:
        n = counts.pop()
        return f", mean over the {n} measured frame{'s' if n != 1 else ''}"
    return ", mean over each run's measured frames"


def sequence_bases(runs: list[Run]) -> tuple[Basis, Basis]:
    """An animated scene's headline basis (HDR-FLIP vs the full reference, mean over the
    measured frames: metrics.sequence.full_flip_mean) and its bounce-matched view
    (matched_flip_mean), both named with the number of frames."""
    suffix = frames_phrase(runs)
    matched = Basis("matched", MATCHED.caption + ", mean over the measured frames",
                    MATCHED.reference, lambda r: _anim(r).matched_flip_mean, lambda r: None,
                    lambda r: _anim(r).matched_rel_mse_mean, lambda r: None,
                    MATCHED.group, suffix)
    full = Basis("sequence", FULL.caption + ", mean over the measured frames", FULL.reference,
                 lambda r: _anim(r).full_flip_mean, lambda r: None,
                 lambda r: _anim(r).full_rel_mse_mean, lambda r: None, FULL.group, suffix,
                 matched)
    return full, matched


def is_animated_scene(runs: list[Run]) -> bool:
    return any(r.animated for r in runs)


def scene_basis(runs: list[Run]) -> Basis:
    """The one basis every headline number and ranking of a scene uses: on an animated scene the
    mean over the measured frames against the full reference when any measured run has it;
    else FULL when any measured run of the scene has errors against the full reference, else
    MATCHED (older results)."""
    measured = [r for r in runs if r.measured]
    if any(r.animated and _anim(r).full_flip_mean is not None for r in measured):
        return sequence_bases(runs)[0]
    return FULL if any(FULL.flip(r) is not None for r in measured) else MATCHED


def comparable_groups(runs: list[Run], basis: Basis,
                      error: Optional[Callable[[Run], Optional[float]]] = None
                      ) -> dict[str, list[Run]]:
    """Ok runs with a frame time and an error, by the reference they were compared with (only
    groups of at least MIN_COMPARED runs; fewest light paths first)."""
    error = error or basis.flip
    groups: dict[str, list[Run]] = {}
    for run in runs:
        if run.status == "ok" and run.frame_ms is not None and error(run) is not None:
            groups.setdefault(basis.group(run), []).append(run)
    return {label: members for label, members in sorted(groups.items(),
                                                        key=lambda kv: (len(kv[0]), kv[0]))
            if len(members) >= MIN_COMPARED}


def by_device(runs: list[Run]) -> dict[str, list[Run]]:
    """The runs by the device model they were timed on when the measured ones were timed on
    several (their times are never compared), else {'': runs}."""
    devices = device_groups([r for r in runs if r.measured and r.frame_ms is not None])
    if len(devices) < 2:
        return {"": runs}
    return {device: [r for r in runs if device_group(r) == device] for device in devices}


def pareto_fronts(runs: list[Run], basis: Basis,
                  error: Optional[Callable[[Run], Optional[float]]] = None
                  ) -> dict[str, list[Run]]:
    """The Pareto front (of `error`, default the basis' mean FLIP) of each comparable group."""
    error = error or basis.flip
    return {label: pareto_front(members, error)
            for label, members in comparable_groups(runs, basis, error).items()}


def pareto_ties(runs: list[Run], basis: Basis,
                error: Optional[Callable[[Run], Optional[float]]] = None,
                sigma: Optional[Callable[[Run], Optional[float]]] = None
                ) -> dict[str, dict[int, Run]]:
    """Per comparable group: the runs off its front that are inseparable from a front run
    (frame-time IQRs and error bars both overlap), id(run) -> that front run (noise)."""
    error = error or basis.flip
    sigma = sigma or basis.flip_sigma
    out = {}
    for label, members in comparable_groups(runs, basis, error).items():
        out[label] = front_ties(members, pareto_front(members, error), error, sigma)
    return out


def time_budgets(times: list[float]) -> list[float]:
    """1-2-5 budgets [ms]: from the first one ≥ the fastest run to the first ≥ the slowest."""
    if not times:
        return []
    low, high = min(times), max(times)
    budgets: list[float] = []
    decade = 10.0 ** math.floor(math.log10(low)) if low > 0 else 0.01
    while not budgets or budgets[-1] < high:
        for step in BUDGET_STEPS:
            value = round(step * decade, 10)
            if value >= low and (not budgets or budgets[-1] < high):
                budgets.append(value)
        decade *= 10.0
        if len(budgets) > 60:
            break
    return budgets


def error_targets(errors: list[float]) -> list[float]:
    """Target errors: the ERROR_QUANTILES of the observed values, 2 significant digits, unique,
    loosest first."""
    if not errors:
        return []
    values = sorted(errors)
    targets = []
    for q in ERROR_QUANTILES:
        position = q * (len(values) - 1)
        lo = math.floor(position)
        hi = min(lo + 1, len(values) - 1)
        value = values[lo] + (values[hi] - values[lo]) * (position - lo)
        targets.append(float(f"{value:.2g}"))
    return sorted(set(targets), reverse=True)


def best_within_budget(runs: list[Run], budget: float, basis: Basis) -> Optional[Run]:
    """Lowest mean FLIP (of the basis) among the ok runs whose median frame time is ≤ budget."""
    fits = [r for r in runs if r.status == "ok" and r.frame_ms is not None
            and r.frame_ms <= budget and basis.flip(r) is not None]
    return min(fits, key=lambda r: (basis.flip(r), r.frame_ms, r.key)) if fits else None


def cheapest_reaching(runs: list[Run], target: float, basis: Basis) -> Optional[Run]:
    """Fastest ok run whose mean FLIP (of the basis) is ≤ target."""
    fits = [r for r in runs if r.status == "ok" and r.frame_ms is not None
            and basis.flip(r) is not None and basis.flip(r) <= target]
    return min(fits, key=lambda r: (r.frame_ms, basis.flip(r), r.key)) if fits else None


@dataclass
class Sweep:
    """Runs of one technique on one scene that vary `key`; one series per value of the others.
    The runs of one sweep share one set of swept keys (technique.swept): two sweeps of a
    technique over different keys (e.g. `direct` over shared.pcf_radius and, apart, over
    shared.area_light_samples) are never drawn as one grid."""

    technique: str
    scene: str
    key: str
    other_keys: list[str]
    series: dict[tuple, list[Run]]  # values of other_keys -> runs sorted by the swept value
    numeric: bool  # every value of `key` is a number
    keys: tuple[str, ...] = ()  # the sweep's swept keys (key and other_keys), sorted


def param_value(run: Run, key: str) -> object:
    """The value of a swept parameter: the typed one from params, else the swept text."""
    if key in run.params:
        return run.params[key]
    return run.swept.get(key)


def sweep_x(run: Run, key: str) -> Optional[float]:
    value = param_value(run, key)
    if num(value) is not None:
        return num(value)
    try:
        return float(text(value))
    except ValueError:
        return None


def find_sweeps(runs: list[Run]) -> list[Sweep]:
    """Every (technique, scene, set of swept keys, swept key) whose measured runs take ≥ 2
    values of that key. Runs belong to one sweep only when they share the same set of swept
    keys (technique.swept)."""
    sweeps: list[Sweep] = []
    groups: dict[tuple[str, str, tuple[str, ...]], list[Run]] = {}
    for run in runs:
        if run.measured and run.swept:
            keyset = tuple(sorted(run.swept))
            groups.setdefault((run.technique, run.scene, keyset), []).append(run)
    for (tech, scene, keyset), group in sorted(groups.items()):
        keys = ordered_unique([k for r in group for k in r.swept])
        for key in keys:
            values = {text(param_value(r, key)) for r in group}
            if len(values) < 2:
                continue
            others = [k for k in keys if k != key] + _varying_unswept(group, keys)
            numeric = all(sweep_x(r, key) is not None for r in group)
            series: dict[tuple, list[Run]] = {}
            for run in group:
                series.setdefault(tuple(text(param_value(run, k)) for k in others), []).append(run)
            for members in series.values():
                members.sort(key=lambda r: (sweep_x(r, key) if numeric else 0.0,
                                            text(param_value(r, key))))
            ordered = dict(sorted(series.items(), key=lambda item: _series_order(item[0])))
            sweeps.append(Sweep(tech, scene, key, others, ordered, numeric, keyset))
    return sweeps


# Parameters that never split a sweep's lines: seeds and repeats are the spread of one point.
SPREAD_KEYS = ("seed", "repeat")


def _varying_unswept(group: list[Run], swept: tuple[str, ...]) -> list[str]:
    """Parameters that are not swept but differ between the runs of a sweep (e.g. two config
    blocks sweeping the same keys at two `lift` values): each of their values is a line of its
    own, or a line would join runs that differ in more than its key."""
    names = ordered_unique([k for r in group for k in r.params])
    return [k for k in names if k not in swept and k not in SPREAD_KEYS
            and len({text(param_value(r, k)) for r in group}) > 1]


def sweep_names(sweeps: list[Sweep]) -> list[str]:
    """A file-name stem per sweep: 'sweep_<technique>_<scene>_<key>', with '_in_<keys>' added
    where one technique sweeps the same key in two sweeps of a scene."""
    plain = [f"sweep_{slug(s.technique)}_{slug(s.scene)}_{slug(s.key)}" for s in sweeps]
    return [name if plain.count(name) == 1 else f"{name}_in_{slug('+'.join(s.keys))}"
            for name, s in zip(plain, sweeps)]


def _series_order(values: tuple) -> tuple:
    out = []
    for v in values:
        try:
            out.append((0, float(v), ""))
        except ValueError:
            out.append((1, 0.0, v))
    return tuple(out)


def params_text(run: Run, only_swept: bool = False) -> str:
    """'key=value, ...' with swept keys first."""
    keys = ordered_unique(list(run.swept) + ([] if only_swept else list(run.params)))
    return ", ".join(f"{k}={text(param_value(run, k))}" for k in keys)
