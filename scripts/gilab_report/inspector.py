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

The runner's HDR-FLIP maps (flip.png, flip_full.png) are only PNGs: their values are read back by
inverting the runner's colour map (experiments/metrics/colormap.cpp: 256 entries, entry
round(255 t), written as 8-bit sRGB, all 256 entries distinct). Each pixel's colour is matched to
the nearest entry k and embedded as one byte (base64, row-major, top row first); the inspector
shows k / 255, which is the FLIP value to within the map's own quantisation (+-0.5/255, about
0.002) when the colour is exactly an entry ("dev" 0: every runner-written map); pixels with no
entry within MAP_TOLERANCE levels per channel (NaN: magenta) have no value. Each error-map layer
also carries its legend (metric, range, colour stops) for the inspector's colour bar.
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
MAP_TOLERANCE = 4  # 8-bit levels per channel between a map's colour and its colour-map entry

# experiments/metrics/colormap.cpp's kMagmaAnchors: (entry, sRGB) of the runner's magma, linearly
# interpolated in between (the C++ code is the source; tests/report/test_inspector.py checks that
# these agree with it).
RUNNER_MAGMA_ANCHORS = (
    (0, (0.001462, 0.000466, 0.013866)), (16, (0.039608, 0.031090, 0.133515)),
    (32, (0.113094, 0.065492, 0.276784)), (48, (0.211718, 0.061992, 0.418647)),
    (64, (0.316654, 0.071690, 0.485380)), (80, (0.414709, 0.110431, 0.504662)),
    (96, (0.512831, 0.148179, 0.507648)), (112, (0.613617, 0.181811, 0.498536)),
    (128, (0.716387, 0.214982, 0.475290)), (144, (0.816914, 0.255895, 0.436461)),
    (160, (0.904281, 0.319610, 0.388137)), (176, (0.960949, 0.418323, 0.359630)),
    (192, (0.986700, 0.535582, 0.382210)), (208, (0.996096, 0.653659, 0.446213)),
    (224, (0.996898, 0.769591, 0.534892)), (240, (0.992440, 0.884330, 0.640099)),
    (255, (0.987053, 0.991438, 0.749504)))
# The legends of the two kinds of error map (the inspector's colour bar).
FLIP_LEGEND = {"metric": "HDR-FLIP", "min": 0, "max": 1, "minLabel": "0", "maxLabel": "1",
               "cmap": "runner-magma",
               "note": "0: no visible difference, 1: the largest; value read back from the "
                       "PNG's 8-bit colour (±0.002)"}
RELERR_LEGEND = {"metric": "|ΔY| / mean Y", "min": 0, "max": 1, "minLabel": "0",
                 "maxLabel": "≥ 1", "cmap": "magma",
                 "note": "the report's own map; colours clamp at 1; value computed from the "
                         "embedded linear images"}


LEGENDS = {"map": FLIP_LEGEND, "relerr": RELERR_LEGEND}


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
class MapValues:
    """One error map's values read back from its PNG: one byte k per pixel (value k / 255)."""

    id: str
    width: int
    height: int
    b64: str
    bad: list[int]  # pixels (y * width + x) with no value (not a colour of the map: NaN)
    dev: int  # largest difference (8-bit levels, any channel) of a matched colour to its entry
    codes: bytes  # the bytes embedded


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
    q: Optional[str] = None  # map: id of its values read back from the PNG (MapValues)


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


def runner_magma_lut() -> list[tuple[int, int, int]]:
    """The 256 8-bit colours of the runner's FLIP maps (colormap.cpp, written by
    writePngTonemapped: round(255 * sRGB))."""
    lut = []
    for (i0, c0), (i1, c1) in zip(RUNNER_MAGMA_ANCHORS, RUNNER_MAGMA_ANCHORS[1:]):
        for i in range(i0 if i0 == 0 else i0 + 1, i1 + 1):
            f = (i - i0) / (i1 - i0)
            lut.append(tuple(int(math.floor(255.0 * (a + f * (b - a)) + 0.5))
                             for a, b in zip(c0, c1)))
    return lut


def read_png_rgb(path: str, max_pixels: int) -> "tuple[int, int, bytes] | str":
    """(width, height, 8-bit RGB bytes) of a PNG, or why not (OpenImageIO, like exr.py)."""
    from .exr import oiio

    image = oiio.ImageInput.open(path)
    if image is None:
        return f"{os.path.basename(path)}: {oiio.geterror() or 'cannot be opened'}"
    try:
        spec = image.spec()
        if spec.width * spec.height > max_pixels:
            return (f"{spec.width}×{spec.height} pixels, over the limit of {max_pixels} for "
                    "embedded values")
        if spec.nchannels < 3:
            return f"{os.path.basename(path)} has {spec.nchannels} channel(s), not RGB"
        pixels = image.read_image(0, 0, 0, 3, "uint8")
    finally:
        image.close()
    if pixels is None:
        return f"{os.path.basename(path)}: {oiio.geterror() or 'cannot be read'}"
    return spec.width, spec.height, bytes(pixels.reshape(-1))


def invert_colormap(rgb: bytes, lut: list[tuple[int, int, int]],
                    nearest: Optional[dict] = None) -> tuple[bytes, list[int], int]:
    """Per pixel the index of the nearest lut colour (squared distance), the pixels with none
    within MAP_TOLERANCE levels per channel, and the largest per-channel difference of the
    others. nearest: colour -> (index, deviation), a cache for one lut."""
    exact = {c: i for i, c in enumerate(lut)}
    nearest = {} if nearest is None else nearest
    codes = bytearray(len(rgb) // 3)
    bad: list[int] = []
    dev = 0
    for p in range(len(codes)):
        colour = (rgb[3 * p], rgb[3 * p + 1], rgb[3 * p + 2])
        index = exact.get(colour)
        if index is None:
            if colour not in nearest:
                best = min(range(len(lut)), key=lambda i: sum(
                    (a - b) * (a - b) for a, b in zip(colour, lut[i])))
                nearest[colour] = (best, max(abs(a - b) for a, b in zip(colour, lut[best])))
            index, off = nearest[colour]
            if off > MAP_TOLERANCE:
                bad.append(p)
                continue
            dev = max(dev, off)
        codes[p] = index
    return bytes(codes), bad, dev


def legend_stops(lut: list[tuple[int, int, int]]) -> list[list]:
    """[position 0..1, '#rrggbb'] at every 16th entry and the last (a CSS gradient)."""
    return [[round(i / 255.0, 4), "#%02x%02x%02x" % lut[i]] for i in list(range(0, 255, 16))
            + [255]]


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
        self._runner_lut: Optional[list[tuple[int, int, int]]] = None
        self._nearest: dict = {}  # invert_colormap's cache for the runner's lut
        self.maps_written: list[str] = []
        self.map_values: dict[str, MapValues] = {}
        self.map_by_path: dict[str, Optional[str]] = {}
        self.map_problems: dict[str, str] = {}

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

    # ---- the runner's HDR-FLIP maps: values read back from the PNG -------------------------

    def flip_values(self, png_path: str) -> Optional[str]:
        """The id of a FLIP map's values (its PNG's colours inverted through the runner's
        magma), None when there are none (map_problems says why); each file read once."""
        if png_path in self.map_by_path:
            return self.map_by_path[png_path]
        ident = None
        read = read_png_rgb(png_path, MAX_PIXELS) if os.path.isfile(png_path) else "no file"
        if isinstance(read, str):
            self.map_problems[png_path] = read
        else:
            width, height, rgb = read
            if self._runner_lut is None:
                self._runner_lut = runner_magma_lut()
            codes, bad, dev = invert_colormap(rgb, self._runner_lut, self._nearest)
            text = base64.b64encode(codes).decode("ascii")
            if len(bad) > len(codes) // 8:
                self.map_problems[png_path] = (f"{len(bad)} of its {len(codes)} pixels are not "
                                               "colours of the runner's magma map")
            elif self.chars + len(text) > BUDGET_CHARS:
                self.skipped_budget += 1
                self.map_problems[png_path] = ("the page's budget for embedded values "
                                               f"({BUDGET_CHARS // (1024 * 1024)} MiB) is spent")
            else:
                ident = f"M{len(self.map_values)}"
                self.map_values[ident] = MapValues(ident, width, height, text, bad, dev, codes)
                self.chars += len(text)
        self.map_by_path[png_path] = ident
        return ident

    # ---- groups and the page's JSON ---------------------------------------------------------

    def group(self, title: str, layers: list[Layer]) -> str:
        for layer in layers:
            if layer.kind == "map" and layer.q is None and layer.path:
                layer.q = self.flip_values(layer.path)
                if layer.q is None and not layer.why:
                    layer.why = self.map_problems.get(layer.path, "")
        ident = f"G{len(self.groups)}"
        self.groups[ident] = Group(title, layers)
        return ident

    def payload(self, rel: Callable[[str], str]) -> str:
        """The JSON embedded in the page (rel: absolute path -> the page's relative URL), safe
        inside <script>."""
        groups = {}
        cmaps: set[str] = set()
        for ident, group in self.groups.items():
            layers = []
            for layer in group.layers:
                entry = {"name": layer.name, "src": rel(layer.path), "kind": layer.kind,
                         "expo": layer.expo}
                for key in ("lin", "a", "b", "mean", "why", "q"):
                    value = getattr(layer, key)
                    if value not in (None, ""):
                        entry[key] = value
                if layer.kind in LEGENDS:
                    entry["legend"] = LEGENDS[layer.kind]
                    cmaps.add(LEGENDS[layer.kind]["cmap"])
                layers.append(entry)
            groups[ident] = {"title": group.title, "layers": layers}
        images = {i: {"w": im.width, "h": im.height, "fmt": im.fmt, "b64": im.b64}
                  for i, im in self.images.items()}
        maps = {i: {"w": m.width, "h": m.height, "b64": m.b64, "bad": m.bad, "dev": m.dev}
                for i, m in self.map_values.items()}
        luts = {"runner-magma": lambda: self._runner_lut or runner_magma_lut(),
                "magma": lambda: self._lut or magma_lut()}
        stops = {name: legend_stops(luts[name]()) for name in sorted(cmaps)}
        text = json.dumps({"maxPixels": MAX_PIXELS, "images": images, "maps": maps,
                           "cmaps": stops, "groups": groups},
                          separators=(",", ":"), allow_nan=False)
        return text.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")


def clear_old_maps(out_dir: str) -> None:
    """Removes the error maps of an earlier report (maps/ belongs to the report)."""
    for path in glob.glob(os.path.join(out_dir, MAPS_DIR, "*.png")):
        os.remove(path)
