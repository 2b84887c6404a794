#!/usr/bin/env python3
"""Prints topovpl's paper-shaped tables (Noel & Biri 2014, Tables I and II) from a results folder:

  Table I    median GPU ms per pass as the paper splits them: GP (the shared G-buffer + the
             visibility-cluster channel), IUGC, LA, IL, their total; then what the paper leaves
             out of its total (RSM + VPLs + their clusters, direct light)
  set-up     the topology's CPU steps (voxelization, distance transform, thinning, segmentation,
             clustering, nearest node) in ms; a run that read the topology from the cache has none
  Table II   MSE against the same VPLs shaded with exact Embree shadow rays (metrics.same_vpl,
             experiments/runner/same_vpl.h): direct light only, the VPLs unshadowed, the method;
             on 8-bit sRGB (0-255, the paper's probable scale) and on linear HDR
  ground     each run's final image against the path tracer: relMSE and HDR-FLIP against the
  truth      one-bounce reference (what topovpl claims) and the full one, the energy ratio, the
             clamp's share, the light-assignment entries and overflow

    python3 scripts/topovpl_tables.py results/topovpl_paper

Standard library only. Runs of other techniques (direct, ssvp) are listed in Table II and the
ground-truth table when they have the numbers.
"""
import json
import sys
from pathlib import Path

STEPS = ["voxelization", "distance_transform", "thinning", "segmentation", "clustering",
         "nearest_node"]


def fmt(v, digits=2):
    return "-" if v is None else f"{v:.{digits}f}"


def metric(r, group, name):
    v = r.get("metrics", {}).get(group, {}).get(name)
    return v.get("mean") if isinstance(v, dict) else v


def passes(r):
    out = {}
    for p in r.get("timing", {}).get("passes", []):
        ms = (p.get("gpu_ms") or {}).get("median")
        if ms is not None:
            out[p["name"]] = ms
    return out


def label(r):
    p = r["technique"]["params"]
    tid = r["technique"]["id"]
    if tid != "topovpl":
        return tid
    parts = [f"vpls={p.get('vpls')}"]
    for k, default in (("visibility", "gates"), ("cluster_merge", "visible"),
                       ("gate_placement", "bottleneck"), ("gate_radius", "neck"),
                       ("gate_radius_scale", 1.0), ("merge_visibility", 1.0)):
        if k in p and p[k] != default:
            parts.append(f"{k}={p[k]}")
    return "topovpl " + " ".join(parts)


def main(folder):
    rows = []
    for path in sorted((Path(folder) / "runs").glob("*/result.json")):
        r = json.loads(path.read_text())
        if r.get("status") == "ok":
            rows.append(r)
    topo = [r for r in rows if r["technique"]["id"] == "topovpl"]
    if not topo:
        sys.exit(f"{folder}: no finished topovpl runs")
    rows.sort(key=lambda r: (r["scene"]["label"], label(r)))
    topo.sort(key=lambda r: (r["scene"]["label"], label(r)))
    device = topo[0].get("device", {}).get("name", "?")
    res = topo[0]["scene"].get("resolution")
    print(f"Table I (median GPU ms; device: {device}; {res[0]}x{res[1]})")
    print("\t".join(["scene", "run", "GP", "IUGC", "LA", "IL", "total", "RSM+VPLs", "direct",
                     "geometry_clusters", "la_entries"]))
    for r in topo:
        ms = passes(r)
        gp = ms.get("gbuffer", 0.0) + ms.get("topovpl/gp.clusters", 0.0)
        iugc, la, il = (ms.get("topovpl/" + k, 0.0) for k in ("iugc", "la", "il"))
        misc = sum(v for k, v in ms.items() if k.startswith("topovpl/misc."))
        s = r.get("stats", {})
        print("\t".join([r["scene"]["label"], label(r), fmt(gp), fmt(iugc), fmt(la), fmt(il),
                         fmt(gp + iugc + la + il), fmt(misc), fmt(ms.get("direct_light")),
                         fmt(s.get("geometry_clusters"), 0), fmt(s.get("la_entries"), 0)]))
    print("\nSet-up (CPU ms; '-': read from the topology cache)")
    print("\t".join(["scene", "run", "resolution"] + STEPS + ["clusters", "gates"]))
    for r in topo:
        cpu = {p["name"].split("/", 1)[-1]: p["cpu_ms"]
               for p in r.get("timing", {}).get("setup_cpu_passes", [])}
        s = r.get("stats", {})
        print("\t".join([r["scene"]["label"], label(r),
                         str(r["technique"]["params"].get("voxel_resolution"))] +
                        [fmt(cpu.get(k), 0) for k in STEPS] +
                        [fmt(s.get("visibility_clusters"), 0), fmt(s.get("gates"), 0)]))
    print("\nTable II: MSE against the same VPLs with exact shadow rays (8-bit sRGB | linear)")
    print("\t".join(["scene", "run", "direct_only", "unshadowed", "method",
                     "direct_only_lin", "unshadowed_lin", "method_lin", "indirect_energy",
                     "unshadowed_energy"]))
    for r in rows:
        sv = r.get("metrics", {}).get("same_vpl")
        if not sv:
            continue
        t = sv["table_ii"]
        ind = sv.get("indirect", {})
        print("\t".join([r["scene"]["label"], label(r)] +
                        [fmt(t[k]["mse_8bit"], 3) for k in ("direct_only", "unshadowed", "method")] +
                        [f"{t[k]['mse']:.3g}" for k in ("direct_only", "unshadowed", "method")] +
                        [fmt(ind.get("energy_ratio"), 3), fmt(ind.get("energy_ratio_unshadowed"), 3)]))
    print("\nAgainst the path tracer (final image): one-bounce reference | full")
    print("\t".join(["scene", "run", "relMSE_1b", "HDR-FLIP_1b", "relMSE_full", "HDR-FLIP_full",
                     "energy_ratio", "clamped_%", "la_overflow"]))
    for r in rows:
        s = r.get("stats", {})
        print("\t".join([r["scene"]["label"], label(r), fmt(metric(r, "final", "rel_mse"), 4),
                         fmt(metric(r, "final", "flip"), 4),
                         fmt(metric(r, "final_vs_full", "rel_mse"), 4),
                         fmt(metric(r, "final_vs_full", "flip"), 4),
                         fmt(r.get("metrics", {}).get("energy_ratio"), 3),
                         fmt(s.get("clamped_energy_percent"), 2),
                         fmt(s.get("la_overflow_entries"), 0)]))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
