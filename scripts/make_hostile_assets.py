#!/usr/bin/env python3
"""Writes testdata/hostile/: small glTF, OBJ and MTL assets that must each be refused in one
line (Python 3, standard library only).

    python3 scripts/make_hostile_assets.py      # from the repository's root

Each case is a one-triangle asset broken in one way (issue 52's list): a missing buffer, an
accessor past its buffer view, an index beyond the vertex count, a NaN position, a transform
that overflows to infinity, a texture whose header claims more than the memory budget, and a
buffer, image or `map_Kd` that names a file outside the asset's folder (`../`, an absolute
path, a `file:` URI). `cli/tests/hostile/assets.rs` runs `relight precompute` on every file
named `*.gltf`, `*.glb` and `*.obj` here and requires the one-line refusal the table there
names; the fuzz targets `gltf` and `mtl` take these files as seeds too.
"""

import base64
import json
import math
import os
import struct
import zlib

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "testdata", "hostile")


def triangle_bytes(index=2, y=1.0):
    """Positions (0,0,0), (1,0,0), (0,y,0) as f32, indices 0 1 INDEX as u16 (padded to 4)."""
    positions = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, y, 0)
    return positions + struct.pack("<4H", 0, 1, index, 0)


def data_uri(data, kind="application/octet-stream"):
    return "data:%s;base64,%s" % (kind, base64.b64encode(data).decode())


def triangle(data=None, uv=False):
    """A one-triangle glTF document whose buffer holds `data` (triangle_bytes() by default),
    then six f32 texture coordinates when `uv`."""
    data = triangle_bytes() if data is None else data
    if uv:
        data += struct.pack("<6f", 0, 0, 1, 0, 0, 1)
    views = [
        {"buffer": 0, "byteOffset": 0, "byteLength": 36},
        {"buffer": 0, "byteOffset": 36, "byteLength": 6},
    ]
    accessors = [
        {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
        {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"},
    ]
    primitive = {"attributes": {"POSITION": 0}, "indices": 1}
    doc = {
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [primitive]}],
        "buffers": [{"byteLength": len(data), "uri": data_uri(data)}],
        "bufferViews": views,
        "accessors": accessors,
    }
    if uv:
        views.append({"buffer": 0, "byteOffset": 44, "byteLength": 24})
        accessors.append({"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC2"})
        primitive["attributes"]["TEXCOORD_0"] = 2
        primitive["material"] = 0
        doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
        doc["textures"] = [{"source": 0}]
    return doc


def textured(image):
    doc = triangle(uv=True)
    doc["images"] = [image]
    return doc


def png_claiming(width, height):
    """A PNG whose IHDR claims width x height RGB and whose IDAT holds almost nothing."""

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(b"")) + chunk(b"IEND", b"")


def glb(doc):
    """`doc` as a .glb whose buffer 0 is its BIN chunk."""
    data = base64.b64decode(doc["buffers"][0].pop("uri").split(",", 1)[1])
    data += b"\0" * (-len(data) % 4)
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    body = struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(data), b"BIN\0") + data
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def main():
    os.makedirs(ROOT, exist_ok=True)
    files = {}

    def gltf(name, doc):
        files[name] = (json.dumps(doc, indent=1) + "\n").encode()

    doc = triangle()
    doc["buffers"][0]["uri"] = "missing.bin"
    gltf("missing_buffer.gltf", doc)
    doc = triangle()
    doc["accessors"][0]["count"] = 4
    gltf("accessor_past_its_view.gltf", doc)
    doc = triangle()
    doc["bufferViews"][1]["byteLength"] = 600
    gltf("view_past_its_buffer.gltf", doc)
    gltf("index_beyond_the_vertices.gltf", triangle(triangle_bytes(index=7)))
    gltf("nan_position.gltf", triangle(triangle_bytes(y=math.nan)))
    doc = triangle()
    doc["nodes"] = [{"scale": [3e38, 1, 1], "children": [1]}, {"scale": [3e38, 1, 1], "mesh": 0}]
    gltf("transform_overflows.gltf", doc)
    gltf("texture_beyond_the_budget.gltf", textured({"uri": data_uri(png_claiming(60000, 60000), "image/png")}))
    for name, uri in [("climbs_out", "../x.bin"), ("absolute", "/etc/passwd"), ("file_uri", "file:///etc/passwd")]:
        doc = triangle()
        doc["buffers"][0]["uri"] = uri
        gltf("buffer_%s.gltf" % name, doc)
    gltf("image_climbs_out.gltf", textured({"uri": "../meshes/checker.png"}))
    doc = triangle(triangle_bytes(index=7))
    files["index_beyond_the_vertices.glb"] = glb(doc)
    files["truncated.glb"] = glb(triangle())[:60]
    obj = b"mtllib %s.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl m\nf 1/1 2/2 3/3\n"
    for name, map_kd in [("climbs_out", "../meshes/checker.png"), ("absolute", "/etc/passwd"), ("file_uri", "file:///etc/passwd")]:
        stem = "map_kd_" + name
        files[stem + ".obj"] = obj % stem.encode()
        files[stem + ".mtl"] = b"newmtl m\nKd 1 1 1\nmap_Kd %s\n" % map_kd.encode()
    for name, data in files.items():
        with open(os.path.join(ROOT, name), "wb") as f:
            f.write(data)


if __name__ == "__main__":
    main()
