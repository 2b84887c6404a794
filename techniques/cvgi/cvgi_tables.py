#!/usr/bin/env python3
"""Prints cvgi's paper-shaped tables (Cosin Ayerbe & Patow 2022, Tables 1-4) from a results
folder: per-pass set-up ms (Table 1), emitter-update ms (Table 2), visibility cost vs rays and the
frame (Table 3), voxel / cluster counts and memory (Table 4), the visibility lists' sampling
(rays per lit entry: 1 = each lit cluster a face lists was found by one ray) and the error, per
gather. Standard library only.

    python3 techniques/cvgi/cvgi_tables.py results/cvgi_paper
"""
import json
import sys
from pathlib import Path

SETUP = ["voxelization", "prefix_sum", "voxel_readback", "heuristic_normal", "clustering",
         "cluster_visibility"]
UPDATE = ["dist_shadow_map", "lit_cluster", "camera_visible_voxel", "light_bounce",
          "gaussian_filtering"]


def pass_ms(result):
    """Set-up pass times in ms by short name (GPU and CPU passes, repeated names summed)."""
    out = {}
    timing = result.get("timing", {})
    for p in timing.get("setup_gpu_passes", []):
        if p["name"].startswith("cvgi/") and p.get("gpu_ms") is not None:
            out[p["name"][5:]] = out.get(p["name"][5:], 0.0) + p["gpu_ms"]
    for p in timing.get("setup_cpu_passes", []):
        if p["name"].startswith("cvgi/") and p.get("cpu_ms") is not None:
            out[p["name"][5:]] = out.get(p["name"][5:], 0.0) + p["cpu_ms"]
    return out


def frame_ms(result):
    for p in result.get("timing", {}).get("passes", []):
        if p["name"] == "cvgi/final_frame":
            return p["gpu_ms"]["median"]
    return None


def key(r):
    p = r["technique"]["params"]
    return [r["scene"]["label"], p.get("gather", "paper"), str(p["voxel_resolution"]),
            str(p["rays_per_face"])]


def fmt(v, digits=1):
    return "-" if v is None else f"{v:.{digits}f}"


def main(folder):
    rows = []
    for path in sorted((Path(folder) / "runs").glob("*/result.json")):
        r = json.loads(path.read_text())
        if r.get("technique", {}).get("id") != "cvgi" or r.get("status") != "ok":
            continue
        rows.append(r)
    if not rows:
        sys.exit(f"{folder}: no finished cvgi runs")
    rows.sort(key=lambda r: (r["scene"]["label"], r["technique"]["params"].get("gather", "paper"),
                             r["technique"]["params"]["voxel_resolution"],
                             r["technique"]["params"]["rays_per_face"]))
    head = ["scene", "gather", "N", "rays"]
    print("Table 1 (set-up, ms; GPU passes timed with timestamps, CPU passes wall time)")
    print("\t".join(head + SETUP + ["final_frame"]))
    for r in rows:
        p = r["technique"]["params"]
        ms = pass_ms(r)
        print("\t".join(key(r) +
                        [fmt(ms.get(k)) for k in SETUP] + [fmt(frame_ms(r), 2)]))
    print("\nTable 2 (first emitter update, ms)")
    print("\t".join(head + UPDATE + ["total"]))
    for r in rows:
        p = r["technique"]["params"]
        ms = pass_ms(r)
        vals = [ms.get(k) for k in UPDATE]
        total = sum(v for v in vals if v is not None)
        print("\t".join(key(r) +
                        [fmt(v) for v in vals] + [fmt(total)]))
    print("\nTable 4 (counts and memory) and error")
    cols = ["voxels", "seeds", "clusters", "cluster_percent", "unassigned_voxels",
            "visibility_entries", "visibility_compacted_percent", "visibility_per_ray_percent",
            "memory_final_mib", "lit_voxels", "lit_clusters", "rays_per_lit_entry"]
    print("\t".join(head + cols + ["peak_mib", "HDR-FLIP_full", "relMSE_1bounce", "energy"]))
    for r in rows:
        p = r["technique"]["params"]
        s = r.get("stats", {})
        peak = r.get("memory", {}).get("peak_bytes")
        m = r.get("metrics", {})
        print("\t".join(key(r) +
                        [fmt(s.get(k), 1) for k in cols] +
                        [fmt(peak / 2**20 if peak else None),
                         fmt((m.get("final_vs_full", {}).get("flip") or {}).get("mean"), 3),
                         fmt(m.get("final", {}).get("rel_mse"), 4),
                         fmt(m.get("energy_ratio"), 3)]))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
