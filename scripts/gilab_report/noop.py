"""No-op sweeps: a swept parameter that changes nothing on a scene.

Runs of one technique on one scene that differ only in the swept key (one series of the sweep:
the other swept keys fixed) are compared. The key has *no effect on this scene* when, in every
series with at least two runs, the runs' final images are byte-identical (hash of
outputs.final_png, else of outputs.exr) or, when no image can be read, their metric sets
(metrics.final and metrics.final_vs_full) are identical. Frame times are not compared: they
differ by noise alone. Example: shared.area_light_samples on a scene without area lights.
"""
from __future__ import annotations

import hashlib
import json
import os
from typing import Optional

from .analysis import Sweep
from .data import Run, dig

_HASHES: dict[str, Optional[str]] = {}


def file_hash(path: Optional[str]) -> Optional[str]:
    """SHA-1 of a file's bytes (cached), None when it cannot be read."""
    if not path:
        return None
    if path not in _HASHES:
        try:
            with open(path, "rb") as f:
                _HASHES[path] = hashlib.sha1(f.read()).hexdigest()
        except OSError:
            _HASHES[path] = None
    return _HASHES[path]


def output_hash(run: Run) -> Optional[str]:
    for name in ("final_png", "exr"):
        digest = file_hash(run.output_path(name))
        if digest:
            return f"{name}:{digest}"
    return None


def metrics_fingerprint(run: Run) -> Optional[str]:
    metrics = [dig(run.data, "metrics", name) for name in ("final", "final_vs_full")]
    if metrics[0] is None:
        return None
    return json.dumps(metrics, sort_keys=True)


def _identical(runs: list[Run]) -> Optional[str]:
    """How the runs are identical ('output images' / 'metrics'), None when they differ or
    cannot be compared."""
    hashes = [output_hash(r) for r in runs]
    if all(hashes):
        return "output images" if len(set(hashes)) == 1 else None
    prints = [metrics_fingerprint(r) for r in runs]
    if all(prints):
        return "metrics" if len(set(prints)) == 1 else None
    return None


def no_effect(sweep: Sweep) -> Optional[str]:
    """Why the swept key has no effect on the scene (e.g. '4 runs that differ only in it have
    identical output images'), None when it has one or it cannot be told."""
    compared = 0
    how: set[str] = set()
    for members in sweep.series.values():
        measured = [r for r in members if r.measured]
        if len(measured) < 2:
            continue
        same = _identical(measured)
        if same is None:
            return None
        compared += len(measured)
        how.add(same)
    if not compared:
        return None
    what = "output images" if how == {"output images"} else "metrics"
    return f"{compared} runs that differ only in {sweep.key} have identical {what}"


def scene_has_file(path: Optional[str]) -> bool:
    return bool(path) and os.path.isfile(path)
