#!/usr/bin/python3
"""vct's indirect energy per grid resolution, cones against the level-0 control, with the power
counts (issue 43; techniques/vct/README.md "Energy against the grid resolution").

Usage: /usr/bin/python3 techniques/vct/vct_energy_table.py results/vct_resolution_control
(the runs of techniques/vct/configs/vct_resolution_control.json or vct_mip_control.json). Energy = mean of the run's
indirect layer over the reference's bounce-1 mean (metrics.final_vs_bounces 1 minus 0).
"""
import glob
import json
import sys

import OpenImageIO as oiio


def indirect_mean(run_dir):
    image = oiio.ImageBuf(run_dir + "/output.exr")
    pixels = image.get_pixels(oiio.FLOAT)
    channel = image.spec().channelnames.index("indirect.R")
    return float(pixels[:, :, channel:channel + 3].mean())


def main(folder):
    rows = {}
    for path in glob.glob(folder + "/runs/*/result.json"):
        run = json.load(open(path))
        if run.get("status") != "ok" or run["technique"]["id"] != "vct":
            continue
        ladder = run["metrics"]["final_vs_bounces"]
        one = ladder["1"]["reference_mean"] - ladder["0"]["reference_mean"]
        params = run["technique"]["params"]
        control = params.get("control_level0_rays", 0)
        # At aperture 0 the control reads level max(lod_offset - 1, 0) (vct_mip_control.json)
        level = max(int(round(params.get("lod_offset", 0) - 1)), 0)
        series = (f"control {control} rays, level {level}" if control
                  else f"cones, lift {params['lift']}")
        stats = run.get("stats", {})
        energy = indirect_mean(path.rsplit("/", 1)[0]) / one if one > 0 else float("nan")
        rows.setdefault((run["scene"]["label"], series), {})[params["voxel_resolution"]] = (
            energy, stats.get("power_volume_over_photons"), stats.get("power_photons_reflected_w"))
    if not rows:
        sys.exit(f"{folder}: no finished vct runs")
    print("scene\tseries\tenergy per N (64 / 128 / 256)\tmax/min - 1\tvolume/photons power")
    for (scene, series), by_n in sorted(rows.items()):
        ns = sorted(by_n)
        energies = [by_n[n][0] for n in ns]
        spread = max(energies) / min(energies) - 1 if min(energies) > 0 else float("nan")
        power = " / ".join("-" if by_n[n][1] is None else f"{by_n[n][1]:.3f}" for n in ns)
        print(f"{scene}\t{series}\t" + " / ".join(f"{e:.3f}" for e in energies) +
              f"\t{100 * spread:.0f} %\t{power}")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
