"""The image inspector's data (docs/report.md, "Image inspector").

Clicking an image of the page opens it in the inspector (assets.INSPECTOR_JS): nearest-
neighbour zoom, flipping between the layers of its group (the run, the references, the error
maps, ...) and the linear values under the cursor. The values are read here from the runs' and
references' EXR files (exr.py, OpenImageIO) and embedded in the page, per image,
as base64 little-endian float16 RGB (float32 when a value is beyond float16's range), row-major,
top row first, at the EXR's resolution (that of the PNG previews). Only images of at most
MAX_PIXELS pixels are embedded, and at most BUDGET_CHARS characters of them in one page; the
inspector says why an image has no values.

Where the runner wrote no HDR-FLIP map against the full reference (outputs.flip_full_png), the
report draws its own error map against it from the same linear values: per pixel
|Y(run) - Y(full reference)| / mean Y(full reference) (Y: Rec. 709 luminance), magma from 0 to 1
(1 = an error as large as the reference's mean luminance), written to OUTDIR/maps/.
"""
from __future__ import annotations

import base64
import glob
import json
import math
import os
import struct
import zlib
from dataclasses import dataclass
from typing import Callable, Optional

from .exr import ExrImage, ExrProblem, read_exr

MAX_PIXELS = 256 * 256  # per embedded image
BUDGET_CHARS = 8 * 1024 * 1024  # of base64 text per page
LUMA = (0.2126, 0.7152, 0.0722)
MAPS_DIR = "maps"
F16_MAX = 65504.0
MAGENTA = (255, 0, 255)


@dataclass
class Linear:
    """One embedded image: linear RGB at width x height."""

    id: str
    width: int
    height: int
    fmt: str  # "f16" or "f32"
    b64: str
    rgb: list[float]  # the values embedded (float16-rounded when fmt is f16)


@dataclass
class Layer:
    """One layer of an inspector group: an image file and, where known, its linear values."""

    name: str  # "run", "full reference", "error vs full reference", ...
    path: str  # the PNG shown (absolute)
    lin: Optional[str] = None  # id of its linear values
    kind: str = "image"  # "image" (values: linear RGB), "map" (an error map, colour only),
    #                      "relerr" (the report's error map: values computed from a and b)
    expo: bool = True  # the section's exposure slider applies
    a: Optional[str] = None  # relerr: the run's linear values
    b: Optional[str] = None  # relerr: the reference's
    mean: Optional[float] = None  # relerr: mean luminance of the reference
    why: str = ""  # why there are no linear values


@dataclass
class Group:
    title: str
    layers: list[Layer]


def luminance(rgb: list[float], i: int) -> float:
    return LUMA[0] * rgb[3 * i] + LUMA[1] * rgb[3 * i + 1] + LUMA[2] * rgb[3 * i + 2]


def _pack(values: list[float]) -> tuple[str, bytes, list[float]]:
    """('f16', bytes, rounded values), or f32 when a finite value is beyond float16's range."""
    if all(not math.isfinite(v) or abs(v) <= F16_MAX for v in values):
        data = struct.pack(f"<{len(values)}e", *values)
        return "f16", data, list(struct.unpack(f"<{len(values)}e", data))
    data = struct.pack(f"<{len(values)}f", *values)
    return "f32", data, list(struct.unpack(f"<{len(values)}f", data))


def write_png(path: str, width: int, height: int, rgb: bytes) -> None:
    """An 8-bit RGB PNG (no filter, zlib) from width * height * 3 bytes."""
    rows = b"".join(b"\x00" + rgb[y * width * 3:(y + 1) * width * 3] for y in range(height))

    def chunk(tag: bytes, data: bytes) -> bytes:
        return (struct.pack(">I", len(data)) + tag + data
                + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF))

    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0,
                                                            0, 0))
           + chunk(b"IDAT", zlib.compress(rows, 9)) + chunk(b"IEND", b""))
    tmp = f"{path}.tmp-{os.getpid()}"
    with open(tmp, "wb") as f:
        f.write(png)
    os.replace(tmp, path)


def magma_lut() -> list[tuple[int, int, int]]:
    """256 colours of matplotlib's magma (the FLIP maps' colour map)."""
    import matplotlib  # the report's figures need it anyway

    cmap = matplotlib.colormaps["magma"]
    return [tuple(int(round(255 * c)) for c in cmap(i / 255.0)[:3]) for i in range(256)]


class Inspector:
    """Collects the linear images and the groups of layers of one page."""

    def __init__(self, out_dir: str) -> None:
        self.out_dir = out_dir
        self.images: dict[str, Linear] = {}
        self.by_source: dict[tuple[str, str], Optional[str]] = {}
        self.problems: dict[tuple[str, str], str] = {}
        self.groups: dict[str, Group] = {}
        self.chars = 0
        self.skipped_budget = 0
        self._files: dict[str, object] = {}
        self._lut: Optional[list[tuple[int, int, int]]] = None
        self.maps_written: list[str] = []

    # ---- linear values ----------------------------------------------------------------------

    def _file(self, path: str, layer: str) -> object:
        key = f"{path}\0{layer}"
        if key not in self._files:
            wanted = {f"{layer}.{c}" for c in "RGB"} | set("RGB")
            self._files[key] = read_exr(path, MAX_PIXELS, wanted)
        return self._files[key]

    def linear(self, exr_path: Optional[str], layer: str = "final") -> Optional[str]:
        """The id of the linear values of `layer` of an EXR (read once), None when it gives
        none (then why_not says why)."""
        if not exr_path:
            return None
        source = (exr_path, layer)
        if source in self.by_source:
            return self.by_source[source]
        image = self._file(exr_path, layer)
        ident = None
        if isinstance(image, ExrProblem):
            self.problems[source] = f"{os.path.basename(exr_path)}: {image.why}"
        elif isinstance(image, ExrImage):
            rgb = image.layer_rgb(layer)
            if rgb is None:
                self.problems[source] = f"{os.path.basename(exr_path)} has no {layer} layer"
            else:
                fmt, data, rounded = _pack(rgb)
                text = base64.b64encode(data).decode("ascii")
                if self.chars + len(text) > BUDGET_CHARS:
                    self.skipped_budget += 1
                    self.problems[source] = ("the page's budget for embedded values "
                                             f"({BUDGET_CHARS // (1024 * 1024)} MiB) is spent")
                else:
                    ident = f"L{len(self.images)}"
                    self.images[ident] = Linear(ident, image.width, image.height, fmt, text,
                                                rounded)
                    self.chars += len(text)
        self.by_source[source] = ident
        return ident

    def why_not(self, exr_path: Optional[str], layer: str = "final") -> str:
        if not exr_path:
            return "no EXR recorded"
        return self.problems.get((exr_path, layer), "")

    # ---- the report's own error map ---------------------------------------------------------

    def relerr_map(self, name: str, run_id: Optional[str], ref_id: Optional[str]
                   ) -> Optional[tuple[str, float]]:
        """Writes OUTDIR/maps/<name>.png, |Y(run) - Y(ref)| / mean Y(ref) in magma (0..1);
        returns (path, mean Y(ref)), None without both images at one size or a positive mean."""
        run, ref = self.images.get(run_id or ""), self.images.get(ref_id or "")
        if run is None or ref is None or (run.width, run.height) != (ref.width, ref.height):
            return None
        n = run.width * run.height
        ref_y = [luminance(ref.rgb, i) for i in range(n)]
        finite = [y for y in ref_y if math.isfinite(y)]
        mean = sum(finite) / len(finite) if finite else 0.0
        if not mean > 0.0:
            return None
        if self._lut is None:
            self._lut = magma_lut()
        out = bytearray()
        for i in range(n):
            e = abs(luminance(run.rgb, i) - ref_y[i]) / mean
            out += bytes(self._lut[min(255, int(round(min(e, 1.0) * 255)))] if math.isfinite(e)
                         else MAGENTA)
        folder = os.path.join(self.out_dir, MAPS_DIR)
        os.makedirs(folder, exist_ok=True)
        path = os.path.join(folder, f"{name}.png")
        write_png(path, run.width, run.height, bytes(out))
        self.maps_written.append(path)
        return path, mean

    # ---- groups and the page's JSON ---------------------------------------------------------

    def group(self, title: str, layers: list[Layer]) -> str:
        ident = f"G{len(self.groups)}"
        self.groups[ident] = Group(title, layers)
        return ident

    def payload(self, rel: Callable[[str], str]) -> str:
        """The JSON embedded in the page (rel: absolute path -> the page's relative URL), safe
        inside <script>."""
        groups = {}
        for ident, group in self.groups.items():
            layers = []
            for layer in group.layers:
                entry = {"name": layer.name, "src": rel(layer.path), "kind": layer.kind,
                         "expo": layer.expo}
                for key in ("lin", "a", "b", "mean", "why"):
                    value = getattr(layer, key)
                    if value not in (None, ""):
                        entry[key] = value
                layers.append(entry)
            groups[ident] = {"title": group.title, "layers": layers}
        images = {i: {"w": im.width, "h": im.height, "fmt": im.fmt, "b64": im.b64}
                  for i, im in self.images.items()}
        text = json.dumps({"maxPixels": MAX_PIXELS, "images": images, "groups": groups},
                          separators=(",", ":"), allow_nan=False)
        return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def clear_old_maps(out_dir: str) -> None:
    """Removes the error maps of an earlier report (maps/ belongs to the report)."""
    for path in glob.glob(os.path.join(out_dir, MAPS_DIR, "*.png")):
        os.remove(path)
