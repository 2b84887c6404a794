#!/usr/bin/env bash
# Optional cross-check of gilab's Embree path tracer (the reference) against Blender Cycles:
# the time each needs to a relative MSE of 1e-3, and whether their images agree. Not part of the
# default install, the build or CI; Blender is installed on demand (Debian's `blender` package,
# 3.4.1 on Debian 12).
#
# Both renderers see the same scene: Lambertian materials from the glTF (Cycles' materials are
# rebuilt by scripts/cycles_render.py: the factors, and on Sponza the importer's base-colour
# textures), gilab's camera and lights, rays through pixel centres, the same bounce limit, black
# background, T threads each. The renders run in rounds; each round renders gilab seed s, Cycles
# seed s, gilab seed s + 1, Cycles seed s + 1, then one 1-sample render of each (the set-up time
# every render repeats). scripts/cycles_crosscheck.py derives, per round, each renderer's
# relative MSE per sample from its seed pair, its marginal wall and CPU time per sample, the time
# to 1e-3 and the ratio gilab / Cycles; then the spread over rounds and the agreement of the
# pooled images. Writes OUT/crosscheck.{json,md}; the figures belong in docs/reference.md
# ("Measured: ground-truth speed").
#
# usage: scripts/cycles_crosscheck.sh [--scene NAME] [--rounds R] [--gilab-spp N]
#          [--cycles-spp N] [--threads T] [--out DIR] [--gilab-sampler sobol|independent]
#          [--ladder N] [--seed-base S] [--target E] [--pixel-filter center|box]
#   cornell (default): McGuire's Cornell box glTF, 256x256, 64 bounces, gilab 1024 / Cycles 512 spp
#   sponza: Dabrovic Sponza, the sun of scenes/sponza.json, 256x144, 16 bounces, textured,
#           gilab 256 / Cycles 128 spp
#   sponza-flat: the same with every base-colour texture replaced by its mean linear colour
#           (scripts/gltf_mean_factors.py), the integrators without texture filtering
#   sponza-linear: textured, Cycles' textures decoded to linear floats before it filters them
#           (as gilab does; Cycles decodes 8-bit sRGB after its bilinear filter)
#   --rounds: repeats of the interleaved seed pairs (default 2; the ratio's spread needs >= 2)
#   --ladder N: measure at relMSE 1e-3 instead of extrapolating to it (issue 49): seed pairs of
#       both renderers at N, 2N, 4N, ... spp until each reaches 1e-3 (the count is interpolated
#       between the two rungs around it), then --rounds (at least 4) interleaved rounds of seed
#       pairs at that count; --gilab-spp and --cycles-spp are not used
#   --seed-base S: first seed (default: from the clock, so every sitting draws new seeds)
#   --target E: the relMSE the ladder measures at (default 1e-3; larger only for a quick try)
#   --pixel-filter: center (default; gilab filters the camera hit's textures at the rasteriser's
#       mip level) or box (both renderers average over the pixel, textures at full resolution)
#   env GILAB: the gilab binary (default build/gilab)
# tiny test: scripts/cycles_crosscheck.sh --rounds 2 --gilab-spp 8 --cycles-spp 8 --out /tmp/x
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
scene=cornell rounds="" gilab_spp="" cycles_spp="" threads=2 sampler=sobol ladder=""
pixel_filter=center
seed_base=$(( $(date +%s) % 1000000 * 100 )) target=1e-3
out=""
gilab=${GILAB:-$root/build/gilab}
py=/usr/bin/python3

die() { echo "cycles_crosscheck: $*" >&2; exit 1; }
usage() { sed -n '18,39p' "$0"; exit "${1:-2}"; }

while [[ $# -gt 0 ]]; do
    [[ $1 == -h || $1 == --help ]] && usage 0
    [[ $# -ge 2 ]] || usage
    case $1 in
        --scene) scene=$2 ;;
        --rounds) rounds=$2 ;;
        --gilab-spp) gilab_spp=$2 ;;
        --cycles-spp) cycles_spp=$2 ;;
        --threads) threads=$2 ;;
        --out) out=$2 ;;
        --gilab-sampler) sampler=$2 ;;
        --ladder) ladder=$2 ;;
        --seed-base) seed_base=$2 ;;
        --target) target=$2 ;;
        --pixel-filter) pixel_filter=$2 ;;
        *) echo "unknown option $1" >&2; usage ;;
    esac
    shift 2
done
case $scene in
    cornell)
        desc=$root/scenes/cornell_box_gltf.json
        gltf=$root/../shared/scenes/cornell-box/cornell_box.gltf
        width=256 height=256 bounces=64 textures=""
        : "${gilab_spp:=1024}" "${cycles_spp:=512}" ;;
    sponza | sponza-flat | sponza-linear)
        desc=$root/scenes/sponza.json
        gltf=$root/../shared/scenes/dabrovic-sponza/sponza.gltf
        width=256 height=144 bounces=16 textures=--textures
        [[ $scene == sponza-flat ]] && textures=""
        [[ $scene == sponza-linear ]] && textures="--textures --linear-textures"
        : "${gilab_spp:=256}" "${cycles_spp:=128}" ;;
    *) die "--scene takes cornell, sponza, sponza-flat or sponza-linear (got $scene)" ;;
esac
: "${out:=results/cycles_crosscheck/$scene}"
[[ $pixel_filter == center || $pixel_filter == box ]] ||
    die "--pixel-filter takes center or box (got $pixel_filter)"
[[ $sampler == independent || $sampler == sobol ]] ||
    die "--gilab-sampler takes independent or sobol"
if [[ -n $ladder ]]; then
    : "${rounds:=4}"
    [[ $ladder =~ ^[1-9][0-9]*$ && $ladder -ge 2 ]] || die "--ladder takes a count >= 2"
    [[ $rounds -ge 4 ]] || die "--ladder needs --rounds 4 or more (seed pairs at the target)"
else
    : "${rounds:=2}"
fi
[[ $seed_base =~ ^[0-9]+$ ]] || die "--seed-base takes a non-negative integer"
[[ $target =~ ^[0-9.]+(e-?[0-9]+)?$ ]] || die "--target takes a relMSE such as 1e-3"
for v in "$rounds" "$threads" "$gilab_spp" "$cycles_spp"; do
    [[ $v =~ ^[1-9][0-9]*$ ]] || die "not a positive integer: $v"
done
[[ $gilab_spp -ge 2 && $cycles_spp -ge 2 ]] || die "--gilab-spp and --cycles-spp must be >= 2"

[[ -f $gltf ]] || die "scene file not found: $gltf (see scenes/README.md)"
[[ -x $gilab ]] || die "gilab binary not found: $gilab (build it, or set GILAB)"
$py -c 'import numpy' 2>/dev/null || die "$py with numpy is needed"
$py -c 'import OpenImageIO' 2>/dev/null ||
    die "$py with the OpenImageIO module is needed (Debian: python3-openimageio)"

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
if [[ $scene == sponza-flat ]]; then
    # Both renderers see the textures replaced by their mean linear colours (issue 49)
    $py "$root/scripts/gltf_mean_factors.py" "$gltf" "$out/sponza_mean_factors.gltf" ||
        die "scripts/gltf_mean_factors.py failed"
    gltf=$out/sponza_mean_factors.gltf
fi
# One scene description for both renderers: the preset's camera and lights, this glTF.
$py - "$desc" "$(realpath "$gltf")" "$width" "$height" "$out/scene.json" <<'PY'
import json, sys
src, gltf, w, h, dst = sys.argv[1:]
d = json.load(open(src))
scene = {"gltf": gltf, "camera": d["camera"], "resolution": [int(w), int(h)]}
if "lights" in d:
    scene["lights"] = d["lights"]
json.dump(scene, open(dst, "w"), indent=2)
PY

# gilab uses every CPU it may run on (TBB): pin it to T CPUs when there are more.
pin=()
if [[ $threads -lt $(nproc) ]]; then pin=(taskset -c "0-$((threads - 1))"); fi

gilab_render() {  # spp seed dir
    echo "gilab:  $1 spp (seed $2, $sampler sampler) -> $3"
    "${pin[@]}" "$gilab" reference --scene "$out/scene.json" --resolution "${width}x${height}" \
        --max-bounces "$bounces" --pixel-filter "$pixel_filter" --spp "$1" --seed "$2" \
        --sampler "$sampler" --batch 16 --no-cache -o "$out/$3" -q >/dev/null ||
        die "gilab reference failed ($out/$3)"
}

cycles_render() {  # spp seed name
    echo "cycles: $1 spp (seed $2) -> $3.exr"
    blender -b --factory-startup -t "$threads" --python "$root/scripts/cycles_render.py" -- \
        --scene "$out/scene.json" --out "$out/$3.exr" --width "$width" --height "$height" \
        --samples "$1" --seed "$2" --threads "$threads" --max-bounces "$bounces" \
        --pixel-filter "$pixel_filter" \
        $textures >"$out/$3.log" 2>&1 ||
        { tail -n 20 "$out/$3.log" >&2; die "blender failed (log: $out/$3.log)"; }
    grep -q '^cycles_render: .* spp in' "$out/$3.log" ||
        { tail -n 20 "$out/$3.log" >&2; die "cycles_render.py did not finish ($out/$3.log)"; }
}

# The rounds, interleaved; runs.json lists every render for the analysis
runs=()
stage=""
add_run() {
    runs+=("{\"renderer\": \"$1\", \"round\": $2, \"seed\": $3, \"spp\": $4, \"path\": \"$5\"${stage:+, \"stage\": \"$stage\"}}")
}
cpu=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')
write_runs() {
    {
        printf '{"scene": "%s", "width": %d, "height": %d, "max_bounces": %d, "threads": %d,\n' \
            "$scene" "$width" "$height" "$bounces" "$threads"
        printf ' "pixel_filter": "%s",\n' "$pixel_filter"
        printf ' "machine": "%s, %d CPUs", "date": "%s", "seed_base": %d, "target": %s,\n' \
            "$cpu" "$(nproc)" "$(date -u '+%Y-%m-%d %H:%M UTC')" "$seed_base" "$target"
        printf ' "runs": [\n  %s\n ]}\n' "$(IFS=,; echo "${runs[*]}" | sed 's/},{/},\n  {/g')"
    } >"$out/runs.json"
}
seed=$seed_base
next_seed() { seed=$((seed + 1)); }

if [[ -n $ladder ]]; then
    # The ladder: both renderers' seed pairs at n, 2n, ... until each brackets the target
    stage=ladder n=$ladder rung=0 g_n="" c_n=""
    while [[ -z $g_n || -z $c_n ]]; do
        rung=$((rung + 1))
        [[ $n -le 1048576 ]] || die "the ladder passed 1048576 spp without reaching $target"
        for s in 1 2; do
            next_seed
            if [[ -z $g_n ]]; then
                gilab_render "$n" $seed "ladder_gilab_${n}_s$seed"
                add_run gilab "$rung" $seed "$n" "ladder_gilab_${n}_s$seed"
            fi
            if [[ -z $c_n ]]; then
                cycles_render "$n" $seed "ladder_cycles_${n}_s$seed"
                add_run cycles "$rung" $seed "$n" "ladder_cycles_${n}_s$seed"
            fi
        done
        write_runs
        status=$($py "$root/scripts/cycles_crosscheck.py" --ladder-status "$out") || exit 1
        echo "$status" | sed 's/^/ladder: /'
        g_n=$(awk '$1 == "gilab" && $2 != "-" {print $2}' <<<"$status")
        c_n=$(awk '$1 == "cycles" && $2 != "-" {print $2}' <<<"$status")
        n=$((n * 2))
    done
    # Render at the count the ladder found, rounded up to whole batches of 16 (gilab's --batch)
    gilab_spp=$($py -c "import math; print(16 * math.ceil($g_n / 16))")
    cycles_spp=$($py -c "import math; print(16 * math.ceil($c_n / 16))")
    echo "ladder: rendering gilab at $gilab_spp spp and Cycles at $cycles_spp spp"
    stage=final
fi
for ((r = 1; r <= rounds; ++r)); do
    if [[ -n $ladder ]]; then
        next_seed; s1=$seed; next_seed; s2=$seed
    else
        s1=$((2 * r - 1)) s2=$((2 * r))
    fi
    gilab_render "$gilab_spp" $s1 "gilab_r${r}_s$s1"; add_run gilab $r $s1 "$gilab_spp" "gilab_r${r}_s$s1"
    cycles_render "$cycles_spp" $s1 "cycles_r${r}_s$s1"; add_run cycles $r $s1 "$cycles_spp" "cycles_r${r}_s$s1"
    gilab_render "$gilab_spp" $s2 "gilab_r${r}_s$s2"; add_run gilab $r $s2 "$gilab_spp" "gilab_r${r}_s$s2"
    cycles_render "$cycles_spp" $s2 "cycles_r${r}_s$s2"; add_run cycles $r $s2 "$cycles_spp" "cycles_r${r}_s$s2"
    gilab_render 1 1000 "gilab_r${r}_setup"; add_run gilab $r 1000 1 "gilab_r${r}_setup"
    cycles_render 1 1000 "cycles_r${r}_setup"; add_run cycles $r 1000 1 "cycles_r${r}_setup"
done
write_runs

$py "$root/scripts/cycles_crosscheck.py" "$out"
