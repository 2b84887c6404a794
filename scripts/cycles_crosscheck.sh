#!/usr/bin/env bash
# Optional cross-check of gilab's Embree path tracer (the reference) against Blender Cycles on
# the Cornell box glTF. Not part of the default install, the build or CI; Blender is installed
# on demand (Debian's `blender` package, 3.4.1 on Debian 12).
#
# Both renderers see the same scene: Lambertian materials from the glTF factors (Cycles'
# materials are rebuilt by scripts/cycles_render.py), gilab's camera, rays through pixel
# centres, 64 bounces, black background. A long gilab run (seed 1) is the converged image y;
# every measured run x with n spp gives
#   relMSE = mean over pixels and RGB of (x - y)^2 / (y^2 + 1e-2)   (gilab's definition)
#   a      = n * (relMSE - noise(y)),  noise(y) from y's own full_stderr layer
# hence the spp (a / 1e-3) and seconds (spp x s/spp) each renderer needs for relMSE 1e-3, and
# the agreement of the two renderers: mean ratio and relMSE beyond the expected noise.
# Writes OUT/crosscheck.{json,md}; the result figures belong in docs/reference.md ("Measured").
#
# usage: scripts/cycles_crosscheck.sh [--resolution N] [--gilab-spp LIST] [--cycles-spp LIST]
#          [--long-spp L] [--threads T] [--out DIR] [--scene-gltf PATH] [--cycles-roulette on|off]
#          [--gilab-sampler independent|sobol]
#   --gilab-sampler: the sampler of gilab's measured runs (the converged run is independent)
#   --cycles-roulette off: no Russian roulette in Cycles (default on, as Cycles ships; gilab's
#     reference thins only paths past bounce 4 whose throughput fell below 0.05)
#   env GILAB: the gilab binary (default build/gilab)
# tiny test: scripts/cycles_crosscheck.sh --resolution 32 --gilab-spp 16,32 --cycles-spp 16,32 \
#              --long-spp 256
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
res=256 gilab_spp=64,256 cycles_spp=64,256,1024 long_spp=4096 threads=2 roulette=on
sampler=independent
out=results/cycles_crosscheck
gltf=$root/../shared/scenes/cornell-box/cornell_box.gltf
gilab=${GILAB:-$root/build/gilab}
py=/usr/bin/python3

die() { echo "cycles_crosscheck: $*" >&2; exit 1; }
usage() { sed -n '16,24p' "$0"; exit "${1:-2}"; }

while [[ $# -gt 0 ]]; do
    [[ $1 == -h || $1 == --help ]] && usage 0
    [[ $# -ge 2 ]] || usage
    case $1 in
        --resolution) res=$2 ;;
        --gilab-spp) gilab_spp=$2 ;;
        --cycles-spp) cycles_spp=$2 ;;
        --long-spp) long_spp=$2 ;;
        --threads) threads=$2 ;;
        --out) out=$2 ;;
        --scene-gltf) gltf=$2 ;;
        --cycles-roulette) roulette=$2 ;;
        --gilab-sampler) sampler=$2 ;;
        *) echo "unknown option $1" >&2; usage ;;
    esac
    shift 2
done
[[ $roulette == on || $roulette == off ]] || die "--cycles-roulette takes on or off"
[[ $sampler == independent || $sampler == sobol ]] ||
    die "--gilab-sampler takes independent or sobol"
min_light_bounces=0
[[ $roulette == on ]] || min_light_bounces=64
for v in "$res" "$long_spp" "$threads" ${gilab_spp//,/ } ${cycles_spp//,/ }; do
    [[ $v =~ ^[1-9][0-9]*$ ]] || die "not a positive integer: $v"
done

[[ -f $gltf ]] || die "scene file not found: $gltf (--scene-gltf; see scenes/README.md)"
[[ -x $gilab ]] || die "gilab binary not found: $gilab (build it, or set GILAB)"
$py -c 'import numpy' 2>/dev/null || die "$py with numpy is needed"
command -v oiiotool >/dev/null || $py -c 'import OpenImageIO' 2>/dev/null ||
    die "oiiotool or the OpenImageIO Python module is needed"

if ! command -v blender >/dev/null; then
    as_root=()
    if [[ $(id -u) != 0 ]]; then
        command -v sudo >/dev/null || die "blender is missing and installing it needs root or sudo"
        as_root=(sudo)
    fi
    echo "cycles_crosscheck: blender not found; installing Debian's blender package:"
    sudo_=${as_root[*]:+sudo }
    echo "  ${sudo_}apt-get update && ${sudo_}apt-get install -y --no-install-recommends blender"
    "${as_root[@]}" apt-get update -q ||
        echo "cycles_crosscheck: apt-get update failed; trying the install anyway"
    "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive \
        apt-get install -y -q --no-install-recommends blender || die "installing blender failed"
    command -v blender >/dev/null || die "blender is still not on PATH"
fi

mkdir -p "$out"
out=$(cd "$out" && pwd)
# One scene description for both renderers: gilab's camera, the glTF given here.
$py - "$root/scenes/cornell_box_gltf.json" "$(realpath "$gltf")" "$res" "$out/scene.json" <<'PY'
import json, sys
src, gltf, res, dst = sys.argv[1:]
camera = json.load(open(src))["camera"]
json.dump({"gltf": gltf, "camera": camera, "resolution": [int(res), int(res)]},
          open(dst, "w"), indent=2)
PY

# gilab uses every CPU it may run on (TBB): pin it to T CPUs when there are more.
pin=()
if [[ $threads -lt $(nproc) ]]; then pin=(taskset -c "0-$((threads - 1))"); fi

gilab_render() {  # spp seed dir sampler
    echo "gilab:  $1 spp (seed $2, $4 sampler) -> $3"
    "${pin[@]}" "$gilab" reference --scene "$out/scene.json" --resolution "${res}x${res}" \
        --max-bounces 64 --pixel-filter center --spp "$1" --seed "$2" --sampler "$4" \
        --no-cache -o "$3" -q >/dev/null || die "gilab reference failed ($3)"
}

cycles_render() {  # spp seed exr
    echo "cycles: $1 spp (seed $2) -> $3"
    blender -b --factory-startup -t "$threads" --python "$root/scripts/cycles_render.py" -- \
        --scene "$out/scene.json" --out "$3" --resolution "$res" --samples "$1" --seed "$2" \
        --threads "$threads" --min-light-bounces "$min_light_bounces" >"${3%.exr}.log" 2>&1 ||
        { tail -n 20 "${3%.exr}.log" >&2; die "blender failed (log: ${3%.exr}.log)"; }
    grep -q '^cycles_render: .* spp in' "${3%.exr}.log" ||
        { tail -n 20 "${3%.exr}.log" >&2; die "cycles_render.py did not finish (${3%.exr}.log)"; }
}

# The converged image uses i.i.d. samples: its stderr layer (its own noise) must be exact
gilab_render "$long_spp" 1 "$out/gilab_long" independent
seed=2
for n in ${gilab_spp//,/ }; do
    gilab_render "$n" $seed "$out/gilab_spp$n" "$sampler"
    seed=$((seed + 1))
done
seed=1
for n in ${cycles_spp//,/ }; do
    cycles_render "$n" $seed "$out/cycles_spp$n.exr"; seed=$((seed + 1))
done

$py - "$out" "$gilab_spp" "$cycles_spp" <<'PY'
import json, os, re, subprocess, sys, tempfile
import numpy as np

out = sys.argv[1]
gilab_spp, cycles_spp = (sorted(set(a.split(",")), key=int) for a in sys.argv[2:4])
EPS, TARGET = 1e-2, 1e-3

def read(path, chans):
    """Channels of an EXR as float64 (h, w, c): the OpenImageIO module, else oiiotool text."""
    try:
        import OpenImageIO as oiio
        inp = oiio.ImageInput.open(path)
        spec, px = inp.spec(), inp.read_image("float")
        inp.close()
        return np.stack([px[..., spec.channelnames.index(c)] for c in chans], -1).astype(float)
    except ImportError:
        with tempfile.TemporaryDirectory() as tmp:
            sub = os.path.join(tmp, "sub.exr")
            subprocess.run(["oiiotool", path, "--ch", ",".join(chans), "-o", sub], check=True)
            txt = subprocess.run(["oiiotool", "--dumpdata", sub], check=True,
                                 capture_output=True, text=True).stdout
        w, h = map(int, re.search(r":\s*(\d+)\s*x\s*(\d+)", txt).groups())
        rows = [l.split(":", 1)[1].split() for l in txt.splitlines()
                if l.lstrip().startswith("Pixel (")]
        return np.array(rows, float).reshape(h, w, len(chans))

RGB = ["R", "G", "B"]
FULL, STDERR = ["full." + c for c in RGB], ["full_stderr." + c for c in RGB]
LUM = np.array([0.2126, 0.7152, 0.0722])
y = read(f"{out}/gilab_long/reference.exr", FULL)
s = read(f"{out}/gilab_long/reference.exr", STDERR)
w = 1.0 / (y * y + EPS)
rel = lambda x: float(np.mean((x - y) ** 2 * w))
noise_y = float(np.mean(s * s * w))
long_info = json.load(open(f"{out}/gilab_long/reference.json"))

runs = []  # renderer, n, seconds, image
for n in gilab_spp:
    info = json.load(open(f"{out}/gilab_spp{n}/reference.json"))
    x = read(f"{out}/gilab_spp{n}/reference.exr", FULL)
    runs.append(("gilab", int(n), info["seconds"], x))
for n in cycles_spp:
    info = json.load(open(f"{out}/cycles_spp{n}.json"))
    runs.append(("cycles", int(n), info["seconds"], read(f"{out}/cycles_spp{n}.exr", RGB)))
blender_version = info["blender_version"]
cycles_rr = info["settings"]["min_light_bounces"] < 64

rows = []
for r, n, sec, x in runs:
    m = rel(x)
    a = n * (m - noise_y)
    spp = a / TARGET if a > 0 else float("nan")
    rows.append({"renderer": r, "spp": n, "seconds": sec, "s_per_spp": sec / n, "rel_mse": m,
                 "a": a, "spp_to_1e-3": spp, "seconds_to_1e-3": spp * sec / n})

def self_noise(r):
    """Per-sample relMSE a and per-channel sum of per-sample pixel variances from the renderer's
    two longest runs (different seeds), independent of the other renderer."""
    (n1, x1), (n2, x2) = [(n, x) for rr, n, _, x in runs if rr == r][-2:]
    k = 1.0 / n1 + 1.0 / n2
    d2 = (x1 - x2) ** 2
    return float(np.mean(d2 * w)) / k, d2.sum((0, 1)) / k, (d2 * LUM).sum(-1).sum() / k

cyc = [(n, x) for r, n, _, x in runs if r == "cycles"]
n_c, c = cyc[-1]
npx = y.shape[0] * y.shape[1]
mean_y, mean_c = y.mean((0, 1)), c.mean((0, 1))
var_mean_y = (s * s).sum((0, 1)) / npx ** 2  # variance of the image mean, per channel
lum_y, lum_c = float(mean_y @ LUM), float(mean_c @ LUM)
agreement = {"cycles_spp": n_c, "gilab_long_spp": long_info["samples"],
             "mean_gilab": mean_y.tolist() + [lum_y], "mean_cycles": mean_c.tolist() + [lum_c],
             "ratio_cycles_over_gilab": (mean_c / mean_y).tolist() + [lum_c / lum_y],
             "rel_mse": rel(c), "noise_gilab_long": noise_y}
if len(cyc) >= 2:
    a_c, var_c, var_c_lum = self_noise("cycles")
    noise_c = a_c / n_c
    sig = np.sqrt(var_c / n_c / npx ** 2 / mean_c ** 2 + var_mean_y / mean_y ** 2)
    sig_lum = np.sqrt(var_c_lum / n_c / npx ** 2 / lum_c ** 2
                      + (var_mean_y @ LUM ** 2) / lum_y ** 2)
    agreement.update({"a_cycles_self": a_c, "noise_cycles": noise_c,
                      "rel_mse_minus_noise": rel(c) - noise_y - noise_c,
                      "ratio_sigma": sig.tolist() + [float(sig_lum)]})
# Control: the same excess for gilab's own longest measured run (0 up to the estimates' noise).
gil = [(n, x) for r, n, _, x in runs if r == "gilab"]
if len(gil) >= 2:
    a_g = self_noise("gilab")[0]
    n_g, x_g = gil[-1]
    agreement.update({"a_gilab_self": a_g, "control_gilab_spp": n_g,
                      "control_gilab_rel_mse_minus_noise": rel(x_g) - noise_y - a_g / n_g})
# Orientation: the unflipped Cycles image must be the closest to gilab's.
flips = {"none": rel(c), "left-right": rel(c[:, ::-1]), "up-down": rel(c[::-1])}
agreement["orientation_rel_mse"] = flips
orientation_ok = min(flips, key=flips.get) == "none"

def f(v, fmt):
    return "n/a" if v != v else format(v, fmt)

lines = ["| renderer | spp measured | s/spp | relMSE | a = n(relMSE - noise) | spp to 1e-3 "
         "| s to 1e-3 |",
         "|---|---:|---:|---:|---:|---:|---:|"]
for r in rows:
    lines.append(f"| {r['renderer']} | {r['spp']} | {r['s_per_spp']:.4g} | {r['rel_mse']:.4g} | "
                 f"{r['a']:.4g} | {f(r['spp_to_1e-3'], '.0f')} | "
                 f"{f(r['seconds_to_1e-3'], '.3g')} |")
ag = agreement
ratio = ", ".join(f"{k} {v:.4f}" + (f" ± {e:.4f}" if "ratio_sigma" in ag else "")
                  for k, v, e in zip(["R", "G", "B", "lum"], ag["ratio_cycles_over_gilab"],
                                     ag.get("ratio_sigma", [0] * 4)))
lines += ["", f"Converged image: gilab, {ag['gilab_long_spp']} spp, seed 1; its own noise "
          f"mean(stderr^2 / (y^2 + 1e-2)) = {noise_y:.4g}.",
          f"Agreement, Cycles {n_c} spp vs gilab converged: mean ratio Cycles/gilab {ratio} " +
          ("(± one standard error from both images' noise)." if "ratio_sigma" in ag else
           "(no noise estimate: that needs two Cycles runs).")]
if "rel_mse_minus_noise" in ag:
    lines.append(f"relMSE {ag['rel_mse']:.4g} - gilab noise {noise_y:.4g} - Cycles noise "
                 f"{ag['noise_cycles']:.4g} (a = {ag['a_cycles_self']:.4g} from its two longest "
                 f"runs) = {ag['rel_mse_minus_noise']:.4g} (0 within noise when they agree).")
if "a_gilab_self" in ag:
    lines.append(f"Control, gilab {ag['control_gilab_spp']} spp vs its converged image, the "
                 f"same way (a = {ag['a_gilab_self']:.4g} from its two longest runs): "
                 f"{ag['control_gilab_rel_mse_minus_noise']:.4g}.")
lines.append("Orientation (relMSE of Cycles vs gilab, Cycles flipped): " +
             ", ".join(f"{k} {v:.4g}" for k, v in flips.items()) +
             ("" if orientation_ok else "  ** a flipped image matches better: camera mismatch **"))
threads = long_info.get("threads")
st = long_info.get("settings", {})
measured = json.load(open(f"{out}/gilab_spp{gilab_spp[-1]}/reference.json")).get("settings", {})
rr = st.get("roulette_start_bounce", -1)
gilab_rr = (f"Russian roulette past bounce {rr} below throughput {st.get('roulette_threshold', 1):.3g}"
            if rr >= 0 else "no Russian roulette")
head = [f"# Cycles cross-check ({y.shape[1]}x{y.shape[0]})", "",
        f"gilab reference path tracer v{long_info.get('renderer', {}).get('version', '?')} "
        f"({threads} threads, {measured.get('sampler', 'independent')} sampler, {gilab_rr}) vs Blender "
        f"{blender_version} Cycles (CPU, Russian roulette {'on' if cycles_rr else 'off'}); "
        "times are the render calls only (Cycles: bpy render incl. scene sync and EXR write; "
        "gilab: reference.json seconds).", ""]
text = "\n".join(head + lines) + "\n"
print(text, end="")
open(f"{out}/crosscheck.md", "w").write(text)
json.dump({"resolution": list(y.shape[:2]), "gilab_threads": threads,
           "blender_version": blender_version,
           "cycles_russian_roulette": cycles_rr, "runs": rows, "agreement": agreement,
           "orientation_ok": orientation_ok}, open(f"{out}/crosscheck.json", "w"), indent=2)
print(f"wrote {out}/crosscheck.json and crosscheck.md")
sys.exit(0 if orientation_ok else 1)
PY
