"""OpenEXR files for the report's tests, with numpy: a writer (the fixture's EXR outputs and
references) and an independent reader (the expected linear values of the inspector's check).
Neither shares code with scripts/gilab_report/exr.py (OpenImageIO), whose reader the test checks.

Single-part scanline files, compression NONE or ZIP (16 lines per chunk), channels FLOAT or
HALF, as OpenEXR 2 defines them: the channel list sorted by name, each line holding every
channel's values in turn; ZIP splits the bytes into two halves (even, odd positions), stores
differences of consecutive bytes + 128, and deflates the result.
"""
from __future__ import annotations

import struct
import zlib

import numpy as np

NONE, ZIP = 0, 3
FLOAT, HALF = 2, 1
LINES = {NONE: 1, ZIP: 16}
DTYPES = {FLOAT: np.dtype("<f4"), HALF: np.dtype("<f2")}


def _attr(name: str, kind: str, value: bytes) -> bytes:
    return (name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value))
            + value)


def _zip(raw: bytes) -> bytes:
    data = np.frombuffer(raw, np.uint8)
    split = np.concatenate([data[0::2], data[1::2]]).astype(np.int16)
    diff = split.copy()
    diff[1:] = (split[1:] - split[:-1] + 128) & 0xFF
    packed = zlib.compress(diff.astype(np.uint8).tobytes(), 6)
    return packed if len(packed) < len(raw) else raw


def write_exr(path: str, layers: dict[str, np.ndarray], compression: int = ZIP,
              half: tuple[str, ...] = ()) -> None:
    """layers: name ('' for the unnamed R, G, B) -> (height, width, 3) array; the layers named
    in `half` are written as HALF, the others as FLOAT."""
    height, width = next(iter(layers.values())).shape[:2]
    channels = {}
    for layer, image in layers.items():
        for i, c in enumerate("RGB"):
            name = f"{layer}.{c}" if layer else c
            channels[name] = (np.ascontiguousarray(image[..., i]), HALF if layer in half
                              else FLOAT)
    names = sorted(channels)
    chlist = b"".join(n.encode() + b"\0" + struct.pack("<iBBBBii", channels[n][1], 0, 0, 0, 0,
                                                           1, 1) for n in names) + b"\0"
    box = struct.pack("<4i", 0, 0, width - 1, height - 1)
    header = (b"\x76\x2f\x31\x01" + struct.pack("<I", 2)
              + _attr("channels", "chlist", chlist)
              + _attr("compression", "compression", bytes([compression]))
              + _attr("dataWindow", "box2i", box) + _attr("displayWindow", "box2i", box)
              + _attr("lineOrder", "lineOrder", b"\0")
              + _attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
              + _attr("screenWindowCenter", "v2f", struct.pack("<2f", 0.0, 0.0))
              + _attr("screenWindowWidth", "float", struct.pack("<f", 1.0)) + b"\0")
    lines = LINES[compression]
    chunks = []
    for y in range(0, height, lines):
        raw = b"".join(channels[n][0][row].astype(DTYPES[channels[n][1]]).tobytes()
                       for row in range(y, min(y + lines, height)) for n in names)
        data = _zip(raw) if compression == ZIP else raw
        chunks.append(struct.pack("<ii", y, len(data)) + data)
    offsets, at = [], len(header) + 8 * len(chunks)
    for chunk in chunks:
        offsets.append(at)
        at += len(chunk)
    with open(path, "wb") as f:
        f.write(header + struct.pack(f"<{len(offsets)}Q", *offsets) + b"".join(chunks))


def read_exr(path: str) -> dict[str, np.ndarray]:
    """Channel name -> (height, width) float64 array, for files write_exr writes."""
    with open(path, "rb") as f:
        data = f.read()
    assert data[:4] == b"\x76\x2f\x31\x01", f"{path}: not an OpenEXR file"
    pos, attrs = 8, {}
    while data[pos] != 0:
        name_end = data.index(b"\0", pos)
        kind_end = data.index(b"\0", name_end + 1)
        size = struct.unpack_from("<i", data, kind_end + 1)[0]
        attrs[data[pos:name_end].decode()] = data[kind_end + 5:kind_end + 5 + size]
        pos = kind_end + 5 + size
    pos += 1
    channels, raw = [], attrs["channels"]
    at = 0
    while raw[at] != 0:
        end = raw.index(b"\0", at)
        channels.append((raw[at:end].decode(), DTYPES[struct.unpack_from("<i", raw, end + 1)[0]]))
        at = end + 17
    compression = attrs["compression"][0]
    x0, y0, x1, y1 = struct.unpack("<4i", attrs["dataWindow"])
    width, height = x1 - x0 + 1, y1 - y0 + 1
    lines = LINES[compression]
    count = -(-height // lines)
    offsets = struct.unpack_from(f"<{count}Q", data, pos)
    out = {name: np.zeros((height, width)) for name, _ in channels}
    line_bytes = sum(d.itemsize for _, d in channels) * width
    for offset in offsets:
        y, size = struct.unpack_from("<ii", data, offset)
        rows = min(lines, height - y)
        chunk = data[offset + 8:offset + 8 + size]
        if compression == ZIP and size < rows * line_bytes:
            diff = np.frombuffer(zlib.decompress(chunk), np.uint8).astype(np.int64)
            split = np.cumsum(diff - 128) + 128  # undo the differences (mod 256 below)
            split = (split & 0xFF).astype(np.uint8)
            half = (len(split) + 1) // 2
            merged = np.empty_like(split)
            merged[0::2], merged[1::2] = split[:half], split[half:]
            chunk = merged.tobytes()
        at = 0
        for row in range(rows):
            for name, dtype in channels:
                n = dtype.itemsize * width
                out[name][y + row] = np.frombuffer(chunk[at:at + n], dtype).astype(np.float64)
                at += n
    return out


def layer_rgb(channels: dict[str, np.ndarray], layer: str = "final") -> np.ndarray:
    """(height, width, 3) of '<layer>.R/G/B', else of R, G, B."""
    for prefix in (f"{layer}.", ""):
        if all(prefix + c in channels for c in "RGB"):
            return np.stack([channels[prefix + c] for c in "RGB"], axis=-1)
    raise KeyError(layer)
