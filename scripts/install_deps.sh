#!/usr/bin/env bash
# Installs every package gilab needs from Debian 12 (run as root). Idempotent: when everything is
# already installed it only checks and returns in well under a second.
set -euo pipefail

PACKAGES=(
    build-essential cmake ninja-build pkg-config git
    libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers vulkan-tools
    glslang-tools spirv-tools
    libglm-dev libtinygltf-dev nlohmann-json3-dev libstb-dev
    libopenimageio-dev openimageio-tools libopenexr-dev
    libembree-dev libtbb-dev
    libcli11-dev libxxhash-dev
    python3-matplotlib python3-jinja2 python3-openimageio chromium fonts-dejavu-core
    libgtest-dev libgmock-dev
    slurm-wlm munge  # the cluster tests start a one-node Slurm (docs/cluster.md)
)

missing=()
for p in "${PACKAGES[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        missing+=("$p")
    fi
done

if [ ${#missing[@]} -eq 0 ]; then
    exit 0
fi

if [ "$(id -u)" -ne 0 ]; then
    echo "gilab: missing Debian packages: ${missing[*]}" >&2
    echo "gilab: run this script as root (or: sudo $0)" >&2
    exit 1
fi

echo "gilab: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -q
apt-get install -y -q --no-install-recommends "${missing[@]}"
