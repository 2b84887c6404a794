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
    flip_floor: Optional[float] = None  # HDR-FLIP of the reference's noise alone (floor_mean)
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
            flip_floor=num(metric(flip_bar, "floor_mean")) if available else None,
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
class TimeSummary:
    """One timing block (median, q1, q3, iqr) of result.json's timing; None = not recorded."""

    median: Optional[float] = None
    q1: Optional[float] = None
    q3: Optional[float] = None
    iqr: Optional[float] = None
    source: str = ""  # "gpu" (timestamps), "cpu" (CPU clock) or ""

    @staticmethod
    def parse(summary: Any, source: str = "") -> "TimeSummary":
        summary = summary if isinstance(summary, dict) else {}
        q1, q3 = num(summary.get("q1")), num(summary.get("q3"))
        iqr = num(summary.get("iqr"))
        if iqr is None and q1 is not None and q3 is not None:
            iqr = q3 - q1
        median = num(summary.get("median"))
        return TimeSummary(median, q1, q3, iqr, source if median is not None else "")


@dataclass
class Temporal:
    """A temporal-instability block (toJson(TemporalResult), docs/metrics.md "Temporal
    instability"): how wrong the frame-to-frame change is, relative to the reference's level."""

    instability: Optional[float] = None  # temporal_instability
    p95: Optional[float] = None
    noise_floor: Optional[float] = None
    debiased: Optional[float] = None
    mean_abs: Optional[float] = None
    level: Optional[float] = None
    frames: Optional[float] = None
    pairs: Optional[float] = None
    samples: Optional[float] = None
    skipped: Optional[float] = None  # skipped_pixels
    note: str = ""

    @staticmethod
    def parse(block: Any) -> "Temporal":
        block = block if isinstance(block, dict) else {}
        return Temporal(num(block.get("temporal_instability")), num(block.get("p95")),
                        num(block.get("noise_floor")), num(block.get("debiased")),
                        num(block.get("mean_abs")), num(block.get("level")),
                        num(block.get("frames")), num(block.get("pairs")),
                        num(block.get("samples")), num(block.get("skipped_pixels")),
                        text(block.get("note")) if isinstance(block.get("note"), str) else "")

    @property
    def within_noise(self) -> bool:
        """The instability is no larger than the reference's noise floor: no measurable
        instability (docs/metrics.md)."""
        return (self.instability is not None and self.noise_floor is not None
                and self.instability <= self.noise_floor)


@dataclass
class SequenceFrame:
    """One measured frame of an animated run (metrics.sequence.frames[i])."""

    frame: Optional[int]
    time_s: Optional[float]
    vs_full: "MetricView"  # final_vs_full: against the full reference of that frame
    matched: "MetricView"  # final: against the bounce-matched reference of that frame


def _mean(values: list[Optional[float]]) -> Optional[float]:
    """The mean when every value is known (never a mean over a subset), else None."""
    if not values or any(v is None for v in values):
        return None
    return sum(values) / len(values)


@dataclass
class Animation:
    """What an animated scene's run adds (docs/report.md, "Animated scenes"); every part
    optional."""

    frames: Optional[int] = None  # animation.frames: frames of the animation
    duration_s: Optional[float] = None
    measured: list[int] = field(default_factory=list)  # animation.measured_frames
    update: str = ""  # "incremental", "full rebuild", "none" or ""
    sequence: list[SequenceFrame] = field(default_factory=list)
    full_flip_mean: Optional[float] = None  # metrics.sequence.full_flip_mean
    full_rel_mse_mean: Optional[float] = None
    matched_flip_mean: Optional[float] = None
    matched_rel_mse_mean: Optional[float] = None  # computed from the frames (not in JSON)
    temporal: Temporal = field(default_factory=Temporal)
    temporal_matched: Temporal = field(default_factory=Temporal)
    dynamic: TimeSummary = field(default_factory=TimeSummary)  # dynamic_frame_{gpu,cpu}_ms
    # The dynamic frame's shared passes (G-buffer, shadow maps and cascades, direct light) and
    # the technique's own passes, GPU clock (timing.dynamic_frame_{shared,technique}_gpu_ms)
    dynamic_shared: TimeSummary = field(default_factory=TimeSummary)
    dynamic_technique: TimeSummary = field(default_factory=TimeSummary)
    update_cpu: TimeSummary = field(default_factory=TimeSummary)  # update_cpu_ms
    update_passes: list[tuple[str, Optional[float]]] = field(default_factory=list)
    update_pass_times: dict[str, TimeSummary] = field(default_factory=dict)  # name -> summary

    @property
    def measured_count(self) -> Optional[int]:
        """N, the number of measured frames the sequence means are taken over."""
        for n in (len(self.measured), len(self.sequence), self.temporal.frames):
            if n:
                return int(n)
        return None

    def frame_times(self) -> list[Optional[float]]:
        """The time (s) of each measured frame: sequence.frames[].time_s, else from the
        duration (frames evenly spaced over duration_s)."""
        if self.sequence and all(f.time_s is not None for f in self.sequence):
            return [f.time_s for f in self.sequence]
        out = []
        for index in self.measured:
            if self.duration_s is not None and self.frames and self.frames > 1:
                out.append(self.duration_s * index / (self.frames - 1))
            else:
                out.append(None)
        return out


def parse_animation(data: dict) -> Optional["Animation"]:
    """The animated-scene parts of a result.json, None for a static scene (no `animation` and no
    `metrics.sequence` object)."""
    block = dig(data, "animation")
    sequence = dig(data, "metrics", "sequence")
    if not isinstance(block, dict) and not isinstance(sequence, dict):
        return None
    block = _as_dict(block)
    sequence = _as_dict(sequence)
    frames = []
    for entry in sequence.get("frames") if isinstance(sequence.get("frames"), list) else []:
        if isinstance(entry, dict):
            index = num(entry.get("frame"))
            frames.append(SequenceFrame(int(index) if index is not None else None,
                                        num(entry.get("time_s")),
                                        MetricView.parse(entry.get("final_vs_full")),
                                        MetricView.parse(entry.get("final"))))
    measured = block.get("measured_frames")
    measured = [int(num(i)) for i in measured if num(i) is not None] \
        if isinstance(measured, list) else []
    if not measured and frames and all(f.frame is not None for f in frames):
        measured = [f.frame for f in frames]
    count = num(block.get("frames"))
    dynamic = TimeSummary()
    for source in ("gpu", "cpu"):
        dynamic = TimeSummary.parse(dig(data, "timing", f"dynamic_frame_{source}_ms"), source)
        if dynamic.median is not None:
            break
    passes = dig(data, "timing", "update_passes")
    update_passes = [(text(p.get("name")) or "?", num(dig(p, "gpu_ms", "median")))
                     for p in (passes if isinstance(passes, list) else []) if isinstance(p, dict)]
    update_pass_times = {text(p.get("name")) or "?": TimeSummary.parse(p.get("gpu_ms"), "gpu")
                         for p in (passes if isinstance(passes, list) else [])
                         if isinstance(p, dict)}
    update = block.get("update")
    return Animation(
        frames=int(count) if count is not None else None,
        duration_s=num(block.get("duration_s")),
        measured=measured,
        update=update if isinstance(update, str) else "",
        sequence=frames,
        full_flip_mean=_sequence_mean(sequence, "full_flip_mean",
                                      [f.vs_full.flip_mean for f in frames]),
        full_rel_mse_mean=_sequence_mean(sequence, "full_rel_mse_mean",
                                         [f.vs_full.rel_mse for f in frames]),
        matched_flip_mean=_sequence_mean(sequence, "matched_flip_mean",
                                         [f.matched.flip_mean for f in frames]),
        matched_rel_mse_mean=_sequence_mean(sequence, "matched_rel_mse_mean",
                                            [f.matched.rel_mse for f in frames]),
        temporal=Temporal.parse(sequence.get("temporal")),
        temporal_matched=Temporal.parse(sequence.get("temporal_matched")),
        dynamic=dynamic,
        dynamic_shared=TimeSummary.parse(dig(data, "timing", "dynamic_frame_shared_gpu_ms"), "gpu"),
        dynamic_technique=TimeSummary.parse(dig(data, "timing", "dynamic_frame_technique_gpu_ms"),
                                            "gpu"),
        update_cpu=TimeSummary.parse(dig(data, "timing", "update_cpu_ms"), "cpu"),
        update_passes=update_passes,
        update_pass_times=update_pass_times)


def _sequence_mean(sequence: dict, key: str, per_frame: list[Optional[float]]
                   ) -> Optional[float]:
    """metrics.sequence.<key> as the runner wrote it; when it is missing, the mean of the
    per-frame values if every measured frame has one."""
    value = num(sequence.get(key))
    return value if value is not None else _mean(per_frame)


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
    # The frame time every ranking, front and figure uses: the static frame (GPU, else CPU), or,
    # on an animated scene, the dynamic frame (use_dynamic_clock).
    frame_ms: Optional[float]
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
    device_name: str = ""  # device.name: "NVIDIA H200", "llvmpipe (LLVM 15.0.6, 256 bits)"
    host: str = ""  # the node it ran on (short hostname); "" = unknown
    # The static frame (timing.frame_gpu_ms, else frame_cpu_ms), whatever the ranking clock is.
    static: TimeSummary = field(default_factory=TimeSummary)
    anim: Optional[Animation] = None  # None: a static scene's run
    dynamic_clock: bool = False  # frame_* hold the dynamic frame (an animated scene)

    @property
    def animated(self) -> bool:
        return self.anim is not None

    def use_dynamic_clock(self) -> None:
        """Ranks this run by its dynamic frame (light/camera moved, update included): frame_*
        become the dynamic frame's numbers (None when it was not timed); `static` keeps the
        static frame."""
        dynamic = self.anim.dynamic if self.anim is not None else TimeSummary()
        self.frame_ms, self.frame_q1, self.frame_q3 = dynamic.median, dynamic.q1, dynamic.q3
        self.frame_iqr, self.frame_source = dynamic.iqr, dynamic.source
        self.dynamic_clock = True

    def output_list(self, name: str) -> list[Optional[str]]:
        """Absolute paths of the list outputs.<name> (e.g. frames_png), None for an entry that
        is not a string."""
        return _path_list(dig(self.data, "outputs", name), self.folder)

    def reference_list(self, name: str) -> list[Optional[str]]:
        return _path_list(dig(self.data, "reference", name), self.folder)

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
        return [(name, summary.median) for name, summary in self.pass_times()]

    def pass_times(self) -> list[tuple[str, "TimeSummary"]]:
        """Per-frame passes in recorded order: (name, GPU time summary: median, IQR)."""
        out = []
        passes = dig(self.data, "timing", "passes")
        for entry in passes if isinstance(passes, list) else []:
            if isinstance(entry, dict):
                out.append((text(entry.get("name")) or "?",
                            TimeSummary.parse(entry.get("gpu_ms"), "gpu")))
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


def _path_list(value: Any, folder: str) -> list[Optional[str]]:
    if not isinstance(value, list):
        return []
    return [os.path.normpath(os.path.join(folder, v)) if isinstance(v, str) and v else None
            for v in value]


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


def _host(data: dict) -> str:
    """The top-level "host"; older results only have provenance.host (cut to its short
    name); '' when neither is a non-empty string."""
    host = data.get("host")
    if isinstance(host, str) and host:
        return host
    host = dig(data, "provenance", "host")
    return host.split(".")[0] if isinstance(host, str) else ""


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
        device_name=text(dig(data, "device", "name")),
        host=_host(data),
        static=TimeSummary(num(frame.get("median")), q1, q3, iqr, source),
        anim=parse_animation(data),
    )


def read_json(path: str) -> tuple[Any, str]:
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
    data, why = read_json(path)
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
        experiment, _ = read_json(os.path.join(results_dir, "experiment.json"))
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
    apply_clocks(results.runs)
    return results


def apply_clocks(runs: list[Run]) -> None:
    """On a scene with animated runs, every run of the scene is ranked by its dynamic frame
    (a run without one is left out of the time rankings rather than mixed with them)."""
    animated = {r.scene for r in runs if r.animated}
    for run in runs:
        if run.scene in animated:
            run.use_dynamic_clock()
