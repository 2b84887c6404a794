"""A small OpenEXR reader (Python standard library only) for the report's image inspector.

Reads single-part scanline files with the compressions gilab's writer (OpenImageIO) and most
tools use for small images: NONE, RLE, ZIPS and ZIP; channels of type HALF, FLOAT or UINT. Tiled,
deep and multi-part files and the other compressions (PIZ, PXR24, B44, DWA) are refused with a
reason, never an exception: the report then shows the image without linear values.

    image = read_exr(path, max_pixels=65536)   # ExrImage, or ExrProblem(why)
    rgb = image.layer_rgb("final")            # [r, g, b, r, g, b, ...], top row first
"""
from __future__ import annotations

import itertools
import math
import struct
import zlib
from dataclasses import dataclass, field
from typing import Optional, Union

MAGIC = b"\x76\x2f\x31\x01"
NONE, RLE, ZIPS, ZIP = 0, 1, 2, 3
LINES_PER_CHUNK = {NONE: 1, RLE: 1, ZIPS: 1, ZIP: 16}
COMPRESSION_NAMES = {0: "NONE", 1: "RLE", 2: "ZIPS", 3: "ZIP", 4: "PIZ", 5: "PXR24", 6: "B44",
                     7: "B44A", 8: "DWAA", 9: "DWAB"}
PIXEL_TYPES = {0: ("I", 4), 1: ("e", 2), 2: ("f", 4)}  # UINT, HALF, FLOAT: struct code, bytes
TILED, LONG_NAMES, DEEP, MULTIPART = 0x200, 0x400, 0x800, 0x1000
# XOR 0x80 on every byte: the ZIP predictor's "- 128" on odd positions (see _undo_predictor).
_FLIP_TOP = bytes(i ^ 0x80 for i in range(256))


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


class _Bad(Exception):
    pass


def _header(data: bytes) -> tuple[dict[str, tuple[str, bytes]], int]:
    """Attributes (name -> (type, bytes)) and the offset just past the header."""
    if data[:4] != MAGIC:
        raise _Bad("not an OpenEXR file")
    if len(data) < 8:
        raise _Bad("truncated header")
    flags = struct.unpack_from("<I", data, 4)[0]
    if flags & 0xFF != 2:
        raise _Bad(f"OpenEXR version {flags & 0xFF} (expected 2)")
    if flags & (TILED | DEEP | MULTIPART):
        raise _Bad("tiled, deep or multi-part OpenEXR files are not read by the report")
    attrs: dict[str, tuple[str, bytes]] = {}
    pos = 8
    while True:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode("latin-1")
        pos = end + 1
        if not name:
            return attrs, pos
        end = data.index(b"\0", pos)
        kind = data[pos:end].decode("latin-1")
        pos = end + 1
        size = struct.unpack_from("<i", data, pos)[0]
        pos += 4
        if size < 0 or pos + size > len(data):
            raise _Bad("truncated header")
        attrs[name] = (kind, data[pos:pos + size])
        pos += size


def _channels(raw: bytes) -> list[tuple[str, int]]:
    """(name, pixel type) of each channel, in file order (sorted by name)."""
    out = []
    pos = 0
    while pos < len(raw) and raw[pos] != 0:
        end = raw.index(b"\0", pos)
        name = raw[pos:end].decode("utf-8", "replace")
        pixel_type, _linear, _r1, _r2, _r3, xs, ys = struct.unpack_from("<iBBBBii", raw, end + 1)
        if pixel_type not in PIXEL_TYPES:
            raise _Bad(f"channel {name}: unknown pixel type {pixel_type}")
        if xs != 1 or ys != 1:
            raise _Bad(f"channel {name} is subsampled")
        out.append((name, pixel_type))
        pos = end + 1 + 16
    return out


def _undo_predictor(data: bytes) -> bytes:
    """OpenEXR's ZIP/RLE predictor: t[i] = t[i-1] + d[i] - 128 (mod 256), i.e. the running sum
    of the bytes minus 128 i; 128 i mod 256 is 128 on odd positions (a flip of the top bit)."""
    out = bytearray(map((255).__and__, itertools.accumulate(data)))
    out[1::2] = bytes(out[1::2]).translate(_FLIP_TOP)
    return bytes(out)


def _deinterleave(data: bytes) -> bytes:
    """OpenEXR splits every value's bytes into two halves before compressing; put them back."""
    half = (len(data) + 1) // 2
    out = bytearray(len(data))
    out[0::2] = data[:half]
    out[1::2] = data[half:]
    return bytes(out)


def _unrle(data: bytes, expected: int) -> bytes:
    out = bytearray()
    pos = 0
    while pos < len(data) and len(out) < expected:
        count = struct.unpack_from("<b", data, pos)[0]
        pos += 1
        if count < 0:
            out += data[pos:pos - count]
            pos -= count
        else:
            out += data[pos:pos + 1] * (count + 1)
            pos += 1
    return bytes(out)


def _decode_chunk(compression: int, data: bytes, expected: int) -> bytes:
    if compression == NONE or len(data) == expected:  # stored as is when it did not shrink
        raw = data
    elif compression in (ZIP, ZIPS):
        raw = _deinterleave(_undo_predictor(zlib.decompress(data)))
    elif compression == RLE:
        raw = _deinterleave(_undo_predictor(_unrle(data, expected)))
    else:
        raise _Bad(f"compression {COMPRESSION_NAMES.get(compression, compression)}")
    if len(raw) != expected:
        raise _Bad("a chunk does not decode to its size")
    return raw


def read_exr(path: str, max_pixels: Optional[int] = None,
             wanted: Optional[set[str]] = None) -> Union[ExrImage, ExrProblem]:
    """The channels (all, or those in `wanted`) of an OpenEXR file, or why not: unreadable,
    an unsupported kind of file, or more than max_pixels pixels (checked before decoding)."""
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError as e:
        return ExrProblem(f"cannot read {path}: {e.strerror or e}")
    try:
        return _read(data, max_pixels, wanted)
    except _Bad as e:
        return ExrProblem(str(e))
    except (ValueError, IndexError, struct.error, zlib.error, OverflowError) as e:
        return ExrProblem(f"malformed or truncated OpenEXR file ({type(e).__name__}: {e})")


def _read(data: bytes, max_pixels: Optional[int], wanted: Optional[set[str]]) -> ExrImage:
    attrs, pos = _header(data)
    for name in ("channels", "compression", "dataWindow"):
        if name not in attrs:
            raise _Bad(f"no {name} attribute")
    channels = _channels(attrs["channels"][1])
    compression = attrs["compression"][1][0]
    if compression not in LINES_PER_CHUNK:
        raise _Bad(f"compression {COMPRESSION_NAMES.get(compression, compression)} is not read "
                   "by the report (NONE, RLE, ZIPS and ZIP are)")
    x0, y0, x1, y1 = struct.unpack("<4i", attrs["dataWindow"][1][:16])
    width, height = x1 - x0 + 1, y1 - y0 + 1
    if width <= 0 or height <= 0:
        raise _Bad("empty data window")
    if max_pixels is not None and width * height > max_pixels:
        raise _Bad(f"{width}×{height} is over the report's limit of {max_pixels} pixels")
    lines = LINES_PER_CHUNK[compression]
    chunks = math.ceil(height / lines)
    offsets = struct.unpack_from(f"<{chunks}Q", data, pos)
    line_bytes = sum(PIXEL_TYPES[t][1] for _, t in channels) * width
    keep = [(i, name, t) for i, (name, t) in enumerate(channels)
            if wanted is None or name in wanted]
    out: dict[str, list[float]] = {name: [0.0] * (width * height) for _, name, _ in keep}
    for offset in offsets:
        y, size = struct.unpack_from("<ii", data, offset)
        first = y - y0
        count = min(lines, height - first)
        if first < 0 or count <= 0:
            raise _Bad("a chunk lies outside the data window")
        raw = _decode_chunk(compression, data[offset + 8:offset + 8 + size], line_bytes * count)
        for row in range(count):
            at = row * line_bytes
            starts = []
            for name, t in channels:
                starts.append(at)
                at += PIXEL_TYPES[t][1] * width
            base = (first + row) * width
            for index, name, t in keep:
                code = PIXEL_TYPES[t][0]
                values = struct.unpack_from(f"<{width}{code}", raw, starts[index])
                out[name][base:base + width] = [float(v) for v in values]
    return ExrImage(width, height, out)
