#!/usr/bin/python3
"""Writes a synthetic, schema-faithful gilab results folder for the report's tests.

    /usr/bin/python3 tests/report/make_fixture.py OUTDIR [--no-sweeps]

Contents (schema 1, see scripts/gilab_report/data.py for what the report reads):
  scenes      "cornell_box" (64x64; two metric regions; error bars from the reference's noise)
              and "sponza#sun" (96x64; no regions, no error bars)
  techniques  "direct" (0 bounces, nothing swept), "tech_a" (1-D sweep of cone_count),
              "tech_b" (2-D grid voxel_res x steps)
  failures    one unsupported run (tech_b, voxel_res=256 on sponza#sun), one nonfinite run
              (tech_a, cone_count=16 on sponza#sun, magenta pixels), one invalid run (tech_a,
              cone_count=64 on cornell_box: Vulkan validation messages; its numbers would make it
              the best run and put it on the front if it were ranked), one folder with a
              malformed result.json, one in-progress folder (.tmp-...) the report must ignore
  metrics     final (vs. the bounce-matched reference), final_vs_full, indirect (techniques with
              bounces), regions, energy_ratio; key names as experiments/metrics toJson writes them
  images      tiny PNGs: references/<scene>/<matched>.png ('+' in names), full.png (the full
              reference) and <name>.indirect.png (reference minus emission+direct), and
              final/indirect/flip PNGs per run; on cornell_box also flip_full.png (the FLIP map
              against the full reference, outputs.flip_full_png, as a newer runner would write)
  EXR files   real OpenEXR (fixture_exr.py): each run's output.exr (ZIP, FLOAT layers final,
              indirect, direct and R, G, B) and each reference's <name>.exr (NONE, FLOAT final,
              HALF final_stderr), linear = (the PNG's value)^2.2, the light 12x brighter (HDR),
              NaN where the PNG is magenta; the animated scene's frames have no EXR
  animated    "cornell_box#moving_light" (48x48, a light moving across the box; 9 frames, 5
              measured): tech_a (cone_count 4 and 16, update "incremental"; the 16-cone run's
              temporal instability is within the noise floor) and tech_b (update "full
              rebuild"); dynamic frame, update and update-pass times, metrics.sequence (per-frame
              errors, means, temporal and temporal_matched), frames/NNN.png and temporal.png
              per run, references/<scene>/frames/NNN_full.png
  device      lavapipe (device.type "cpu"), as the project's own results
  no-op sweep direct sweeps shared.area_light_samples (4, 16): it changes cornell_box (area
              light) and nothing on sponza#sun (identical images and metrics)
  two sweeps  direct also sweeps shared.pcf_radius (0, 1) on cornell_box, a separate sweep
              (its runs' technique.swept holds only that key)
  noisy time  frame-time IQR 35 % of the median (tech_a, 2 cones, cornell_box), 20 % (tech_a,
              4 cones: a second noisy tech_a run there), 15 % (tech_b 64 x 8) and 8 % (tech_a,
              8 cones: under the report's 10 % threshold)
  noise floor final_vs_full's HDR-FLIP floor_mean 0.02 on cornell_box (no spread): the
              pcf_radius sweep changes by less, the cone sweep by more
  parameters  tech_b has five; `seed` is not swept but is 1 on its 128 x 16 sponza#sun run
With --no-sweeps: every technique has one run per scene and nothing is swept, and there are no
regions, no error bars, no final_vs_full, no metrics.direct, no full reference or reference
indirect layers (an older runner), no animated scene, placeholder EXR files (magic number only)
and the device is a GPU (for checking that those parts are left out or labelled accordingly).
The numbers are made up but consistent: more cones / voxels / steps = lower error, more time.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import sys
from dataclasses import dataclass, field
from typing import Optional

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import fixture_exr  # noqa: E402

SCENES = {"cornell_box": (64, 64), "sponza#sun": (96, 64)}
# The animated scene (main fixture only): a light moving across a Cornell box.
ANIMATED_SCENE = "cornell_box#moving_light"
ANIMATED_SIZE = (48, 48)
ANIMATION_FRAMES = 9
ANIMATION_DURATION_S = 4.0
MEASURED_FRAMES = [0, 2, 4, 6, 8]
UPDATE_KINDS = {"tech_a": "incremental", "tech_b": "full rebuild"}
MATCHED = {0: "emission+direct", 1: "emission+direct+bounce1",
           2: "emission+direct+bounce1+bounce2"}
SKIPPED = {
    "cornell_box": ["shared/shadow.2d: scene has no spot or directional lights",
                    "shared/shadow.cube: scene has no point lights (or spots with an outer cone "
                    "over 85 deg)"],
    "sponza#sun": ["shared/shadow.cube: scene has no point lights (or spots with an outer cone "
                   "over 85 deg)"],
    ANIMATED_SCENE: ["shared/shadow.2d: scene has no spot or directional lights"],
}
REGIONS = ("ceiling", "indirect_dominant")
# What the runner saves for a run during which the validation layer complained.
INVALID_MESSAGES = [
    "[error] Validation Error: [ VUID-vkCmdDispatch-groupCountX-00386 ] Object 0: handle = "
    "0x55d0c2a1b2c0, name = tech_a/filter, type = VK_OBJECT_TYPE_COMMAND_BUFFER; | "
    "vkCmdDispatch(): groupCountX (104875) exceeds device limit maxComputeWorkGroupCount[0] "
    "(65535). The Vulkan spec states: groupCountX must be less than or equal to "
    "VkPhysicalDeviceLimits::maxComputeWorkGroupCount[0] <script>alert(1)</script>",
    "[warning] Validation Performance Warning: a second, made-up message",
]


@dataclass
class Spec:
    """One run to write."""

    scene: str
    technique: str
    params: dict
    swept: list[str]
    status: str = "ok"
    reason: str = ""
    nan_pixels: int = 0
    index: int = 0
    notes: list[str] = field(default_factory=list)
    validation: list[str] = field(default_factory=list)  # messages; any makes it "invalid"
    shared: dict = field(default_factory=dict)  # swept shared-pass parameters (shared.<name>)
    update: str = ""  # the animated scene's runs: "incremental" / "full rebuild"


def tech_b_params(scene: str, voxel_res: int, steps: int) -> dict:
    """tech_b's five parameters; `seed` is not swept but differs on its best sponza#sun run
    (the card must show it, not hide it behind "+ N more")."""
    seed = 1 if (scene, voxel_res, steps) == ("sponza#sun", 128, 16) else 0
    return {"voxel_res": voxel_res, "steps": steps, "temporal": False, "filter": "tent",
            "seed": seed}


def run_specs(sweeps: bool) -> list[Spec]:
    specs: list[Spec] = []
    cones = [1, 2, 4, 8, 16] if sweeps else [4]
    grid = [(v, s) for v in (32, 64, 128) for s in (8, 16)] if sweeps else [(64, 16)]
    swept_a = ["cone_count"] if sweeps else []
    swept_b = ["voxel_res", "steps"] if sweeps else []
    samples = [4, 16] if sweeps else [16]
    for scene in SCENES:
        for n in samples:  # no effect on sponza#sun (no area light): identical outputs
            specs.append(Spec(scene, "direct", {}, ["shared.area_light_samples"] if sweeps else [],
                              notes=["direct: baseline: indirect layer is zero by construction"],
                              shared={"area_light_samples": n}))
        for radius in ((0, 1) if sweeps and scene == "cornell_box" else ()):
            specs.append(Spec(scene, "direct", {}, ["shared.pcf_radius"],  # a second sweep
                              notes=["direct: baseline: indirect layer is zero by construction"],
                              shared={"pcf_radius": radius}))
        for n in cones:
            bad = sweeps and scene == "sponza#sun" and n == 16
            specs.append(Spec(scene, "tech_a", {"cone_count": n, "max_distance": 1.5}, swept_a,
                              status="nonfinite" if bad else "ok", nan_pixels=37 if bad else 0))
        for v, s in grid:
            specs.append(Spec(scene, "tech_b", tech_b_params(scene, v, s), swept_b))
    specs.append(Spec("sponza#sun", "tech_b", {"voxel_res": 256, "steps": 16, "temporal": False},
                      swept_b, status="unsupported",
                      reason="tech_b: a 256^3 voxel grid needs 2.0 GiB, over the device's "
                             "1.0 GiB allocation limit"))
    specs.append(Spec("cornell_box", "tech_a", {"cone_count": 64, "max_distance": 1.5}, swept_a,
                      status="invalid", validation=INVALID_MESSAGES))
    if sweeps:  # the animated scene: two techniques, one incremental, one full rebuild
        for n in (4, 16):
            specs.append(Spec(ANIMATED_SCENE, "tech_a", {"cone_count": n, "max_distance": 1.5},
                              swept_a, update=UPDATE_KINDS["tech_a"]))
        specs.append(Spec(ANIMATED_SCENE, "tech_b", {"voxel_res": 64, "steps": 16,
                                                     "temporal": False}, swept_b,
                          update=UPDATE_KINDS["tech_b"]))
    for i, spec in enumerate(specs):
        spec.index = i
    return specs


# ---------------------------------------------------------------------------------------------
# Synthetic numbers
# ---------------------------------------------------------------------------------------------

def bounces(tech: str) -> int:
    return {"direct": 0, "tech_a": 1, "tech_b": 1}[tech]


def scene_factor(scene: str) -> float:
    return 1.0 if scene == "cornell_box" else 1.2


def area_lit(scene: str) -> bool:
    """The fixture's cornell_box has an area light (its samples matter), sponza#sun has not."""
    return scene == "cornell_box"


def flip_of(spec: Spec) -> float:
    p = spec.params
    if spec.technique == "direct":  # against the emission+direct reference: small error
        samples = spec.shared.get("area_light_samples", 16)
        base = 0.06 + (0.08 / samples if area_lit(spec.scene) else 0.0)
        if "pcf_radius" in spec.shared:  # softer shadow filtering: a little more error
            base += 0.003 * (1 + spec.shared["pcf_radius"])
    elif spec.technique == "tech_a":
        base = 0.05 + 0.20 / math.sqrt(p["cone_count"])
    else:
        base = 0.04 + 6.0 / p["voxel_res"] + 0.4 / p["steps"]
    return base * scene_factor(spec.scene)


def flip_vs_full(spec: Spec) -> float:
    """Against all the light: the baseline misses every bounce, the others the 2nd and later."""
    missing = 0.30 if bounces(spec.technique) == 0 else 0.03
    return flip_of(spec) + missing * scene_factor(spec.scene)


def flip_vs_bounces(spec: Spec, n: int) -> float:
    """Against the reference with n indirect bounces: each bounce a technique lacks adds error."""
    missing = max(0, n - bounces(spec.technique)) * 0.12 + max(0, bounces(spec.technique) - n) * 0.05
    return flip_of(spec) + missing * scene_factor(spec.scene)


def region_metrics(spec: Spec, flip: float, pixels: int, bars: bool) -> dict:
    entry = {"pixels": pixels, "final": metric_set(flip, pixels, bars)}
    if bounces(spec.technique):
        entry["indirect"] = metric_set(min(1.0, flip * 1.8), pixels, bars)
    return entry


def pass_times(spec: Spec) -> list[tuple[str, float]]:
    k = 1.0 if spec.scene == "cornell_box" else 1.5
    passes = [("gbuffer", 0.4 * k), ("direct_light", 1.2 * k)]
    p = spec.params
    if spec.technique == "tech_a":
        passes += [("tech_a/inject", 0.3 * k), ("tech_a/trace", 0.45 * p["cone_count"] * k)]
    elif spec.technique == "tech_b":
        r = p["voxel_res"] / 64.0
        passes += [("tech_b/voxelize", 1.5 * r ** 3 * k),
                   ("tech_b/march", 0.12 * p["steps"] * r * k)]
    return passes


# Frame-time IQRs set on purpose (fraction of the median): a noisy run, one noisy by a smaller
# margin, and one just under the report's 10 % threshold (not flagged); a second noisy tech_a
# run on cornell_box (the header must tell the two apart).
SPREADS = {("cornell_box", "tech_a", 2): 0.35, ("cornell_box", "tech_b", 64, 8): 0.15,
           ("cornell_box", "tech_a", 8): 0.08, ("cornell_box", "tech_a", 4): 0.2}
# HDR-FLIP of the full reference's own noise on cornell_box (final_vs_full error_bars.flip
# .floor_mean): above the pcf_radius sweep's change (0.003), below the cone sweep's (0.15).
FULL_FLIP_FLOOR = 0.02


def spread(spec: Spec) -> Optional[float]:
    key = (spec.scene, spec.technique) + tuple(
        spec.params[k] for k in ("cone_count", "voxel_res", "steps") if k in spec.params)
    return SPREADS.get(key)


def summary(median: float, rng: np.random.Generator, count: int = 5,
            iqr: Optional[float] = None) -> dict:
    """Five samples around the median; with iqr, quartiles (1 - 0.4 iqr) and (1 + 0.6 iqr) x
    the median (an IQR of iqr x the median)."""
    samples = sorted(median * (1.0 + rng.normal(0.0, 0.04, count)))
    if iqr is not None:
        samples = [median * (1.0 + f * iqr) for f in (-0.8, -0.4, 0.0, 0.6, 1.2)]
    samples[count // 2] = median
    q1, q3 = float(np.percentile(samples, 25)), float(np.percentile(samples, 75))
    return {"median": median, "q1": q1, "q3": q3, "iqr": q3 - q1, "min": min(samples),
            "max": max(samples), "samples": [float(s) for s in rng.permutation(samples)]}


def flip_stats(mean: float, pixels: int, exposures: bool) -> dict:
    stats = {"mean": mean, "weighted_median": mean * 1.6, "weighted_p25": mean * 0.9,
             "weighted_p75": mean * 2.2, "weighted_p95": min(1.0, mean * 3.5), "min": 0.0,
             "max": min(1.0, mean * 6.0), "pixels": pixels}
    if exposures:
        stats.update({"start_exposure": -9.1, "stop_exposure": 2.3, "exposures": 12})
    return stats


def bar(spread: Optional[float], floor: float, value: float, lower_is_better: bool = True
        ) -> dict:
    if spread is None:  # not resampled (e.g. FLIP of final_vs_full)
        return {"spread": None, "floor_mean": None, "floor_spread": None, "within_noise": False}
    within = value <= floor + 2 * spread if lower_is_better else value >= floor - 2 * spread
    return {"spread": spread, "floor_mean": floor, "floor_spread": spread * 0.5,
            "within_noise": within}


def error_bars(flip: float, mse: float, rel_mse: float, psnr_ldr: float, ssim: float,
               within: bool, flip_resampled: bool) -> dict:
    noise_floor = mse / 2.2 if within else mse / 40.0
    flip_spread = 0.004 if flip_resampled else None
    flip_bar = bar(flip_spread, 0.10, flip)
    if not flip_resampled:  # no spread, but the floor of the full reference's noise
        flip_bar["floor_mean"] = FULL_FLIP_FLOOR
    return {"resamples": 8, "mse_noise_floor": noise_floor, "mse_sigma": mse * 0.04,
            "mse_debiased": mse - noise_floor, "rel_mse_noise_floor": rel_mse / 40.0,
            "rel_mse_sigma": rel_mse * 0.05, "rel_mse_debiased": rel_mse * 0.97,
            "psnr_ldr": bar(0.15, 44.0, psnr_ldr, lower_is_better=False),
            "psnr_hdr": bar(0.2, 48.0, psnr_ldr + 4.0, lower_is_better=False),
            "ssim": bar(0.002, 0.995, ssim, lower_is_better=False),
            "flip": flip_bar, "flip_ldr": bar(flip_spread, 0.09, flip * 0.9)}


def metric_set(flip: float, pixels: int, bars: bool, nonfinite: int = 0,
               flip_resampled: bool = True) -> dict:
    """A metric set M as experiments/metrics toJson(MetricSet) writes it (docs/metrics.md)."""
    rel_mse = 2.5 * flip * flip
    psnr_ldr = 12.0 - 20.0 * math.log10(flip)
    ssim = 1.0 - 0.9 * flip
    mse = 0.8 * flip * flip
    within = bars and flip < 0.115
    included = pixels - nonfinite
    return {"pixels": included, "region_pixels": pixels, "test_non_finite": nonfinite,
            "ref_non_finite": 0, "has_non_finite": nonfinite > 0, "mse": mse,
            "rmse": math.sqrt(mse), "rel_mse": rel_mse, "psnr_ldr": psnr_ldr,
            "psnr_hdr": psnr_ldr + 4.0, "psnr_hdr_peak": 12.5, "ssim": ssim,
            "flip": flip_stats(flip, included, True),
            "flip_ldr": flip_stats(flip * 0.9, included, False),
            "error_bars": error_bars(flip, mse, rel_mse, psnr_ldr, ssim, within, flip_resampled)
            if bars else None,
            "within_reference_noise": within}


# ---------------------------------------------------------------------------------------------
# Synthetic images
# ---------------------------------------------------------------------------------------------

def resolution(scene: str) -> tuple[int, int]:
    return ANIMATED_SIZE if scene == ANIMATED_SCENE else SCENES[scene]


def reference_layers(scene: str, t: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """(direct + emission, one bounce of indirect) as display-ready RGB in [0, 1]; t in [0, 1]
    is the animation time (the animated scene's light moves from left to right)."""
    w, h = resolution(scene)
    y, x = np.mgrid[0:h, 0:w] / np.array([h - 1, w - 1])[:, None, None]
    img = np.full((h, w, 3), 0.72)
    if scene == ANIMATED_SCENE:
        img[x < 0.15] = (0.70, 0.12, 0.10)
        img[x > 0.85] = (0.14, 0.55, 0.16)
        lx = 0.25 + 0.5 * t
        shade = 0.25 + 0.75 * np.exp(-((x - lx) ** 2 + (y * 0.6) ** 2) / 0.12)
        direct = img * shade[..., None]
        direct[(y < 0.07) & (np.abs(x - lx) < 0.1)] = (1.0, 0.97, 0.9)
        bleed = np.zeros_like(img)
        bleed[..., 0] += 0.3 * np.exp(-x / 0.2) * (1.2 - lx)
        bleed[..., 1] += 0.3 * np.exp(-(1.0 - x) / 0.2) * (0.2 + lx)
        bleed += 0.1 * y[..., None]
    elif scene == "cornell_box":
        img[x < 0.18] = (0.70, 0.12, 0.10)
        img[x > 0.82] = (0.14, 0.55, 0.16)
        img[(y > 0.3) & (y < 0.8) & (x > 0.3) & (x < 0.55)] = (0.55, 0.55, 0.52)
        shade = 0.35 + 0.65 * (1.0 - y) ** 1.5
        direct = img * shade[..., None]
        direct[(y < 0.06) & (np.abs(x - 0.5) < 0.12)] = (1.0, 0.97, 0.9)
        bleed = np.zeros_like(img)
        bleed[..., 0] += 0.25 * np.exp(-x / 0.25)
        bleed[..., 1] += 0.22 * np.exp(-(1.0 - x) / 0.25)
        bleed += 0.12 * y[..., None]
    else:
        img[y < 0.25] = (0.55, 0.70, 0.95)
        columns = (np.sin(x * 6 * np.pi) > 0.6) & (y > 0.25)
        img[columns] = (0.60, 0.52, 0.40)
        sun = (np.abs((x - y) - 0.1) < 0.18) & (y > 0.25)
        direct = img * np.where(sun, 1.0, 0.25)[..., None]
        bleed = np.zeros_like(img) + np.array([0.18, 0.14, 0.08]) * (y[..., None] > 0.25)
    return np.clip(direct, 0, 1), np.clip(bleed, 0, 1)


def reference_image(scene: str, bounce_count: int, t: float = 0.0) -> np.ndarray:
    direct, indirect = reference_layers(scene, t)
    return np.clip(direct + indirect * min(bounce_count, 1) * (1.0 + 0.25 * (bounce_count - 1)),
                   0, 1)


def technique_images(spec: Spec, flip: float, rng: np.random.Generator, t: float = 0.0
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(final, indirect, FLIP error map in [0, 1]) at animation time t. An incremental update
    lags a little: its indirect light is that of an earlier moment."""
    ref = reference_image(spec.scene, bounces(spec.technique), t)
    direct, _ = reference_layers(spec.scene, t)
    lag = 0.12 if spec.update == "incremental" and spec.params.get("cone_count", 0) < 16 else 0.0
    _, indirect = reference_layers(spec.scene, max(0.0, t - lag))
    if spec.technique == "direct":  # no indirect light; the shared direct pass is a bit dark
        noisy = np.zeros_like(indirect)
        samples = spec.shared.get("area_light_samples", 16)
        direct = direct * (0.94 - (0.2 / samples if area_lit(spec.scene) else 0.0))
        if "pcf_radius" in spec.shared:
            direct = direct * (0.98 - 0.02 * spec.shared["pcf_radius"])
    else:
        noisy = indirect * (1.0 - flip) + rng.normal(0.0, flip * 0.12, indirect.shape)
    if spec.technique == "tech_b":  # blocky, like a coarse voxel grid
        block = max(1, 256 // spec.params["voxel_res"])
        noisy = np.repeat(np.repeat(noisy[::block, ::block], block, 0), block, 1)
        noisy = noisy[:ref.shape[0], :ref.shape[1]]
    final = np.clip(direct + noisy, 0, 1)
    error = np.clip(np.abs(final - ref).mean(axis=2) * 3.0, 0, 1)
    if spec.nan_pixels:
        idx = rng.choice(final.shape[0] * final.shape[1], spec.nan_pixels, replace=False)
        final.reshape(-1, 3)[idx] = (1.0, 0.0, 1.0)
    return final, np.clip(noisy, 0, 1), error


def linear(image: np.ndarray) -> np.ndarray:
    """The linear values behind a display image: value^2.2, the light (near-white pixels) 12x
    brighter than white, NaN where the image is magenta (a non-finite pixel)."""
    out = np.power(np.clip(image, 0.0, 1.0), 2.2).astype(np.float32)
    light = (image.min(axis=2) > 0.88)
    out[light] *= 12.0
    magenta = (image[..., 0] == 1.0) & (image[..., 1] == 0.0) & (image[..., 2] == 1.0)
    out[magenta] = np.nan
    return out


def write_reference_exr(path: str, image: np.ndarray) -> None:
    """A reference's EXR: final (FLOAT) and final_stderr (HALF), uncompressed."""
    lin = linear(image)
    fixture_exr.write_exr(path, {"final": lin, "final_stderr": lin * 0.01},
                          compression=fixture_exr.NONE, half=("final_stderr",))


def write_png(path: str, image: np.ndarray, cmap: Optional[str] = None) -> None:
    os.makedirs(os.path.dirname(path), exist_ok=True)
    if cmap:
        plt.imsave(path, image, cmap=cmap, vmin=0.0, vmax=1.0)
    else:
        plt.imsave(path, image)


# ---------------------------------------------------------------------------------------------
# result.json
# ---------------------------------------------------------------------------------------------

def safe_label(label: str) -> str:
    """The runner's folder name for a scene label (run_store.cpp sanitizeLabel)."""
    return "".join(c if c.isalnum() or c in "-_" else "_" for c in label)


def run_key(spec: Spec) -> str:
    blob = json.dumps([spec.scene, spec.technique, spec.params, spec.shared], sort_keys=True)
    return hashlib.sha1(blob.encode()).hexdigest()[:16]


# The main fixture ran on lavapipe (a CPU device, like the project's own results); the flat one
# on a GPU, so both kinds of time labels are checked.
LAVAPIPE = {"name": "llvmpipe (LLVM 15.0.6, 256 bits)", "type": "cpu", "driver": "llvmpipe",
            "driver_info": "Mesa 22.3.6 (LLVM 15.0.6)", "vulkan_api": "1.3.230"}
GPU = {"name": "Fixture GPU (synthetic)", "type": "discrete", "driver": "fixture",
       "driver_info": "synthetic 1.0", "vulkan_api": "1.3.280"}
EXR_MAGIC = b"v/1\x01"  # the flat fixture's EXR files are placeholders: magic number only


def direct_energy(scene: str) -> float:
    """metrics.direct.energy_ratio of every run of the scene (the report shows it once)."""
    return 0.9987 if area_lit(scene) else 1.0016


def direct_layer_flip(spec: Spec) -> float:
    """The shared direct-light layer against emission+direct: the same for every technique."""
    samples = spec.shared.get("area_light_samples", 16)
    return 0.03 * scene_factor(spec.scene) + (0.08 / samples if area_lit(spec.scene) else 0.0)


def base_result(spec: Spec, key: str, cpu: bool) -> dict:
    w, h = resolution(spec.scene)
    variant = spec.scene.partition("#")[2]
    return {
        "schema": 1, "status": spec.status, "key": key, "index": spec.index,
        "experiment": "fixture",
        "scene": {"label": spec.scene, "path": f"scenes/{spec.scene.partition('#')[0]}.json",
                  "variant": variant, "resolution": [w, h]},
        "technique": {"id": spec.technique, "description": f"synthetic {spec.technique}",
                      "citation": "none (test fixture)",
                      "indirect_bounces": bounces(spec.technique),
                      "params": spec.params,
                      "swept": {k: str(spec.params[k] if k in spec.params else
                                       spec.shared[k.partition(".")[2]]) for k in spec.swept}},
        "shared_params": {"shadows": True, "shadow_resolution": 1024, "area_light_samples": 16,
                          **spec.shared},
        "provenance": {"gilab_version": "0.1.0",
                       "git_commit": "a1b2c3d4e5f6" if spec.index < 12 else "0f9e8d7c6b5a",
                       "build_type": "Release", "compiler": "GNU 12.2.0",
                       "date": f"2026-11-{20 + spec.index // 12:02d}T10:{spec.index % 60:02d}:00Z",
                       "host": "fixture-host", "cpu": "Synthetic CPU", "hardware_threads": 2,
                       "command_line": "gilab run experiments/configs/fixture.json"},
        "device": dict(LAVAPIPE if cpu else GPU),
        "skipped_passes": SKIPPED[spec.scene] + (["tech_b/temporal: temporal=false"]
                                                 if spec.technique == "tech_b" else []),
        "notes": spec.notes,
    }


def timing_json(spec: Spec, rng: np.random.Generator) -> dict:
    passes = pass_times(spec)
    gpu = sum(v for _, v in passes)
    tech_setup = {"direct": 0.004, "tech_a": 3.2,
                  "tech_b": 0.05 * spec.params.get("voxel_res", 0)}[spec.technique]
    setup = {"scene_upload": 0.55 if spec.scene == "cornell_box" else 14.0,
             "shared_passes": 50.9, "shadow_maps": 108.6, "technique": tech_setup}
    setup["total"] = sum(setup.values()) + 0.1
    timing = {"policy": "docs/timing.md: warm-up discarded; median and IQR over timed frames",
              "setup_ms": setup, "setup_gpu_passes": [{"name": "shadow_maps", "gpu_ms": 108.2}],
              "warmup_frames": 2, "timed_frames": 5,
              "frame_cpu_ms": summary(gpu + 0.3, rng),
              "frame_gpu_ms": summary(gpu, rng, iqr=spread(spec)),
              "passes": [{"name": n, "gpu_ms": summary(v, rng),
                          "cpu_record_ms": summary(0.01, rng)} for n, v in passes]}
    if spec.update:  # an animated scene: the frame after the light moved, update included
        update = update_passes(spec)
        cost = sum(v for _, v in update)
        timing.update({
            "dynamic_frame_cpu_ms": summary(gpu + cost + 0.5, rng),
            "dynamic_frame_gpu_ms": summary(gpu + cost, rng),
            "update_cpu_ms": summary(cost + 0.2, rng),
            "update_passes": [{"name": n, "gpu_ms": summary(v, rng)} for n, v in update]})
    return timing


def update_passes(spec: Spec) -> list[tuple[str, float]]:
    """What a moved light costs: the shadow maps always; an incremental technique re-injects
    and propagates, a full rebuild voxelizes the whole scene again."""
    passes = [("shadow_maps", 2.4)]
    if spec.technique == "tech_a":
        passes += [("tech_a/inject", 0.35), ("tech_a/propagate", 0.05 * spec.params["cone_count"])]
    elif spec.technique == "tech_b":
        r = spec.params["voxel_res"] / 64.0
        passes += [("tech_b/clear", 0.2 * r ** 3), ("tech_b/voxelize", 1.5 * r ** 3 * 4.0)]
    return passes


def memory_json(spec: Spec) -> dict:
    owners = {"scene": 3136 if spec.scene == "cornell_box" else 2_621_440, "shared": 27_333_120}
    if spec.technique == "tech_a":
        owners["tech_a"] = 1_048_576 * spec.params["cone_count"]
    elif spec.technique == "tech_b":
        owners["tech_b"] = 8 * spec.params["voxel_res"] ** 3
    total = sum(owners.values())
    return {"total_bytes": total, "peak_bytes": total + 262_144, "by_owner": owners,
            "by_resource": {f"{k}/all": v for k, v in owners.items()}}


def validation_json(messages: list[str]) -> dict:
    """The runner's "validation" block: counts by severity and the messages."""
    errors = sum(1 for m in messages if m.startswith("[error]"))
    return {"enabled": True, "errors": errors, "warnings": len(messages) - errors,
            "messages": messages}


def write_run(root: str, spec: Spec, sweeps: bool, rng: np.random.Generator) -> None:
    key = run_key(spec)
    folder = os.path.join(root, "runs", key)
    os.makedirs(folder, exist_ok=True)
    result = base_result(spec, key, cpu=sweeps)
    if spec.status == "unsupported":
        result["reason"] = spec.reason
    else:
        matched = MATCHED[bounces(spec.technique)]
        flip = flip_of(spec)
        w, h = resolution(spec.scene)
        bars = sweeps and spec.scene == "cornell_box"
        final, indirect, error = technique_images(spec, flip, rng)
        write_png(os.path.join(folder, "final.png"), final)
        write_png(os.path.join(folder, "indirect.png"), indirect)
        write_png(os.path.join(folder, "flip.png"), error, cmap="magma")
        if sweeps and spec.scene == "cornell_box":  # a newer runner's map vs the full reference
            full = reference_image(spec.scene, FULL_BOUNCES)
            write_png(os.path.join(folder, "flip_full.png"),
                      np.clip(np.abs(final - full).mean(axis=2) * 3.0, 0, 1), cmap="magma")
        metrics = {"final": metric_set(flip, w * h, bars, spec.nan_pixels)}
        if sweeps:  # the runner writes it; the flat fixture checks the report without it
            metrics["final_vs_full"] = metric_set(flip_vs_full(spec), w * h, bars,
                                                  spec.nan_pixels, flip_resampled=False)
            # against the 0/1/2-bounce references: the baseline misses bounce 1 against "1"
            metrics["final_vs_bounces"] = {
                str(n): metric_set(flip_vs_bounces(spec, n), w * h, bars, spec.nan_pixels,
                                   flip_resampled=False) for n in (0, 1, 2)}
        if bounces(spec.technique):
            metrics["indirect"] = metric_set(min(1.0, flip * 1.8), w * h, bars, spec.nan_pixels)
        if sweeps:  # newer runners: the direct-light layer vs. emission+direct
            metrics["direct"] = metric_set(direct_layer_flip(spec), w * h, bars)
            # issue 27's direct-light accuracy: the same for every technique of a scene
            metrics["direct"]["energy_ratio"] = direct_energy(spec.scene)
            metrics["direct"]["shadow_leak"] = 0.0025 if area_lit(spec.scene) else 0.0042
        if sweeps and spec.scene == "cornell_box":
            metrics["regions"] = {name: region_metrics(spec, flip * f, w * h // 6, bars)
                                  for name, f in zip(REGIONS, (0.8, 1.4))}
        ratio = {"direct": 0.0, "tech_a": 1.0 - 0.8 * flip, "tech_b": 1.0 - 0.5 * flip}
        metrics["energy_ratio"] = ratio[spec.technique]
        label = safe_label(spec.scene)
        reference = {"key": hashlib.sha1((label + matched).encode()).hexdigest()[:16],
                     "samples": 256, "rel_error": 0.01, "matched": matched,
                     "final_png": f"../../references/{label}/{matched}.png",
                     "final_exr": f"../../references/{label}/{matched}.exr"}
        if sweeps:  # newer runners also record the full reference and the indirect layers
            reference.update({
                "full_png": f"../../references/{label}/{FULL}.png",
                "full_exr": f"../../references/{label}/{FULL}.exr",
                "indirect_png": f"../../references/{label}/{matched}.indirect.png",
                "indirect_full_png": f"../../references/{label}/{FULL}.indirect.png"})
        if sweeps:
            final_lin, indirect_lin = linear(final), linear(indirect)
            fixture_exr.write_exr(os.path.join(folder, "output.exr"), {
                "": final_lin, "final": final_lin, "indirect": indirect_lin,
                "direct": np.maximum(np.nan_to_num(final_lin - indirect_lin), 0.0)})
        else:  # an older runner's folder: a placeholder
            with open(os.path.join(folder, "output.exr"), "wb") as f:
                f.write(EXR_MAGIC)
        outputs = {"exr": "output.exr", "final_png": "final.png",
                   "indirect_png": "indirect.png", "flip_png": "flip.png"}
        if sweeps and spec.scene == "cornell_box":
            outputs["flip_full_png"] = "flip_full.png"
        if spec.update:
            write_animation(folder, spec, rng, metrics, reference, outputs, result)
        result.update({
            "reference": reference,
            "timing": timing_json(spec, rng), "memory": memory_json(spec), "metrics": metrics,
            "nonfinite": {layer: {"nan_pixels": spec.nan_pixels if layer == "final" else 0,
                                  "inf_pixels": 0, "negative_pixels": 0}
                          for layer in ("final", "indirect", "direct")},
            "validation": validation_json(spec.validation),
            "outputs": outputs})
    with open(os.path.join(folder, "result.json"), "w", encoding="utf-8") as f:
        json.dump(result, f, indent=2)


FULL = "full"
FULL_BOUNCES = 3  # the fixture's "all light paths"


def frame_time(index: int) -> float:
    """Animation time (s) of frame `index` (frames evenly spaced over the duration)."""
    return ANIMATION_DURATION_S * index / (ANIMATION_FRAMES - 1)


def temporal_json(instability: float, floor: float, p95: float, pixels: int) -> dict:
    """A temporal-instability block as toJson(TemporalResult) writes it (docs/metrics.md)."""
    n = len(MEASURED_FRAMES)
    level = 0.31
    return {"frames": n, "pairs": n - 1, "region_pixels": pixels, "samples": pixels * (n - 1),
            "skipped_pixels": 0, "level": level, "mean_abs": instability * level,
            "temporal_instability": instability, "p95": p95, "noise_floor": floor,
            "debiased": max(0.0, instability - floor), "note": ""}


def write_animation(folder: str, spec: Spec, rng: np.random.Generator, metrics: dict,
                    reference: dict, outputs: dict, result: dict) -> None:
    """What an animated scene's run adds: the animation block, the measured frames (PNGs and
    per-frame errors), their means and the temporal instability. tech_a with 4 cones lags
    behind the light (error grows, unstable); with 16 cones it is within the noise floor;
    tech_b rebuilds everything every frame (stable, costly)."""
    w, h = resolution(spec.scene)
    label = safe_label(spec.scene)
    frames, names = [], []
    for index in MEASURED_FRAMES:
        t = index / (ANIMATION_FRAMES - 1)
        drift = 0.04 * t if spec.update == "incremental" and spec.params["cone_count"] < 16             else 0.005 * math.sin(3.0 * t)
        flip_full = flip_vs_full(spec) + drift
        flip_matched = flip_of(spec) + drift
        final, _, _ = technique_images(spec, flip_of(spec), rng, t)
        name = f"frames/{index:03d}.png"
        write_png(os.path.join(folder, name), final)
        names.append(name)
        frames.append({"frame": index, "time_s": frame_time(index),
                       "final_vs_full": metric_set(flip_full, w * h, False, flip_resampled=False),
                       "final": metric_set(flip_matched, w * h, False)})
    temporal_map = np.clip(np.abs(rng.normal(0.0, 0.15, (h, w))) +
                           (0.3 if spec.params.get("cone_count") == 4 else 0.0), 0, 1)
    write_png(os.path.join(folder, "temporal.png"), temporal_map, cmap="magma")
    instability = {("tech_a", 4): (0.034, 0.004, 0.12), ("tech_a", 16): (0.0036, 0.004, 0.011),
                   ("tech_b", None): (0.015, 0.004, 0.05)}[
        (spec.technique, spec.params.get("cone_count"))]
    matched = (instability[0] * 0.8, instability[1], instability[2] * 0.9)
    metrics["sequence"] = {
        "frames": frames,
        "full_flip_mean": sum(f["final_vs_full"]["flip"]["mean"] for f in frames) / len(frames),
        "full_rel_mse_mean": sum(f["final_vs_full"]["rel_mse"] for f in frames) / len(frames),
        "matched_flip_mean": sum(f["final"]["flip"]["mean"] for f in frames) / len(frames),
        "temporal": temporal_json(*instability, w * h),
        "temporal_matched": temporal_json(*matched, w * h)}
    result["animation"] = {"frames": ANIMATION_FRAMES, "duration_s": ANIMATION_DURATION_S,
                           "measured_frames": list(MEASURED_FRAMES), "update": spec.update}
    outputs.update({"frames_png": names, "temporal_png": "temporal.png"})
    reference["frames_png"] = [f"../../references/{label}/frames/{i:03d}_full.png"
                               for i in MEASURED_FRAMES]


def write_animated_references(root: str) -> None:
    """The animated scene's references: frame 0's (as a static scene's) and every measured
    frame's full reference."""
    folder = os.path.join(root, "references", safe_label(ANIMATED_SCENE))
    direct = reference_image(ANIMATED_SCENE, 0)
    for count, name in list(MATCHED.items()) + [(FULL_BOUNCES, FULL)]:
        image = reference_image(ANIMATED_SCENE, count)
        write_png(os.path.join(folder, f"{name}.png"), image)
        write_reference_exr(os.path.join(folder, f"{name}.exr"), image)
        write_png(os.path.join(folder, f"{name}.indirect.png"), np.clip(image - direct, 0, 1))
    for index in MEASURED_FRAMES:
        image = reference_image(ANIMATED_SCENE, FULL_BOUNCES, index / (ANIMATION_FRAMES - 1))
        write_png(os.path.join(folder, "frames", f"{index:03d}_full.png"), image)


def write_references(root: str, sweeps: bool) -> None:
    """The bounce-matched references; with sweeps also the full one and the indirect layers
    (reference minus emission+direct)."""
    for scene in SCENES:
        folder = os.path.join(root, "references", safe_label(scene))
        direct = reference_image(scene, 0)
        layers = dict(MATCHED.items())
        if sweeps:
            layers[FULL_BOUNCES] = FULL
        for count, name in layers.items():
            image = reference_image(scene, count)
            write_png(os.path.join(folder, f"{name}.png"), image)
            if sweeps:
                write_reference_exr(os.path.join(folder, f"{name}.exr"), image)
            else:
                with open(os.path.join(folder, f"{name}.exr"), "wb") as f:
                    f.write(EXR_MAGIC)
            if sweeps:
                write_png(os.path.join(folder, f"{name}.indirect.png"),
                          np.clip(image - direct, 0, 1))


def write_extras(root: str, specs: list[Spec], sweeps: bool) -> None:
    """experiment.json, a malformed run folder and an in-progress one. The flat fixture's
    timer overhead is smaller than its IQR (the report must not quote it as a number)."""
    experiment = {"name": "fixture", "description": "Synthetic results for the report's tests: "
                  "two scenes, a baseline and two fake techniques.",
                  "config_path": "experiments/configs/fixture.json",
                  "config_hash": "5eed5eed5eed5eed5eed5eed5eed5eed",
                  "config": {"name": "fixture", "scenes": list(SCENES)},
                  "runs_total": len(specs) + 1, "gilab_version": "0.1.0",
                  "git_commit": "0f9e8d7c6b5a",
                  "device": {"name": "Fixture GPU (synthetic)", "driver": "fixture"},
                  "instrumentation": {"technique": "direct", "scene": "cornell_box",
                                      "frames_each": 8, "frame_cpu_ms_with_timestamps": 1.93,
                                      "frame_cpu_ms_without_timestamps": 1.88,
                                      "overhead_ms": 0.05 if sweeps else 0.01,
                                      "overhead_iqr_ms": 0.02}}
    with open(os.path.join(root, "experiment.json"), "w", encoding="utf-8") as f:
        json.dump(experiment, f, indent=2)
    broken = os.path.join(root, "runs", "0badc0ffee0badc0")
    os.makedirs(broken, exist_ok=True)
    with open(os.path.join(broken, "result.json"), "w", encoding="utf-8") as f:
        f.write('{"schema": 1, "status": "ok", "key": "0badc0ffee0badc0", "metrics": {')
    partial = os.path.join(root, "runs", ".tmp-feedfacefeedface-4242")
    os.makedirs(partial, exist_ok=True)
    with open(os.path.join(partial, "result.json"), "w", encoding="utf-8") as f:
        json.dump({"schema": 1, "status": "ok", "key": "feedfacefeedface"}, f)


def write_fixture(root: str, sweeps: bool = True) -> list[Spec]:
    """Writes the folder; returns the runs written (not counting the malformed/partial ones)."""
    rng = np.random.default_rng(7)
    specs = run_specs(sweeps)
    os.makedirs(os.path.join(root, "runs"), exist_ok=True)
    write_references(root, sweeps)
    if any(spec.update for spec in specs):
        write_animated_references(root)
    for spec in specs:
        write_run(root, spec, sweeps, rng)
    write_extras(root, specs, sweeps)
    return specs


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description="Writes a synthetic gilab results folder.")
    parser.add_argument("out", metavar="OUTDIR")
    parser.add_argument("--no-sweeps", action="store_true",
                        help="no sweeps, no regions, no error bars")
    args = parser.parse_args(argv)
    specs = write_fixture(args.out, sweeps=not args.no_sweeps)
    print(f"{args.out}: {len(specs)} runs")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
