#!/usr/bin/env python3
"""Prints ssvp's paper-shaped tables (Aranha et al., Table I and the Fig. 6 comparison) from a
results folder:

  Table I   per-stage GPU ms: G-buffer (the shared pass), misc (RSM, first-bounce VPLs, K-means,
            second-bounce VPLs), paraboloid, shade (gathering + blur), total; per cluster count
  error     each run against the two-bounce reference (what ssvp claims; bounces = 1 runs too,
            from metrics.final_vs_bounces), against the reference of the bounces the run claims
            and the full one: relMSE and mean HDR-FLIP, the clamp's removed energy, the K-means
            iterations and whether they converged
  same VPLs the run's last-frame VPLs shaded on the CPU with exact shadow rays and unshadowed
            (metrics.same_vpl, with "same_vpl_reference": true in the config): indirect energy of
            the run and of the unshadowed VPLs over the exact one, relMSE against it
  relative  the paper's own comparison: every run against the C = 32 run with the same other
            parameters (the paper: HDR-VDP-2 RMSE; here relMSE and HDR-FLIP via `gilab compare`)

    python3 techniques/ssvp/ssvp_tables.py results/ssvp_paper [path/to/gilab]

Standard library only; the relative table needs the gilab binary (default build/gilab).
"""
import json
import subprocess
import sys
from pathlib import Path

STAGES = ["gbuffer", "misc", "paraboloid", "shade"]


def stage_ms(result):
    """Median GPU ms per Table I stage (passes summed by their stage prefix)."""
    out = {k: 0.0 for k in STAGES}
    out["direct"] = 0.0
    for p in result.get("timing", {}).get("passes", []):
        name, ms = p["name"], (p.get("gpu_ms") or {}).get("median")
        if ms is None:
            continue
        if name == "gbuffer":
            out["gbuffer"] += ms
        elif name == "direct_light":
            out["direct"] += ms
        elif name.startswith("ssvp/"):
            stage = name[5:].split(".")[0]
            if stage in out:
                out[stage] += ms
    return out


def fmt(v, digits=2):
    return "-" if v is None else f"{v:.{digits}f}"


def metric(r, group, name):
    m = r.get("metrics", {}).get(group, {})
    v = m.get(name)
    return v.get("mean") if isinstance(v, dict) else v


def ladder(r, bounces, name):
    """A metric of the final image against the reference of `bounces` bounces."""
    v = r.get("metrics", {}).get("final_vs_bounces", {}).get(str(bounces), {}).get(name)
    return v.get("mean") if isinstance(v, dict) else v


def per_bounce(rows):
    """Issue 29's per-bounce table, one line per bounces = 2 run that has a bounces = 1 twin."""
    def mean_of(r):
        return r["metrics"]["same_vpl"].get("indirect", {}).get("mean")

    ones = {}
    for r in rows:
        p = r["technique"]["params"]
        if p["bounces"] == 1:
            ones[(r["scene"]["label"], key_without(p, ("bounces",) + SECOND_BOUNCE_ONLY))] = r
    out = []
    for r in rows:
        p = r["technique"]["params"]
        one = ones.get((r["scene"]["label"], key_without(p, ("bounces",) + SECOND_BOUNCE_ONLY)))
        if p["bounces"] != 2 or one is None:
            continue
        lad = r["metrics"].get("final_vs_bounces", {})
        means = [lad.get(str(b), {}).get("reference_mean") for b in (0, 1, 2)]
        by = r["metrics"]["same_vpl"].get("by_bounce", {})
        if None in means or mean_of(r) is None or mean_of(one) is None or not by:
            continue
        r1, r2 = means[1] - means[0], means[2] - means[1]

        def ratio(v, d):
            return None if v is None or not d else v / d
        first = mean_of(one)
        second = mean_of(r) - first
        b1, b2 = by.get("1", {}), by.get("2", {})
        out.append("\t".join([r["scene"]["label"], str(p["clusters"]),
                              str(p["second_bounce_vpls"]), variant(p), fmt(ratio(first, r1), 3),
                              fmt(ratio(b1.get("exact_mean"), r1), 3),
                              fmt(ratio(second, r2), 3), fmt(ratio(b2.get("exact_mean"), r2), 3),
                              fmt(ratio(b2.get("unshadowed_mean"), r2), 3)]))
    return out


def variant(params):
    """The issue-29 options a run sets away from their defaults (\"-\" for none)."""
    tags = []
    if params.get("interleave", 4) != 4:
        tags.append(f"I={params['interleave']}")
    if params.get("interleave_subsets", "blocks") != "blocks":
        tags.append(params["interleave_subsets"])
    if params.get("map_eye", "centroid") != "centroid":
        tags.append(params["map_eye"])
    if params.get("map_members", "keep") != "keep":
        tags.append(params["map_members"])
    if params.get("bounces", 2) == 2 and params.get("second_bounce_visibility", "none") != "none":
        tag = params["second_bounce_visibility"]
        if tag == "own_maps":
            tag += f"(C2={params.get('second_bounce_clusters', 8)})"
        tags.append(tag)
    return ",".join(tags) or "-"


# Parameters a bounces = 1 run does not use: its twin of a two-bounce run may differ in them.
SECOND_BOUNCE_ONLY = ("second_bounce_vpls", "second_bounce_visibility", "second_bounce_clusters")


def key_without(params, drop):
    drop = (drop,) if isinstance(drop, str) else drop
    return tuple(sorted((k, str(v)) for k, v in params.items() if k not in drop))


def relative(rows, folder, gilab):
    """Each run against the C = 32 run of the same scene and other parameters."""
    refs = {}
    for r in rows:
        p = r["technique"]["params"]
        if p["clusters"] == 32:
            refs[(r["scene"]["label"], key_without(p, "clusters"))] = r
    lines = []
    for r in rows:
        p = r["technique"]["params"]
        ref = refs.get((r["scene"]["label"], key_without(p, "clusters")))
        if ref is None or ref is r:
            continue
        a = Path(folder) / "runs" / r["key"] / "output.exr"
        b = Path(folder) / "runs" / ref["key"] / "output.exr"
        try:
            out = subprocess.run([gilab, "compare", f"{a}:final", f"{b}:final", "--json",
                                  "--metrics", "relmse,hdr-flip"],
                                 check=True, capture_output=True, text=True).stdout
            m = json.loads(out)["metrics"]
        except (OSError, subprocess.CalledProcessError, json.JSONDecodeError) as e:
            lines.append(f"{r['scene']['label']}\t{p['clusters']}\t{p['second_bounce_vpls']}\t"
                         f"{p['bounces']}\tcompare failed: {e}")
            continue
        flip = m.get("flip") or {}
        lines.append("\t".join([r["scene"]["label"], str(p["clusters"]),
                                str(p["second_bounce_vpls"]), str(p["bounces"]),
                                fmt(m.get("rel_mse"), 4),
                                fmt(flip.get("mean") if isinstance(flip, dict) else flip, 4)]))
    return lines


def main(folder, gilab):
    rows = []
    for path in sorted((Path(folder) / "runs").glob("*/result.json")):
        r = json.loads(path.read_text())
        if r.get("technique", {}).get("id") == "ssvp" and r.get("status") == "ok":
            rows.append(r)
    if not rows:
        sys.exit(f"{folder}: no finished ssvp runs")
    rows.sort(key=lambda r: (r["scene"]["label"], r["technique"]["params"]["bounces"],
                             r["technique"]["params"]["second_bounce_vpls"],
                             r["technique"]["params"]["clusters"]))
    device = rows[0].get("device", {}).get("name", "?")
    print(f"Table I (median GPU ms per stage; device: {device})")
    print("\t".join(["scene", "C", "N2", "bounces"] + STAGES +
                    ["total", "direct (not in Table I)"]))
    for r in rows:
        p = r["technique"]["params"]
        ms = stage_ms(r)
        total = sum(ms[k] for k in STAGES)
        print("\t".join([r["scene"]["label"], str(p["clusters"]), str(p["second_bounce_vpls"]),
                          str(p["bounces"])] + [fmt(ms[k]) for k in STAGES] +
                         [fmt(total), fmt(ms["direct"])]))
    print("\nTable I as stage shares of the total (lavapipe, not a reproduction; the paper at "
          "C = 8 on a GTX 1060: shade 74 %, paraboloid 17 %)")
    print("\t".join(["scene", "C", "N2"] + [k + "_%" for k in STAGES]))
    for r in rows:
        p = r["technique"]["params"]
        if p["bounces"] != 2 or variant(p) != "-":
            continue
        ms = stage_ms(r)
        total = sum(ms[k] for k in STAGES) or 1.0
        print("\t".join([r["scene"]["label"], str(p["clusters"]), str(p["second_bounce_vpls"])] +
                         [fmt(100.0 * ms[k] / total, 1) for k in STAGES]))
    print("\nError (final image) against the two-bounce reference (every row), the reference of "
          "the bounces the run claims and the full one")
    print("\t".join(["scene", "C", "N2", "bounces", "variant", "relMSE_2b", "HDR-FLIP_2b",
                     "relMSE_claimed", "HDR-FLIP_claimed", "relMSE_full", "HDR-FLIP_full",
                     "energy_ratio", "clamped_%", "kmeans_it", "kmeans_converged", "warmup_run",
                     "valid_vpls", "map_sees_members_%", "shading_map_sees_%"]))
    for r in rows:
        p = r["technique"]["params"]
        s = r.get("stats", {})
        print("\t".join([r["scene"]["label"], str(p["clusters"]), str(p["second_bounce_vpls"]),
                         str(p["bounces"]), variant(p), fmt(ladder(r, 2, "rel_mse"), 4),
                         fmt(ladder(r, 2, "flip"), 4), fmt(metric(r, "final", "rel_mse"), 4),
                         fmt(metric(r, "final", "flip"), 4),
                         fmt(metric(r, "final_vs_full", "rel_mse"), 4),
                         fmt(metric(r, "final_vs_full", "flip"), 4),
                         fmt(r.get("metrics", {}).get("energy_ratio"), 3),
                         fmt(s.get("clamped_energy_percent"), 2), fmt(s.get("kmeans_iterations"), 0),
                         fmt(s.get("kmeans_converged"), 0),
                         fmt(r.get("timing", {}).get("warmup_frames_run"), 0),
                         fmt(s.get("valid_first_bounce_vpls"), 0),
                         fmt(s.get("map_sees_member_flux_percent"), 1),
                         fmt(s.get("shading_map_sees_member_flux_percent"), 1)]))
    same = [r for r in rows if r.get("metrics", {}).get("same_vpl")]
    if same:
        print("\nSame VPLs with exact shadow rays (metrics.same_vpl; indirect layers)")
        print("\t".join(["scene", "C", "N2", "bounces", "variant", "vpls", "energy_vs_exact",
                         "unshadowed_vs_exact", "relMSE_vs_exact", "relMSE_unshadowed"]))
        for r in same:
            p = r["technique"]["params"]
            sv = r["metrics"]["same_vpl"]
            ind = sv.get("indirect", {})
            print("\t".join([r["scene"]["label"], str(p["clusters"]),
                             str(p["second_bounce_vpls"]), str(p["bounces"]), variant(p),
                             fmt(sv.get("vpls"), 0), fmt(ind.get("energy_ratio"), 3),
                             fmt(ind.get("energy_ratio_unshadowed"), 3), fmt(ind.get("rel_mse"), 4),
                             fmt(ind.get("rel_mse_unshadowed"), 4)]))
    bounce_rows = per_bounce(same)
    if bounce_rows:
        print("\nPer bounce, over the path tracer's bounce layer (R1, R2): ssvp, the same VPLs with "
              "shadow rays (exact), and without (unshadowed)")
        print("\t".join(["scene", "C", "N2", "variant", "first_ssvp/R1", "first_exact/R1",
                         "second_ssvp/R2", "second_exact/R2", "second_unshadowed/R2"]))
        for line in bounce_rows:
            print(line)
    lines = relative(rows, folder, gilab)
    if lines:
        print("\nRelative to C = 32 (the paper's Fig. 6 comparison; paper HDR-VDP-2 RMSE: "
              "C = 4 0.1259, 8 0.1020, 16 0.0806)")
        print("\t".join(["scene", "C", "N2", "bounces", "relMSE_vs_C32", "HDR-FLIP_vs_C32"]))
        for line in lines:
            print(line)


if __name__ == "__main__":
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2] if len(sys.argv) == 3 else "build/gilab")
