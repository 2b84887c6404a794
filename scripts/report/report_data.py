"""Reading gilab results folders (results/<experiment>/) into Run records.

A results folder holds runs/<key>/result.json, one per finished run (folders whose name starts
with '.' are runs in progress and are ignored), references/<scene>/*.png and optionally
experiment.json. Several folders (shards of one experiment) are merged by run key.

Everything read from JSON is treated as untrusted: a missing key, a null, a string where a number
was expected all become None, never an exception. A result.json that cannot be parsed is kept as
an Unreadable entry with its path so that the page can list it.
"""
from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from typing import Any, Iterable, Optional

# Statuses of a committed run folder. "invalid": Vulkan validation reported an error or warning
# during the run; its numbers are shown but never ranked (docs/report.md).
RUN_STATUSES = ("ok", "nonfinite", "unsupported", "invalid")

# Key names of a metric set M: the C++ toJson's spelling (docs/metrics.md, "JSON") first, then
# other spellings that earlier drafts of the schema used.
METRIC_ALIASES: dict[str, tuple[str, ...]] = {
    "rel_mse": ("rel_mse", "relmse", "relMse"),
    "psnr_ldr": ("psnr_ldr", "psnrLdr"),
    "psnr_hdr": ("psnr_hdr", "psnrHdr"),
    "flip_ldr": ("flip_ldr", "flipLdr"),
    "test_nonfinite": ("test_non_finite", "test_nonfinite", "testNonFinite"),
    "ref_nonfinite": ("ref_non_finite", "ref_nonfinite", "refNonFinite"),
    "has_nonfinite": ("has_non_finite", "has_nonfinite", "hasNonFinite"),
    "error_bars": ("error_bars", "bars"),
    "within_reference_noise": ("within_reference_noise", "withinReferenceNoise"),
    "rel_mse_sigma": ("rel_mse_sigma", "relmse_sigma"),
    "mse_sigma": ("mse_sigma",),
    "floor_mean": ("floor_mean", "floorMean"),
    "within_noise": ("within_noise", "withinNoise"),
}


def dig(data: Any, *path: str) -> Any:
    """data[path[0]][path[1]]..., or None when any step is missing or not an object."""
    for step in path:
        if not isinstance(data, dict):
            return None
        data = data.get(step)
    return data


def num(value: Any) -> Optional[float]:
    """A finite float, or None (nulls, strings, booleans, NaN and Inf all give None)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    value = float(value)
    return value if math.isfinite(value) else None


def text(value: Any) -> str:
    """A display string for a scalar JSON value ('' for None)."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) and value.is_integer() and abs(value) < 1e15:
        return str(int(value))
    if isinstance(value, (dict, list)):
        return json.dumps(value, separators=(",", ":"))
    return str(value)


def metric(metric_set: Any, name: str) -> Any:
    """One entry of a metric set M, accepting the aliases in METRIC_ALIASES."""
    if not isinstance(metric_set, dict):
        return None
    for alias in METRIC_ALIASES.get(name, (name,)):
        if alias in metric_set:
            return metric_set[alias]
    return None


@dataclass
class MetricView:
    """The numbers of one metric set M the report shows (None = not available)."""

    flip_mean: Optional[float] = None
    flip_sigma: Optional[float] = None
    flip_within_noise: bool = False
    rel_mse: Optional[float] = None
    rel_mse_sigma: Optional[float] = None
    psnr_ldr: Optional[float] = None
    psnr_ldr_sigma: Optional[float] = None
    ssim: Optional[float] = None
    test_nonfinite: Optional[float] = None
    within_reference_noise: bool = False
    bars_available: bool = False

    @staticmethod
    def parse(metric_set: Any) -> "MetricView":
        # error_bars is null without a reference stderr image (docs/metrics.md); an
        # "available": false inside the object is accepted too.
        bars = metric(metric_set, "error_bars")
        available = isinstance(bars, dict) and bars.get("available") is not False
        flip_bar = bars.get("flip") if isinstance(bars, dict) else None
        return MetricView(
            flip_mean=num(dig(metric(metric_set, "flip"), "mean")),
            flip_sigma=num(dig(flip_bar, "spread")) if available else None,
            flip_within_noise=available and metric(flip_bar, "within_noise") is True,
            rel_mse=num(metric(metric_set, "rel_mse")),
            rel_mse_sigma=num(metric(bars, "rel_mse_sigma")) if available else None,
            psnr_ldr=num(metric(metric_set, "psnr_ldr")),
            psnr_ldr_sigma=num(dig(metric(bars, "psnr_ldr"), "spread")) if available else None,
            ssim=num(metric(metric_set, "ssim")),
            test_nonfinite=num(metric(metric_set, "test_nonfinite")),
            within_reference_noise=metric(metric_set, "within_reference_noise") is True,
            bars_available=available,
        )


@dataclass
class Run:
    """One finished run (result.json) and the numbers derived from it."""

    data: dict
    folder: str  # absolute path of runs/<key>/
    results_dir: str  # absolute path of the results folder it was read from
    key: str
    index: Optional[int]
    status: str
    reason: str
    scene: str
    technique: str
    params: dict
    swept: dict
    final: MetricView  # against the bounce-matched reference (metrics.final)
    vs_full: MetricView  # against the full reference (metrics.final_vs_full)
    indirect: MetricView
    direct: MetricView  # direct-light layer vs. the reference's emission+direct (metrics.direct)
    regions: dict  # region name -> MetricView of its final layer
    energy_ratio: Optional[float]
    frame_ms: Optional[float]  # median frame time (GPU, else CPU)
    frame_q1: Optional[float]
    frame_q3: Optional[float]
    frame_iqr: Optional[float]
    frame_source: str  # "gpu", "cpu" or ""
    setup_ms: Optional[float]
    date: str
    # metrics.final_vs_bounces: "0", "1", "2" -> the final image against the reference with that
    # many indirect bounces, whatever the technique claims (puts `direct` next to 1-bounce GI)
    vs_bounces: dict = field(default_factory=dict)
    claimed_bounces: Optional[int] = None  # technique.indirect_bounces (-1 = all)
    device_type: str = ""  # device.type: "cpu" (lavapipe), "discrete", "integrated", ...
    device_driver: str = ""  # device.driver

    @property
    def measured(self) -> bool:
        """Has images and numbers to compare (ok or nonfinite; invalid runs are not trusted)."""
        return self.status in ("ok", "nonfinite")

    def validation_counts(self) -> tuple[Optional[float], Optional[float]]:
        """(errors, warnings) reported by Vulkan validation during the run (None = unknown)."""
        return (num(dig(self.data, "validation", "errors")),
                num(dig(self.data, "validation", "warnings")))

    def first_validation_message(self) -> str:
        """The first validation message recorded, '' when there is none."""
        messages = dig(self.data, "validation", "messages")
        first = messages[0] if isinstance(messages, list) and messages else None
        return first if isinstance(first, str) else ""

    def passes(self) -> list[tuple[str, Optional[float]]]:
        """Per-frame passes in recorded order: (name, median GPU ms)."""
        out = []
        passes = dig(self.data, "timing", "passes")
        for entry in passes if isinstance(passes, list) else []:
            if isinstance(entry, dict):
                out.append((text(entry.get("name")) or "?", num(dig(entry, "gpu_ms", "median"))))
        return out

    def setup_stages(self) -> list[tuple[str, Optional[float]]]:
        """Set-up stages (without the total), in recorded order: (name, CPU ms)."""
        setup = dig(self.data, "timing", "setup_ms")
        if not isinstance(setup, dict):
            return []
        return [(k, num(v)) for k, v in setup.items() if k != "total"]

    def output_path(self, name: str) -> Optional[str]:
        """Absolute path of outputs.<name> (relative to the run folder), None if not given."""
        rel = dig(self.data, "outputs", name)
        if not isinstance(rel, str) or not rel:
            return None
        return os.path.normpath(os.path.join(self.folder, rel))

    def reference_path(self, name: str) -> Optional[str]:
        """Absolute path of reference.<name> (final_png, full_png, indirect_png, ...; relative to
        the run folder), None if not given."""
        rel = dig(self.data, "reference", name)
        if not isinstance(rel, str) or not rel:
            return None
        return os.path.normpath(os.path.join(self.folder, rel))

    def reference_png(self) -> Optional[str]:
        return self.reference_path("final_png")

    def reference_label(self) -> str:
        return text(dig(self.data, "reference", "matched"))


@dataclass
class Unreadable:
    """A run folder whose result.json is missing, malformed or has no known status."""

    path: str
    why: str


@dataclass
class Results:
    """Everything read from one or more results folders."""

    dirs: list[str]
    runs: list[Run] = field(default_factory=list)
    unreadable: list[Unreadable] = field(default_factory=list)
    experiments: list[dict] = field(default_factory=list)  # each folder's experiment.json
    duplicates: int = 0  # runs seen in more than one folder (kept once)


def _frame_summary(data: dict) -> tuple[dict, str]:
    """The frame-time summary to report: GPU if it has a median, else CPU."""
    for source in ("gpu", "cpu"):
        summary = dig(data, "timing", f"frame_{source}_ms")
        if num(dig(summary, "median")) is not None:
            return summary, source
    return {}, ""


def _as_dict(value: Any) -> dict:
    return value if isinstance(value, dict) else {}


def parse_run(data: dict, folder: str, results_dir: str) -> Run:
    """A Run from a parsed result.json (never raises on missing or odd values)."""
    frame, source = _frame_summary(data)
    q1, q3 = num(frame.get("q1")), num(frame.get("q3"))
    iqr = num(frame.get("iqr"))
    if iqr is None and q1 is not None and q3 is not None:
        iqr = q3 - q1
    regions = {
        text(name): MetricView.parse(_as_dict(entry).get("final"))
        for name, entry in _as_dict(dig(data, "metrics", "regions")).items()
    }
    index = dig(data, "index")
    return Run(
        data=data,
        folder=folder,
        results_dir=results_dir,
        key=text(data.get("key")) or os.path.basename(folder),
        index=int(index) if num(index) is not None else None,
        status=text(data.get("status")),
        reason=text(data.get("reason")),
        scene=text(dig(data, "scene", "label")) or "(unknown scene)",
        technique=text(dig(data, "technique", "id")) or "(unknown technique)",
        params=_as_dict(dig(data, "technique", "params")),
        swept=_as_dict(dig(data, "technique", "swept")),
        final=MetricView.parse(dig(data, "metrics", "final")),
        vs_full=MetricView.parse(dig(data, "metrics", "final_vs_full")),
        indirect=MetricView.parse(dig(data, "metrics", "indirect")),
        direct=MetricView.parse(dig(data, "metrics", "direct")),
        regions=regions,
        energy_ratio=num(dig(data, "metrics", "energy_ratio")),
        frame_ms=num(frame.get("median")),
        frame_q1=q1,
        frame_q3=q3,
        frame_iqr=iqr,
        frame_source=source,
        setup_ms=num(dig(data, "timing", "setup_ms", "total")),
        date=text(dig(data, "provenance", "date")),
        vs_bounces={text(k): MetricView.parse(v)
                    for k, v in _as_dict(dig(data, "metrics", "final_vs_bounces")).items()},
        claimed_bounces=(int(num(dig(data, "technique", "indirect_bounces")))
                         if num(dig(data, "technique", "indirect_bounces")) is not None
                         else None),
        device_type=text(dig(data, "device", "type")),
        device_driver=text(dig(data, "device", "driver")),
    )


def _read_json(path: str) -> tuple[Any, str]:
    """(parsed JSON, '') or (None, why it failed)."""
    try:
        with open(path, "r", encoding="utf-8") as f:
            return json.load(f), ""
    except FileNotFoundError:
        return None, "no result.json"
    except (OSError, UnicodeDecodeError, ValueError) as e:
        return None, f"{type(e).__name__}: {e}"


def _read_run_folder(folder: str, results_dir: str) -> Run | Unreadable:
    path = os.path.join(folder, "result.json")
    data, why = _read_json(path)
    if data is None:
        return Unreadable(path, why)
    if not isinstance(data, dict):
        return Unreadable(path, "result.json is not a JSON object")
    status = data.get("status")
    if status not in RUN_STATUSES:
        return Unreadable(path, f"status {status!r} is not one of {', '.join(RUN_STATUSES)}")
    return parse_run(data, folder, results_dir)


def _run_folders(results_dir: str) -> Iterable[str]:
    runs_dir = os.path.join(results_dir, "runs")
    if not os.path.isdir(runs_dir):
        return []
    names = sorted(n for n in os.listdir(runs_dir) if not n.startswith("."))
    return [os.path.join(runs_dir, n) for n in names if os.path.isdir(os.path.join(runs_dir, n))]


def _sort_key(run: Run) -> tuple:
    return (run.index if run.index is not None else 1 << 62, run.key)


def load_results(dirs: list[str]) -> Results:
    """Reads every run of every folder; a key seen twice keeps the run with the later date."""
    results = Results(dirs=[os.path.abspath(d) for d in dirs])
    by_key: dict[str, Run] = {}
    for results_dir in results.dirs:
        experiment, _ = _read_json(os.path.join(results_dir, "experiment.json"))
        if isinstance(experiment, dict):
            results.experiments.append(experiment)
        for folder in _run_folders(results_dir):
            item = _read_run_folder(folder, results_dir)
            if isinstance(item, Unreadable):
                results.unreadable.append(item)
                continue
            previous = by_key.get(item.key)
            if previous is not None:
                results.duplicates += 1
                if previous.date >= item.date:
                    continue
            by_key[item.key] = item
    results.runs = sorted(by_key.values(), key=_sort_key)
    return results
