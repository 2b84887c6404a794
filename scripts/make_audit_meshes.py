#!/usr/bin/env python3
"""Writes the audit's small glTF scenes (docs/audit.md): a 1 m room with a block, where

  degenerate_box.gltf  adds zero-area triangles (a repeated index, three collinear points,
                       a 100 nm high sliver of 3e-8 m^2) and draws every floor triangle twice;
  coplanar_box.gltf    covers the back wall and the floor a second time with overlapping,
                       coplanar quads of the same albedo (z-fighting, double voxel coverage).

Only the standard library; the buffers are embedded as base64 data URIs. Run from anywhere:
  python3 scripts/make_audit_meshes.py   (writes scenes/audit/*.gltf)
"""
import base64
import json
import pathlib
import struct

OUT = pathlib.Path(__file__).resolve().parent.parent / "scenes" / "audit"

WHITE = [0.72, 0.71, 0.68, 1.0]
RED = [0.63, 0.065, 0.05, 1.0]
GREEN = [0.14, 0.45, 0.091, 1.0]


def quad(p0, p1, p2, p3):
    """Two triangles (p0 p1 p2), (p0 p2 p3) as a flat list of points."""
    return [p0, p1, p2, p0, p2, p3]


def room():
    """Walls facing in (open at z = 0), by material: {name: [points]}."""
    s = 1.0
    return {
        "floor": quad((0, 0, 0), (0, 0, s), (s, 0, s), (s, 0, 0)),
        "ceiling": quad((0, s, 0), (s, s, 0), (s, s, s), (0, s, s)),
        "backWall": quad((0, 0, s), (0, s, s), (s, s, s), (s, 0, s)),
        "leftWall": quad((s, 0, 0), (s, 0, s), (s, s, s), (s, s, 0)),
        "rightWall": quad((0, 0, 0), (0, s, 0), (0, s, s), (0, 0, s)),
        "block": quad((0.3, 0.3, 0.5), (0.3, 0.3, 0.8), (0.6, 0.3, 0.8), (0.6, 0.3, 0.5))
        + quad((0.3, 0, 0.5), (0.3, 0.3, 0.5), (0.6, 0.3, 0.5), (0.6, 0, 0.5))
        + quad((0.3, 0, 0.5), (0.3, 0, 0.8), (0.3, 0.3, 0.8), (0.3, 0.3, 0.5))
        + quad((0.6, 0, 0.5), (0.6, 0.3, 0.5), (0.6, 0.3, 0.8), (0.6, 0, 0.8)),
    }


ALBEDO = {"floor": WHITE, "ceiling": WHITE, "backWall": WHITE, "leftWall": RED,
          "rightWall": GREEN, "block": WHITE}


def write_gltf(path, parts):
    """parts: {material: (points, indices or None)}; one mesh primitive per material."""
    blob = bytearray()
    buffer_views, accessors, primitives, materials = [], [], [], []
    for name, (points, indices) in parts.items():
        materials.append({"name": name, "doubleSided": True,
                          "pbrMetallicRoughness": {"baseColorFactor": ALBEDO[name],
                                                   "metallicFactor": 0.0,
                                                   "roughnessFactor": 1.0}})
        offset = len(blob)
        for p in points:
            blob += struct.pack("<3f", *p)
        buffer_views.append({"buffer": 0, "byteOffset": offset, "byteLength": 12 * len(points)})
        lo = [min(p[i] for p in points) for i in range(3)]
        hi = [max(p[i] for p in points) for i in range(3)]
        accessors.append({"bufferView": len(buffer_views) - 1, "componentType": 5126,
                          "count": len(points), "type": "VEC3", "min": lo, "max": hi})
        primitive = {"attributes": {"POSITION": len(accessors) - 1},
                     "material": len(materials) - 1}
        if indices is not None:
            offset = len(blob)
            for i in indices:
                blob += struct.pack("<I", i)
            buffer_views.append({"buffer": 0, "byteOffset": offset,
                                 "byteLength": 4 * len(indices)})
            accessors.append({"bufferView": len(buffer_views) - 1, "componentType": 5125,
                              "count": len(indices), "type": "SCALAR"})
            primitive["indices"] = len(accessors) - 1
        primitives.append(primitive)
    doc = {
        "asset": {"version": "2.0", "generator": "gilab scripts/make_audit_meshes.py"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": primitives}],
        "materials": materials,
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64,"
                     + base64.b64encode(bytes(blob)).decode()}],
        "bufferViews": buffer_views,
        "accessors": accessors,
    }
    path.write_text(json.dumps(doc, indent=1) + "\n")


def degenerate():
    parts = {}
    for name, points in room().items():
        pts = list(points)
        indices = list(range(len(pts)))
        if name == "floor":
            indices += list(range(len(pts)))  # every floor triangle twice
            # A repeated index, three collinear points, and a 100 nm high sliver
            base = len(pts)
            pts += [(0.2, 0, 0.2), (0.8, 0, 0.2), (0.5, 0, 0.2),
                    (0.2, 0, 0.4), (0.8, 0, 0.4), (0.5, 0, 0.4 + 1e-7)]
            indices += [0, 0, 1, base, base + 1, base + 2, base + 3, base + 4, base + 5]
        parts[name] = (pts, indices)
    return parts


def coplanar():
    parts = {}
    for name, points in room().items():
        pts = list(points)
        if name == "backWall":  # a second, overlapping quad on the same plane
            pts += quad((0.1, 0.1, 1.0), (0.1, 0.9, 1.0), (0.9, 0.9, 1.0), (0.9, 0.1, 1.0))
        if name == "floor":  # the floor again, with the opposite winding
            pts += quad((0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1))
        parts[name] = (pts, None)
    return parts


if __name__ == "__main__":
    OUT.mkdir(parents=True, exist_ok=True)
    write_gltf(OUT / "degenerate_box.gltf", degenerate())
    write_gltf(OUT / "coplanar_box.gltf", coplanar())
    print("wrote", OUT / "degenerate_box.gltf", "and", OUT / "coplanar_box.gltf")
