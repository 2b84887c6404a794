"""What the frame times were measured on, in words: every time axis and time column names it.

A run on a CPU device (device.type "cpu": Mesa's lavapipe, Vulkan on the llvmpipe software
rasteriser) has "GPU timestamps" that time a CPU rasteriser: its times are not GPU times and
rank techniques differently from a GPU. The report therefore never calls them GPU times.

Runs of one results folder may come from several devices or nodes (Slurm job arrays): the report
groups them by device model (device_groups) and names the nodes (hosts_of), so two devices'
times never share a time axis without saying so.
"""
from __future__ import annotations

from typing import Optional

from .data import Run

LAVAPIPE = "lavapipe (CPU)"
LAVAPIPE_DRIVERS = ("", "llvmpipe", "lavapipe")


def device_of(run: Run) -> str:
    """'lavapipe (CPU)', '<driver> (CPU)' for another CPU device, 'GPU', or '' when unknown."""
    if run.device_type == "cpu":
        driver = run.device_driver.lower()
        return LAVAPIPE if driver in LAVAPIPE_DRIVERS else f"{run.device_driver} (CPU)"
    return "GPU" if run.device_type else ""


UNKNOWN_DEVICE = "unknown device"


def device_group(run: Run) -> str:
    """The device model a run was timed on: 'NVIDIA H200 (GPU)', 'llvmpipe (LLVM 15.0.6, 256
    bits) (lavapipe, CPU)'; device_of() alone without a name, 'unknown device' without both."""
    kind = device_of(run)
    if not run.device_name:
        return kind or UNKNOWN_DEVICE
    return f"{run.device_name} ({kind.replace(' (CPU)', ', CPU')})" if kind else run.device_name


def device_groups(runs: list[Run]) -> dict[str, list[Run]]:
    """The runs by device_group, in label order: times of two groups are never compared."""
    groups: dict[str, list[Run]] = {}
    for run in runs:
        groups.setdefault(device_group(run), []).append(run)
    return dict(sorted(groups.items()))


def hosts_of(runs: list[Run]) -> list[str]:
    """The nodes the runs ran on, sorted ('' = unknown is left out)."""
    return sorted({r.host for r in runs} - {""})


def nodes_phrase(runs: list[Run], most: int = 6) -> str:
    """'on node01', 'on 3 nodes: a, b, c' (the first `most`, then '…'), '' when unknown."""
    hosts = hosts_of(runs)
    if len(hosts) < 2:
        return f"on {hosts[0]}" if hosts else ""
    shown = ", ".join(hosts[:most]) + (", …" if len(hosts) > most else "")
    return f"on {len(hosts)} nodes: {shown}"


def device_label(runs: list[Run]) -> str:
    """The device every run's time was measured on ('mixed devices: ...' naming each model when
    they differ; 'GPU' when no run says, as the runner times GPU passes)."""
    labels = {device_of(r) for r in runs} - {""}
    if not labels:
        return "GPU"
    models = [g for g in device_groups(runs) if g != UNKNOWN_DEVICE]
    return "mixed devices: " + ", ".join(models) if len(models) > 1 else labels.pop()


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
    mixed = len(device_groups([r for r in runs if r.frame_ms is not None])) > 1
    what = "Timings are" if not mixed else "Some timings (those labelled CPU) are"
    which = "in this report" if not mixed else "of those runs"
    return (f"<b>{what} from lavapipe (CPU)</b>: Vulkan on the llvmpipe CPU rasteriser. "
            f"Every frame and pass time {which} is the time a CPU took to rasterise and "
            "shade, not a GPU time: costs scale with pixels, texels and shader work on a few "
            "CPU cores, so techniques rank differently than they would on a GPU (memory "
            "bandwidth, occupancy and fixed-function hardware are not modelled). Compare times "
            + ("only within this report." if not mixed else "only between runs on one device."))


def device_names(runs: list[Run]) -> str:
    """The device model(s) the runs' times were measured on, named by device.name with their
    kind: 'llvmpipe (LLVM 15.0.6, 256 bits) (lavapipe, CPU)'; several joined by ' and ' (for
    the captions of every table and figure that compares techniques)."""
    timed = [r for r in runs if r.frame_ms is not None] or runs
    return " and ".join(device_groups(timed)) or UNKNOWN_DEVICE
