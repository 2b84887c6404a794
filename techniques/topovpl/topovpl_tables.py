#!/usr/bin/env python3
"""Prints topovpl's paper-shaped tables (Noel & Biri 2014, Tables I and II) from a results folder:

  Table I    median GPU ms per pass as the paper splits them: GP (the shared G-buffer + the
             visibility-cluster channel), IUGC, LA, IL, their total; then what the paper leaves
             out of its total (RSM + VPLs + their clusters, direct light)
  set-up     the topology's CPU steps (voxelization, distance transform, thinning, segmentation,
             clustering, nearest node) in ms; a run that read the topology from the cache has none
  Table II   MSE against the same VPLs shaded with exact Embree shadow rays (metrics.same_vpl,
             experiments/runner/same_vpl.h): direct light only, the VPLs unshadowed, the method;
             on 8-bit sRGB (0-255, the paper's probable scale) and on linear HDR; with each
             view's unshadowed / exact energy ratio (does visibility matter there?)
  variants   per view, every topology variant (issue 30: cluster_rule, ball_metric,
             coverage_split, skeleton_filter, gates): clusters, gates, the largest node's share
             of the skeleton, the kept energy (method / exact indirect), the same-cluster share
             of the unshadowed light, MSE (8-bit) and method / unshadowed MSE
  verdicts   per view: which of direct only, unshadowed and the method is closest to the exact
             image, for the default settings and for the best variant
  ground     each run's final image against the path tracer: relMSE and HDR-FLIP against the
  truth      one-bounce reference (what topovpl claims) and the full one, the energy ratio, the
             clamp's share, the light-assignment entries and overflow

    python3 techniques/topovpl/topovpl_tables.py results/topovpl_paper

Standard library only. Runs of other techniques (direct, ssvp) are listed in Table II and the
ground-truth table when they have the numbers.
"""
import json
import sys
from pathlib import Path

# The shipped defaults of the parameters a variant may change (topovpl_settings.cpp).
DEFAULTS = {"visibility": "gates", "cluster_merge": "visible", "gate_placement": "bottleneck",
            "gate_radius": "neck", "gate_radius_scale": 1.0, "merge_visibility": 1.0,
            "cluster_rule": "chained", "ball_metric": "euclidean", "coverage_split": "first",
            "skeleton_filter": "lifespan"}

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
    for k, default in DEFAULTS.items():
        if k in p and p[k] != default:
            parts.append(f"{k}={p[k]}")
    return "topovpl " + " ".join(parts)


def variant(r):
    """The topology and gate choices of a run (its VPL count left out)."""
    return label(r).replace(f"vpls={r['technique']['params'].get('vpls')}", "").strip()


def pass_spread(r, name):
    """(median, q1, q3) GPU ms of one pass."""
    for p in r.get("timing", {}).get("passes", []):
        if p["name"] == name:
            g = p.get("gpu_ms") or {}
            return g.get("median"), g.get("q1"), g.get("q3")
    return None, None, None


def table_ii(r):
    sv = r.get("metrics", {}).get("same_vpl")
    return (sv["table_ii"], sv.get("indirect", {})) if sv else (None, None)


def print_variants(topo, defaults):
    print("\nVariants (1024 VPLs): topology and kept light per view; default settings marked *")
    print("\t".join(["scene", "variant", "clusters", "gates", "largest_node_%", "kept_energy",
                     "same_cluster_%", "method_mse", "unshadowed_mse", "method/unshadowed"]))
    for r in topo:
        if r["technique"]["params"].get("vpls") != 1024:
            continue
        t, ind = table_ii(r)
        if not t:
            continue
        s = r.get("stats", {})
        m, u = t["method"]["mse_8bit"], t["unshadowed"]["mse_8bit"]
        mark = " *" if defaults(r) else ""
        print("\t".join([r["scene"]["label"], (variant(r) or "(default)") + mark,
                         fmt(s.get("visibility_clusters"), 0), fmt(s.get("gates"), 0),
                         fmt(s.get("largest_node_skeleton_percent"), 2),
                         fmt(ind.get("energy_ratio"), 3),
                         fmt(s.get("same_cluster_unshadowed_percent"), 1), fmt(m, 1), fmt(u, 1),
                         fmt(m / u if u else None, 2)]))


def print_verdicts(topo, defaults):
    print("\nVerdicts per view (8-bit MSE vs the same VPLs with shadow rays; visibility matters "
          "where unshadowed / exact energy is well above 1)")
    print("\t".join(["scene", "unshadowed/exact", "direct_only", "unshadowed", "default",
                     "default/unshadowed", "best_variant", "best", "closest (default)"]))
    views = sorted({r["scene"]["label"] for r in topo})
    for v in views:
        runs = [r for r in topo if r["scene"]["label"] == v and table_ii(r)[0] and
                r["technique"]["params"].get("vpls") == 1024 and
                r["technique"]["params"].get("visibility", "gates") == "gates"]
        if not runs:
            continue
        dflt = [r for r in runs if defaults(r)]
        ref = (dflt or runs)[0]
        t, ind = table_ii(ref)
        d, u = t["direct_only"]["mse_8bit"], t["unshadowed"]["mse_8bit"]
        best = min(runs, key=lambda r: table_ii(r)[0]["method"]["mse_8bit"])
        bm = table_ii(best)[0]["method"]["mse_8bit"]
        m = t["method"]["mse_8bit"] if dflt else None
        options = {"direct only": d, "unshadowed": u}
        if m is not None:
            options["method"] = m
        print("\t".join([v, fmt(ind.get("energy_ratio_unshadowed"), 2), fmt(d, 1), fmt(u, 1),
                         fmt(m, 1), fmt(m / u if (m is not None and u) else None, 2),
                         variant(best) or "(default)", fmt(bm, 1),
                         min(options, key=options.get)]))


def is_default(r):
    """Every topology and gate parameter at its default (the run's params hold all of them)."""
    p = r["technique"]["params"]
    return all(p.get(k, v) == v for k, v in DEFAULTS.items())


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
    print(f"Table I (median GPU ms; device: {device}; {res[0]}x{res[1]}; GP with its "
          "interquartile range over the timed frames)")
    print("\t".join(["scene", "run", "GP", "GP_q1-q3", "IUGC", "LA", "IL", "total", "RSM+VPLs",
                     "direct", "geometry_clusters", "la_entries"]))
    for r in topo:
        ms = passes(r)
        gp = ms.get("gbuffer", 0.0) + ms.get("topovpl/gp.clusters", 0.0)
        g = [pass_spread(r, "gbuffer"), pass_spread(r, "topovpl/gp.clusters")]
        spread = "-"
        if all(x[1] is not None for x in g):
            spread = f"{g[0][1] + g[1][1]:.2f}-{g[0][2] + g[1][2]:.2f}"
        iugc, la, il = (ms.get("topovpl/" + k, 0.0) for k in ("iugc", "la", "il"))
        misc = sum(v for k, v in ms.items() if k.startswith("topovpl/misc."))
        s = r.get("stats", {})
        print("\t".join([r["scene"]["label"], label(r), fmt(gp), spread, fmt(iugc), fmt(la),
                         fmt(il), fmt(gp + iugc + la + il), fmt(misc),
                         fmt(ms.get("direct_light")), fmt(s.get("geometry_clusters"), 0),
                         fmt(s.get("la_entries"), 0)]))
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
                     "unshadowed/exact"]))
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
    print_variants(topo, is_default)
    print_verdicts(topo, is_default)
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
