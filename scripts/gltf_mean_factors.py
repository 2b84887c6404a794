#!/usr/bin/python3
"""A copy of a glTF whose base-colour textures are replaced by their mean (issue 49).

Each material with a baseColorTexture gets baseColorFactor = factor x the texture's mean
linear colour (every texel's sRGB value decoded with the sRGB EOTF, IEC 61966-2-1, then
averaged; alpha as stored) and loses the texture reference. Nothing else changes; buffer and
image URIs are rewritten relative to the copy's folder, so the copy can live anywhere on
the same machine. Both renderers of
scripts/cycles_crosscheck.sh (`--scene sponza-flat`) then see the same untextured scene, which
separates the integrators from the texture filtering.

usage: /usr/bin/python3 scripts/gltf_mean_factors.py IN.gltf OUT.gltf
Needs numpy and Debian's python3-openimageio. Prints one line per replaced texture.
"""
import json
import os
import sys

import numpy as np


def fail(msg):
    sys.exit(f"gltf_mean_factors: {msg}")


def srgb_to_linear(c):
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def texture_mean(path):
    """Mean linear RGB and mean alpha of an 8-bit sRGB image."""
    import OpenImageIO as oiio
    config = oiio.ImageSpec()
    config.attribute("oiio:UnassociatedAlpha", 1)  # the texels as stored, not premultiplied
    inp = oiio.ImageInput.open(path, config)
    if inp is None:
        fail(f"cannot read {path}: {oiio.geterror()}")
    px = inp.read_image("uint8")
    inp.close()
    if px is None or px.ndim != 3:
        fail(f"{path}: not an image with channels")
    c = px.astype(np.float64) / 255.0
    rgb = c[..., :3] if c.shape[2] >= 3 else np.repeat(c[..., :1], 3, axis=2)
    alpha = float(c[..., 3].mean()) if c.shape[2] == 4 else 1.0
    return srgb_to_linear(rgb).reshape(-1, 3).mean(axis=0), alpha


def main():
    if len(sys.argv) != 3:
        fail("usage: gltf_mean_factors.py IN.gltf OUT.gltf")
    src, dst = sys.argv[1:]
    try:
        gltf = json.load(open(src))
    except (OSError, ValueError) as e:
        fail(f"{src}: {e}")
    base = os.path.dirname(os.path.abspath(src))
    out_dir = os.path.dirname(os.path.abspath(dst))

    def absolute(uri):
        return uri if uri.startswith("data:") or os.path.isabs(uri) else os.path.join(base, uri)

    def relocated(uri):  # tinygltf joins every uri to the glTF's folder: keep them relative
        return uri if uri.startswith("data:") else os.path.relpath(absolute(uri), out_dir)

    for b in gltf.get("buffers", []):
        if "uri" in b:
            b["uri"] = relocated(b["uri"])
    means = {}
    for k, mat in enumerate(gltf.get("materials", [])):
        pbr = mat.get("pbrMetallicRoughness", {})
        if "baseColorTexture" not in pbr:
            continue
        tex = gltf["textures"][pbr["baseColorTexture"]["index"]]
        image = gltf["images"][tex["source"]]
        if "uri" not in image or image["uri"].startswith("data:"):
            fail(f"{src}: material {k}: only image files are supported")
        if image["uri"] not in means:
            means[image["uri"]] = texture_mean(absolute(image["uri"]))
        rgb, alpha = means[image["uri"]]
        factor = pbr.get("baseColorFactor", [1.0, 1.0, 1.0, 1.0])
        pbr["baseColorFactor"] = [float(factor[i] * rgb[i]) for i in range(3)] + \
            [float(factor[3] * alpha)]
        del pbr["baseColorTexture"]
        print(f"gltf_mean_factors: {mat.get('name', k)}: {os.path.basename(image['uri'])} -> "
              f"({', '.join(f'{v:.4f}' for v in pbr['baseColorFactor'][:3])})")
    for im in gltf.get("images", []):
        if "uri" in im:
            im["uri"] = relocated(im["uri"])
    json.dump(gltf, open(dst, "w"), indent=1)


if __name__ == "__main__":
    main()
