"""What the frame times were measured on, in words: every time axis and time column names it.

A run on a CPU device (device.type "cpu": Mesa's lavapipe, Vulkan on the llvmpipe software
rasteriser) has "GPU timestamps" that time a CPU rasteriser: its times are not GPU times and
rank techniques differently from a GPU. The report therefore never calls them GPU times.
"""
from __future__ import annotations

from typing import Optional

from report_data import Run

LAVAPIPE = "lavapipe (CPU)"
LAVAPIPE_DRIVERS = ("", "llvmpipe", "lavapipe")


def device_of(run: Run) -> str:
    """'lavapipe (CPU)', '<driver> (CPU)' for another CPU device, 'GPU', or '' when unknown."""
    if run.device_type == "cpu":
        driver = run.device_driver.lower()
        return LAVAPIPE if driver in LAVAPIPE_DRIVERS else f"{run.device_driver} (CPU)"
    return "GPU" if run.device_type else ""


def device_label(runs: list[Run]) -> str:
    """The device every run's time was measured on ('mixed devices' when they differ; 'GPU'
    when no run says, as the runner times GPU passes)."""
    labels = {device_of(r) for r in runs} - {""}
    if not labels:
        return "GPU"
    return labels.pop() if len(labels) == 1 else "mixed devices: " + ", ".join(sorted(labels))


def any_cpu_device(runs: list[Run]) -> bool:
    return any(r.device_type == "cpu" for r in runs)


# What an animated scene's frame times are (docs/report.md, "Animated scenes").
DYNAMIC_FRAME = "dynamic frame (light/camera moved, update included)"


def dynamic_clock(runs: list[Run]) -> bool:
    """Whether these runs are timed by their dynamic frame (all of an animated scene)."""
    return bool(runs) and all(r.dynamic_clock for r in runs)


def time_label(runs: list[Run], what: str = "frame time", unit: str = "ms",
               dynamic: Optional[bool] = None) -> str:
    """An axis label or table header: 'frame time, lavapipe (CPU), ms'; for runs ranked by their
    dynamic frame (dynamic None: when every run is; True/False to force) 'frame time, dynamic
    frame (light/camera moved, update included), lavapipe (CPU), ms'."""
    if dynamic is None:
        dynamic = dynamic_clock(runs)
    if dynamic and "frame time" in what:
        what = f"{what}, {DYNAMIC_FRAME}"
    label = f"{what}, {device_label(runs)}"
    sources = [r.frame_source for r in runs] if dynamic else \
        [r.static.source or r.frame_source for r in runs]
    if "cpu" in sources and "frame time" in what:
        label += " (CPU clock where no timestamps)"
    return f"{label}, {unit}" if unit else label


def device_note_html(runs: list[Run]) -> str:
    """The header's warning about what CPU-device timings mean ('' for GPU runs)."""
    if not any_cpu_device(runs):
        return ""
    return ("<b>Timings are from lavapipe (CPU)</b>: Vulkan on the llvmpipe CPU rasteriser. "
            "Every frame and pass time in this report is the time a CPU took to rasterise and "
            "shade, not a GPU time: costs scale with pixels, texels and shader work on a few "
            "CPU cores, so techniques rank differently than they would on a GPU (memory "
            "bandwidth, occupancy and fixed-function hardware are not modelled). Compare times "
            "only within this report.")
