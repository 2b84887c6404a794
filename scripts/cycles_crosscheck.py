#!/usr/bin/python3
"""Analysis half of scripts/cycles_crosscheck.sh: time to a relative MSE of 1e-3, gilab's
reference path tracer against Blender Cycles, from seed pairs rendered in interleaved rounds.

For each renderer and round, two renders x1, x2 of n samples with different seeds give the
relative MSE of ONE sample (its variance, weighted as gilab's relMSE):

    a = n * mean over pixels and RGB of (x1 - x2)^2 / (y^2 + 1e-2) / 2

No converged image enters a, so neither renderer's bias does. The weight's y must not depend
on x1, x2 (their own mean correlates with their difference and biases a low: measured -16 % at
256 spp on the Cornell box, docs/reference.md): it is the sample-weighted mean of every OTHER
render of both renderers. Then spp to 1e-3 = a / 1e-3 and time to 1e-3 = spp x s/spp, with
s/spp the marginal cost of a sample: (t(n) - t(1)) / (n - 1), t(1) from a 1-sample render of the
round (it removes set-up both renderers repeat per render: Cycles' scene sync and BVH build,
file writes). The same with CPU time (every thread). The ratio gilab / Cycles is taken per round
(the machine's speed drifts between rounds; the renderers of one round ran interleaved).

With --ladder (issue 49) nothing is extrapolated: each renderer renders seed pairs on a ladder
of sample counts until one reaches relMSE 1e-3; the count where it is reached is interpolated
between the two rungs that bracket it (samples_to_target); then both render seed pairs at their
count in interleaved rounds, and the relMSE, the marginal cost and the time to 1e-3 are measured
there (analyse_final). The old extrapolation from the first rung is reported beside it.

usage: cycles_crosscheck.py OUT_DIR   (reads OUT_DIR/runs.json written by the shell script)
       cycles_crosscheck.py --ladder-status OUT_DIR   (between rungs: which ladders are done)
Writes OUT_DIR/crosscheck.json and OUT_DIR/crosscheck.md.
"""
import json
import os
import sys

import numpy as np

EPS, TARGET = 1e-2, 1e-3
LUM = np.array([0.2126, 0.7152, 0.0722])


def read_rgb(path, layer=None):
    """RGB (or layer.RGB) of an EXR as float64 (h, w, 3), via the OpenImageIO module."""
    import OpenImageIO as oiio
    inp = oiio.ImageInput.open(path)
    if inp is None:
        sys.exit(f"cycles_crosscheck: cannot read {path}: {oiio.geterror()}")
    spec, px = inp.spec(), inp.read_image("float")
    inp.close()
    names = [f"{layer}.{c}" if layer else c for c in "RGB"]
    missing = [n for n in names if n not in spec.channelnames]
    if missing:
        sys.exit(f"cycles_crosscheck: {path} has no channels {missing}")
    return np.stack([px[..., spec.channelnames.index(n)] for n in names], -1).astype(float)


def load_render(out, run):
    """A run of runs.json: its image and timing sidecar."""
    if run["renderer"] == "gilab":
        info = json.load(open(os.path.join(out, run["path"], "reference.json")))
        image = read_rgb(os.path.join(out, run["path"], "reference.exr"), "full")
    else:
        info = json.load(open(os.path.join(out, run["path"] + ".json")))
        image = read_rgb(os.path.join(out, run["path"] + ".exr"))
    cpu = info.get("cpu_seconds")  # absent from gilab binaries before 2026-12-03: CPU n/a
    return {**run, "seconds": float(info["seconds"]),
            "cpu_seconds": float(cpu) if cpu is not None else float("nan"), "image": image,
            "info": info}


def weighted_mean(renders):
    total = sum(r["spp"] for r in renders)
    return sum(r["image"] * r["spp"] for r in renders) / total


def per_sample_mse(x1, x2, n, y):
    """a from a seed pair of n samples each (module docstring)."""
    return n * float(np.mean((x1 - x2) ** 2 / (y * y + EPS))) / 2.0


def rel_mse_pair(x1, x2, y):
    """The relative MSE of ONE of two independent renders x1, x2 of the same n samples (its
    variance: E[(x1 - x2)^2] / 2), weighted as gilab's relMSE. Measured at n, no 1/n law."""
    return float(np.mean((x1 - x2) ** 2 / (y * y + EPS))) / 2.0


def samples_to_target(rungs, target=TARGET):
    """The sample count whose relMSE is `target`, from a ladder of measured (n, relMSE) rungs:
    interpolated in log-log between the last rung above the target and the first at or below
    it, so between two measured counts and never beyond them. Returns (n, slope) with slope
    = -d log relMSE / d log n of that bracket (1 for a 1/n law), or None while no rung reaches
    the target. A ladder whose first rung already reaches it has no bracket: start it lower."""
    rungs = sorted(rungs)
    for k, (n, e) in enumerate(rungs):
        if e > target:
            continue
        if k == 0:
            raise ValueError(f"the ladder's first rung ({n} spp, relMSE {e:.3g}) is already at "
                             f"or below {target:g}: start it lower")
        (n0, e0), (n1, e1) = rungs[k - 1], (n, e)
        slope = -np.log(e1 / e0) / np.log(n1 / n0)
        if not slope > 0:
            raise ValueError(f"relMSE does not fall between {n0} and {n1} spp "
                             f"({e0:.3g} -> {e1:.3g}): render more seed pairs per rung")
        return float(n0 * (e0 / target) ** (1.0 / slope)), float(slope)
    return None


def ladder_rungs(renders, renderer, stage="ladder"):
    """(n, relMSE) per rung of one renderer's ladder: its seed pairs at each count, weights
    from every render of both renderers outside the pair's rung (as `analyse`)."""
    pairs = [r for r in renders if r.get("stage") == stage and r["spp"] > 1]
    rungs = []
    for n in sorted({r["spp"] for r in pairs if r["renderer"] == renderer}):
        mine = [r for r in pairs if r["renderer"] == renderer and r["spp"] == n]
        if len(mine) % 2:
            sys.exit(f"cycles_crosscheck: {renderer}'s rung {n} spp has {len(mine)} renders, "
                     "not seed pairs")
        others = [r for r in renders if r["spp"] > 1 and r not in mine]
        y = weighted_mean(others) if others else weighted_mean(mine)
        e = [rel_mse_pair(a["image"], b["image"], y) for a, b in zip(mine[::2], mine[1::2])]
        rungs.append((n, float(np.mean(e))))
    return rungs


def analyse_final(renders, target=TARGET):
    """The measurement at the target (issue 49): per renderer, its ladder's count n* (rungs
    bracketing the target) and the seed pairs rendered at n* in interleaved rounds; per round
    the relMSE measured at n*, the marginal s/spp and the time to the target, n* x s/spp scaled
    by the bracket's local law to the measured relMSE (a correction of a few per cent, inside the
    measured range); the ratios gilab / Cycles per round; and, beside them, what the old
    extrapolation (a = n relMSE at n*, times a / target) gives from the same renders."""
    final = [r for r in renders if r.get("stage") == "final"]
    rows = []
    for renderer in ("gilab", "cycles"):
        rungs = ladder_rungs(renders, renderer)
        try:
            found = samples_to_target(rungs, target)
        except ValueError as e:
            sys.exit(f"cycles_crosscheck: {renderer}: {e}")
        if found is None:
            sys.exit(f"cycles_crosscheck: {renderer}'s ladder never reached relMSE {target:g}")
        n_star, slope = found
        # The old method: a = n relMSE(n) at the ladder's first rung, stretched by 1/n
        old_spp = rungs[0][0] * rungs[0][1] / target
        for rnd in sorted({r["round"] for r in final}):
            pair = [r for r in final if r["renderer"] == renderer and r["round"] == rnd
                    and r["spp"] > 1]
            setup = [r for r in final if r["renderer"] == renderer and r["round"] == rnd
                     and r["spp"] == 1]
            if len(pair) != 2 or len(setup) != 1:
                sys.exit(f"cycles_crosscheck: final round {rnd} lacks {renderer}'s seed pair "
                         "or its 1-sample render")
            n = pair[0]["spp"]
            y = weighted_mean([r for r in final if r["spp"] > 1 and r not in pair])
            e = rel_mse_pair(pair[0]["image"], pair[1]["image"], y)
            wall = float(np.mean([(r["seconds"] - setup[0]["seconds"]) / (n - 1) for r in pair]))
            cpu = float(np.mean([(r["cpu_seconds"] - setup[0]["cpu_seconds"]) / (n - 1)
                                 for r in pair]))
            n_target = n * (e / target) ** (1.0 / slope)
            rows.append({"renderer": renderer, "round": rnd, "spp": n, "ladder_spp": n_star,
                         "ladder_slope": slope, "seeds": [r["seed"] for r in pair],
                         "rel_mse": e, "spp_to_target": n_target, "s_per_spp": wall,
                         "cpu_s_per_spp": cpu, "setup_seconds": setup[0]["seconds"],
                         "seconds_to_target": n_target * wall,
                         "cpu_seconds_to_target": n_target * cpu,
                         "extrapolated_spp": old_spp, "extrapolated_seconds": old_spp * wall})
    return (rows, *round_ratios(rows, {"spp": "spp_to_target",
                                       "extrapolated_wall": "extrapolated_seconds"}))


def analyse(renders):
    """Per renderer and round: a, marginal s/spp (wall, CPU) and the time to 1e-3; per round the
    ratios gilab / Cycles; over rounds their spread."""
    pairs = [r for r in renders if r["spp"] > 1]
    rows = []
    for renderer in ("gilab", "cycles"):
        for rnd in sorted({r["round"] for r in pairs}):
            pair = [r for r in pairs if r["renderer"] == renderer and r["round"] == rnd]
            setup = [r for r in renders
                     if r["renderer"] == renderer and r["round"] == rnd and r["spp"] == 1]
            if len(pair) != 2 or len(setup) != 1 or pair[0]["spp"] != pair[1]["spp"]:
                sys.exit(f"cycles_crosscheck: round {rnd} lacks {renderer}'s seed pair or its "
                         "1-sample render")
            n = pair[0]["spp"]
            others = [r for r in pairs if r not in pair]
            y = weighted_mean(others)
            a = per_sample_mse(pair[0]["image"], pair[1]["image"], n, y)
            wall = np.mean([(r["seconds"] - setup[0]["seconds"]) / (n - 1) for r in pair])
            cpu = np.mean([(r["cpu_seconds"] - setup[0]["cpu_seconds"]) / (n - 1) for r in pair])
            rows.append({"renderer": renderer, "round": rnd, "spp": n, "seeds": [r["seed"] for r in pair],
                         "a": a, "s_per_spp": float(wall), "cpu_s_per_spp": float(cpu),
                         "setup_seconds": setup[0]["seconds"],
                         "seconds_to_target": a / TARGET * float(wall),
                         "cpu_seconds_to_target": a / TARGET * float(cpu)})
    return (rows, *round_ratios(rows, {"a": "a"}))


def round_ratios(rows, extra):
    """Per round, gilab / Cycles of the times to the target, the s/spp and the `extra` row
    fields ({ratio name: row key}); over rounds, each ratio's [min, max]."""
    keys = {"wall": "seconds_to_target", "cpu": "cpu_seconds_to_target", **extra,
            "s_per_spp": "s_per_spp"}
    ratios = []
    for rnd in sorted({r["round"] for r in rows}):
        g = next(r for r in rows if r["renderer"] == "gilab" and r["round"] == rnd)
        c = next(r for r in rows if r["renderer"] == "cycles" and r["round"] == rnd)
        ratios.append({"round": rnd, **{name: g[k] / c[k] for name, k in keys.items()}})
    spread = {name: [min(q[name] for q in ratios), max(q[name] for q in ratios)] for name in keys}
    return ratios, spread


def agreement(renders):
    """Every sample of each renderer pooled: mean ratio Cycles / gilab (with one standard error
    from the seed pairs' noise) and their relative MSE beyond both images' expected noise."""
    pooled = {r: [x for x in renders if x["renderer"] == r and x["spp"] > 1]
              for r in ("gilab", "cycles")}
    g, c = weighted_mean(pooled["gilab"]), weighted_mean(pooled["cycles"])
    y = (g + c) / 2
    npx = g.shape[0] * g.shape[1]

    def noise(runs):
        """Per-pixel variance of the pooled mean, from the rounds' seed pairs."""
        var = np.zeros_like(g)
        total = sum(r["spp"] for r in runs)
        for rnd in sorted({r["round"] for r in runs}):
            x1, x2 = [r for r in runs if r["round"] == rnd]
            var += (x1["image"] - x2["image"]) ** 2 / 2 * x1["spp"]  # per-sample variance
        return var / len({r["round"] for r in runs}) / total

    vg, vc = noise(pooled["gilab"]), noise(pooled["cycles"])
    mg, mc = g.mean((0, 1)), c.mean((0, 1))
    sig = np.sqrt(vc.sum((0, 1)) / npx**2 / mc**2 + vg.sum((0, 1)) / npx**2 / mg**2)
    lg, lc = float(mg @ LUM), float(mc @ LUM)
    sig_lum = np.sqrt(float((vc * LUM**2).sum()) / npx**2 / lc**2
                      + float((vg * LUM**2).sum()) / npx**2 / lg**2)
    w = 1.0 / (y * y + EPS)
    rel = float(np.mean((c - g) ** 2 * w))
    expected = float(np.mean((vg + vc) * w))
    flips = {"none": rel, "left-right": float(np.mean((c[:, ::-1] - g) ** 2 * w)),
             "up-down": float(np.mean((c[::-1] - g) ** 2 * w))}
    return {"ratio_cycles_over_gilab": (mc / mg).tolist() + [lc / lg],
            "ratio_sigma": sig.tolist() + [float(sig_lum)],
            "rel_mse": rel, "rel_mse_expected_noise": expected,
            "rel_mse_minus_noise": rel - expected,
            "orientation_rel_mse": flips,
            "orientation_ok": min(flips, key=flips.get) == "none"}


def markdown(meta, rows, ratios, spread, agree):
    lines = [f"# Cycles cross-check: {meta['scene']} ({meta['width']}x{meta['height']}, "
             f"{meta['max_bounces']} bounces, {meta['threads']} threads, "
             f"pixel filter {meta.get('pixel_filter', 'center')})", "",
             f"gilab reference path tracer v{meta['gilab_version']} ({meta['gilab_sampler']} "
             f"sampler) vs Blender {meta['blender_version']} Cycles (CPU, its defaults). "
             f"{len(ratios)} rounds, each: gilab seed 1, Cycles seed 1, gilab seed 2, Cycles seed "
             "2 (then one 1-sample render each, for the set-up time). Machine: "
             f"{meta['machine']}; {meta['date']}.", "",
             "a = n * relMSE(x1, x2) / 2 per seed pair (weights from the other renders); s/spp "
             "= marginal cost of a sample; time to 1e-3 = a / 1e-3 * s/spp.", "",
             "| round | renderer | spp | a | s/spp (wall) | CPU s/spp | set-up s | time to 1e-3 "
             "| CPU time to 1e-3 |",
             "|---:|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in sorted(rows, key=lambda r: (r["round"], r["renderer"] != "gilab")):
        lines.append(f"| {r['round']} | {r['renderer']} | {r['spp']} | {r['a']:.3f} | "
                     f"{r['s_per_spp']:.4f} | {r['cpu_s_per_spp']:.4f} | "
                     f"{r['setup_seconds']:.2f} | {r['seconds_to_target']:.1f} s | "
                     f"{r['cpu_seconds_to_target']:.1f} s |")
    lines += ["", "| round | gilab / Cycles: wall time to 1e-3 | CPU time | a | s/spp |",
              "|---:|---:|---:|---:|---:|"]
    for q in ratios:
        lines.append(f"| {q['round']} | **{q['wall']:.3f}** | **{q['cpu']:.3f}** | "
                     f"{q['a']:.3f} | {q['s_per_spp']:.3f} |")
    lines.append(f"| spread | {spread['wall'][0]:.3f}–{spread['wall'][1]:.3f} | "
                 f"{spread['cpu'][0]:.3f}–{spread['cpu'][1]:.3f} | "
                 f"{spread['a'][0]:.3f}–{spread['a'][1]:.3f} | "
                 f"{spread['s_per_spp'][0]:.3f}–{spread['s_per_spp'][1]:.3f} |")
    ratio = ", ".join(f"{k} {v:.4f} ± {e:.4f}" for k, v, e in
                      zip("RGB", agree["ratio_cycles_over_gilab"], agree["ratio_sigma"]))
    lum = agree["ratio_cycles_over_gilab"][3], agree["ratio_sigma"][3]
    lines += ["", f"Agreement (every sample pooled): mean Cycles / gilab {ratio}, luminance "
              f"{lum[0]:.4f} ± {lum[1]:.4f} (one standard error); relMSE between them "
              f"{agree['rel_mse']:.4g}, of which both images' noise explains "
              f"{agree['rel_mse_expected_noise']:.4g} (excess {agree['rel_mse_minus_noise']:.3g})."
              , "Orientation (relMSE, Cycles flipped): " +
              ", ".join(f"{k} {v:.4g}" for k, v in agree["orientation_rel_mse"].items()) +
              ("" if agree["orientation_ok"] else
               "  ** a flipped image matches better: camera mismatch **")]
    return "\n".join(lines) + "\n"


def markdown_final(meta, ladders, rows, ratios, spread, agree, target=TARGET):
    """crosscheck.md of a ladder run (--ladder): the rungs, the rounds at the target, the ratios
    with the old extrapolation beside them, and the agreement."""
    lines = [f"# Cycles cross-check at relMSE {target:g}: {meta['scene']} ({meta['width']}x"
             f"{meta['height']}, {meta['max_bounces']} bounces, {meta['threads']} threads, "
             f"pixel filter {meta.get('pixel_filter', 'center')})", "",
             f"gilab reference path tracer v{meta['gilab_version']} ({meta['gilab_sampler']} "
             f"sampler) vs Blender {meta['blender_version']} Cycles (CPU, its defaults). "
             f"Machine: {meta['machine']}; {meta['date']}; seeds from {meta.get('seed_base', 1)}.",
             "", "Ladder: relMSE of one render (from seed pairs), per sample count:", ""]
    for renderer, rungs in ladders.items():
        lines.append(f"- {renderer}: " + ", ".join(f"{n} spp {e:.4g}" for n, e in rungs))
    lines += ["", f"{len(ratios)} rounds at the ladder's count, each: gilab pair, Cycles pair, "
              "one 1-sample render each (set-up). Time to the target = spp to the target x the "
              "marginal s/spp; spp to the target = the rendered count scaled by the ladder's "
              "local law to the relMSE measured in the round.", "",
              f"| round | renderer | spp | relMSE measured | spp to {target:g} | s/spp (wall) | "
              f"CPU s/spp | time to {target:g} | old extrapolation |",
              "|---:|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in sorted(rows, key=lambda r: (r["round"], r["renderer"] != "gilab")):
        lines.append(f"| {r['round']} | {r['renderer']} | {r['spp']} | {r['rel_mse']:.4g} | "
                     f"{r['spp_to_target']:.0f} | {r['s_per_spp']:.4f} | "
                     f"{r['cpu_s_per_spp']:.4f} | {r['seconds_to_target']:.1f} s | "
                     f"{r['extrapolated_seconds']:.1f} s ({r['extrapolated_spp']:.0f} spp) |")
    lines += ["", f"| round | gilab / Cycles: wall time to {target:g} | CPU time | spp | s/spp | "
              "old extrapolation (wall) |", "|---:|---:|---:|---:|---:|---:|"]
    for q in ratios:
        lines.append(f"| {q['round']} | **{q['wall']:.3f}** | **{q['cpu']:.3f}** | "
                     f"{q['spp']:.3f} | {q['s_per_spp']:.3f} | {q['extrapolated_wall']:.3f} |")
    lines.append("| spread | " + " | ".join(
        f"{spread[k][0]:.3f}–{spread[k][1]:.3f}"
        for k in ("wall", "cpu", "spp", "s_per_spp", "extrapolated_wall")) + " |")
    lum = agree["ratio_cycles_over_gilab"][3], agree["ratio_sigma"][3]
    lines += ["", f"Agreement (the rounds' samples pooled): mean luminance Cycles / gilab "
              f"{lum[0]:.4f} ± {lum[1]:.4f}; relMSE between them {agree['rel_mse']:.4g}, of "
              f"which noise {agree['rel_mse_expected_noise']:.4g}."]
    return "\n".join(lines) + "\n"


def ladder_status(out):
    """For the shell script between rungs: one line per renderer, `NAME N SLOPE` once its
    ladder brackets the target (N = the count to render), else `NAME -`. Exit 1 when a ladder
    cannot bracket it (its first rung is already below the target)."""
    meta = json.load(open(os.path.join(out, "runs.json")))
    renders = [load_render(out, r) for r in meta["runs"]]
    target = float(meta.get("target", TARGET))
    for renderer in ("gilab", "cycles"):
        try:
            found = samples_to_target(ladder_rungs(renders, renderer), target)
        except ValueError as e:
            sys.exit(f"cycles_crosscheck: {renderer}: {e}")
        print(f"{renderer} -" if found is None else f"{renderer} {found[0]:.1f} {found[1]:.4f}")
    return 0


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--ladder-status":
        return ladder_status(sys.argv[2])
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    meta = json.load(open(os.path.join(out, "runs.json")))
    renders = [load_render(out, r) for r in meta["runs"]]
    gilab_info = next(r["info"] for r in renders if r["renderer"] == "gilab")
    cycles_info = next(r["info"] for r in renders if r["renderer"] == "cycles")
    meta.update({"gilab_version": gilab_info["renderer"]["version"],
                 "gilab_sampler": gilab_info["settings"]["sampler"],
                 "blender_version": cycles_info["blender_version"]})
    if any(r.get("stage") == "final" for r in renders):  # --ladder (issue 49)
        target = float(meta.get("target", TARGET))
        ladders = {k: ladder_rungs(renders, k) for k in ("gilab", "cycles")}
        rows, ratios, spread = analyse_final(renders, target)
        agree = agreement([r for r in renders if r.get("stage") == "final"])
        text = markdown_final(meta, ladders, rows, ratios, spread, agree, target)
        meta["ladders"] = ladders
    else:
        rows, ratios, spread = analyse(renders)
        agree = agreement(renders)
        text = markdown(meta, rows, ratios, spread, agree)
    print(text, end="")
    with open(os.path.join(out, "crosscheck.md"), "w") as f:
        f.write(text)
    result = {k: v for k, v in meta.items() if k != "runs"}
    result.update({"runs": [{k: v for k, v in r.items() if k not in ("image", "info")}
                            for r in renders],
                   "per_round": rows, "ratios": ratios, "spread": spread, "agreement": agree})
    with open(os.path.join(out, "crosscheck.json"), "w") as f:
        json.dump(result, f, indent=2)
    print(f"wrote {out}/crosscheck.json and crosscheck.md")
    return 0 if agree["orientation_ok"] else 1


if __name__ == "__main__":
    sys.exit(main())
