"""OpenEXR pixels for the report's image inspector and the study's leak share, read with
OpenImageIO's Python module (Debian: python3-openimageio).

A file OpenImageIO cannot open, a deep file, or one over the pixel limit gives a reason, never an
exception: the report then shows the image without linear values. Only the first subimage
(part) is read.

    image = read_exr(path, max_pixels=65536)   # ExrImage, or ExrProblem(why)
    rgb = image.layer_rgb("final")            # [r, g, b, r, g, b, ...], top row first
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional, Union

try:
    import OpenImageIO as oiio
except ImportError as e:  # a clear message instead of a bare ModuleNotFoundError
    raise ImportError("the report reads EXR files with OpenImageIO's Python module, which "
                      f"/usr/bin/python3 cannot import ({e}); install the Debian package "
                      "python3-openimageio (scripts/install_deps.sh)") from e


@dataclass
class ExrProblem:
    """Why a file gives no linear values (shown on the page)."""

    why: str


@dataclass
class ExrImage:
    width: int
    height: int
    channels: dict[str, list[float]] = field(default_factory=dict)  # name -> row-major values

    def layer_rgb(self, layer: str = "final") -> Optional[list[float]]:
        """Interleaved RGB of '<layer>.R/G/B' (else the unnamed R, G, B), top row first."""
        for prefix in ((f"{layer}.", "") if layer else ("",)):
            names = [prefix + c for c in "RGB"]
            if all(n in self.channels for n in names):
                r, g, b = (self.channels[n] for n in names)
                out = [0.0] * (3 * len(r))
                out[0::3], out[1::3], out[2::3] = r, g, b
                return out
        return None


def _error(fallback: str) -> str:
    return (oiio.geterror() or fallback).strip()


def read_exr(path: str, max_pixels: Optional[int] = None,
             wanted: Optional[set[str]] = None) -> Union[ExrImage, ExrProblem]:
    """The channels (all, or those in `wanted`) of an OpenEXR file, or why not: unreadable,
    a deep file, or more than max_pixels pixels (checked before reading the pixels)."""
    image = oiio.ImageInput.open(path)
    if image is None:
        return ExrProblem(_error(f"cannot read {path}"))
    try:
        spec = image.spec()
        if spec.deep:
            return ExrProblem("deep OpenEXR files are not read by the report")
        width, height = spec.width, spec.height
        if width <= 0 or height <= 0:
            return ExrProblem("empty data window")
        if max_pixels is not None and width * height > max_pixels:
            return ExrProblem(f"{width}×{height} is over the report's limit of {max_pixels} "
                              "pixels")
        names = list(spec.channelnames)
        formats = list(spec.channelformats) or [spec.format] * len(names)
        out: dict[str, list[float]] = {}
        for index, name in enumerate(names):
            if wanted is not None and name not in wanted:
                continue
            # UINT channels as their integer values (not OpenImageIO's 0..1 normalisation)
            kind = "uint" if formats[index].basetype == oiio.UINT else "float"
            pixels = image.read_image(0, 0, index, index + 1, kind)
            if pixels is None:
                return ExrProblem(_error(f"cannot read the pixels of {path}"))
            out[name] = pixels.reshape(-1).astype("float64").tolist()
        return ExrImage(width, height, out)
    finally:
        image.close()
