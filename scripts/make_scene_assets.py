#!/usr/bin/env python3
"""Writes the glTF, OBJ + MTL and PLY test assets of testdata/meshes/ (Python 3, stdlib only).

    python3 scripts/make_scene_assets.py      # from the repository's root

* checker.png: a 4 x 4 RGB checkerboard (orange and cream texels), 8-bit sRGB.
* bunny_boxes.glb / bunny_boxes.gltf + bunny_boxes.bin: the bunny of bunny.obj (positions and
  triangles unchanged, no normals) textured with checker.png by a planar projection
  (u = (x - x0) / (x1 - x0), v = 1 - (y - y0) / (y1 - y0), glTF's v down; sampler REPEAT,
  LINEAR), a red box on its left and a green one on its right (24 vertices each, one quad a
  face, material colours only). Identity transforms. The .glb embeds the texture in a buffer
  view; the .gltf names bunny_boxes.bin and checker.png beside it.
* bunny_boxes.obj + bunny_boxes.mtl: the same vertices in the same order (vt = (u, 1 - v),
  OBJ's v up), map_Kd checker.png for the bunny, Kd for the boxes.
* bunny_boxes_colours.ply: the same vertices and triangles with float red green blue: the
  albedo each vertex gets, computed here independently of haarshift (base colour factor x the
  texture, decoded from sRGB by the IEC 61966-2-1 formula, sampled bilinearly with REPEAT at
  texel centres (i + 0.5) / w): the Must-show test's second scene.
* hierarchy.gltf: one box (24 vertices, stored normals, buffer as a data: URI) under a
  three-level hierarchy (root: translate (1, 2, 3) and 90 degrees about Y; middle: scale
  (2, 1, 0.5); leaf: translate (0, 1, 0)) and again under a mirrored root (matrix: x -> -x,
  then translate (-3, 0, 0)).
"""

import base64
import json
import math
import os
import struct
import zlib

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "testdata", "meshes")

ORANGE, CREAM = (230, 120, 40), (240, 230, 200)
CHECKER = [[ORANGE if (i + j) % 2 == 0 else CREAM for i in range(4)] for j in range(4)]
RED, GREEN = (0.8, 0.1, 0.1), (0.1, 0.7, 0.15)


def png(rows):
    """An 8-bit RGB PNG of rows of (r, g, b)."""
    raw = b"".join(b"\0" + bytes(c for px in row for c in px) for row in rows)

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    header = struct.pack(">IIBBBBB", len(rows[0]), len(rows), 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")


def srgb_to_linear(c):
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def sample(u, v):
    """The checker's linear RGB at (u, v): bilinear between texel centres, REPEAT."""
    w = h = 4
    x, y = u * w - 0.5, v * h - 0.5
    i, j = math.floor(x), math.floor(y)
    fx, fy = x - i, y - j

    def texel(i, j):
        return [srgb_to_linear(c / 255.0) for c in CHECKER[j % h][i % w]]

    a, b, c, d = texel(i, j), texel(i + 1, j), texel(i, j + 1), texel(i + 1, j + 1)
    return [(a[k] * (1 - fx) + b[k] * fx) * (1 - fy) + (c[k] * (1 - fx) + d[k] * fx) * fy for k in range(3)]


def f32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


def read_obj(path):
    positions, triangles = [], []
    for line in open(path):
        words = line.split()
        if words and words[0] == "v":
            positions.append([f32(float(w)) for w in words[1:4]])
        elif words and words[0] == "f":
            triangles.append([int(w.split("/")[0]) - 1 for w in words[1:4]])
    return positions, triangles


def box(lo, hi):
    """24 vertices (4 a face: +X, -X, +Y, -Y, +Z, -Z), 12 counter-clockwise triangles, normals."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    faces = [
        ([x1, y0, z1], [x1, y0, z0], [x1, y1, z0], [x1, y1, z1], [1, 0, 0]),
        ([x0, y0, z0], [x0, y0, z1], [x0, y1, z1], [x0, y1, z0], [-1, 0, 0]),
        ([x0, y1, z1], [x1, y1, z1], [x1, y1, z0], [x0, y1, z0], [0, 1, 0]),
        ([x0, y0, z0], [x1, y0, z0], [x1, y0, z1], [x0, y0, z1], [0, -1, 0]),
        ([x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1], [0, 0, 1]),
        ([x1, y0, z0], [x0, y0, z0], [x0, y1, z0], [x1, y1, z0], [0, 0, -1]),
    ]
    positions, normals, triangles = [], [], []
    for k, (a, b, c, d, n) in enumerate(faces):
        positions += [a, b, c, d]
        normals += [n] * 4
        triangles += [[4 * k, 4 * k + 1, 4 * k + 2], [4 * k, 4 * k + 2, 4 * k + 3]]
    return positions, normals, triangles


class Buffer:
    """A glTF binary buffer with its views and accessors."""

    def __init__(self):
        self.data, self.views, self.accessors = bytearray(), [], []

    def view(self, blob):
        while len(self.data) % 4:
            self.data += b"\0"
        self.views.append({"buffer": 0, "byteOffset": len(self.data), "byteLength": len(blob)})
        self.data += blob
        return len(self.views) - 1

    def accessor(self, rows, kind, component):
        fmt = {5126: "f", 5123: "H"}[component]
        flat = [x for r in rows for x in (r if isinstance(r, (list, tuple)) else [r])]
        acc = {"bufferView": self.view(struct.pack("<%d%s" % (len(flat), fmt), *flat)), "componentType": component, "count": len(rows), "type": kind}
        if kind == "VEC3" and component == 5126:
            acc["min"] = [min(r[k] for r in rows) for k in range(3)]
            acc["max"] = [max(r[k] for r in rows) for k in range(3)]
        self.accessors.append(acc)
        return len(self.accessors) - 1


def material(colour, texture=None):
    pbr = {"baseColorFactor": list(colour) + [1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}
    if texture is not None:
        pbr["baseColorTexture"] = {"index": texture}
    return {"pbrMetallicRoughness": pbr}


def bunny_boxes():
    bunny, bunny_tris = read_obj(os.path.join(ROOT, "bunny.obj"))
    x0, x1 = min(p[0] for p in bunny), max(p[0] for p in bunny)
    y0, y1 = min(p[1] for p in bunny), max(p[1] for p in bunny)
    uvs = [[f32((p[0] - x0) / (x1 - x0)), f32(1 - (p[1] - y0) / (y1 - y0))] for p in bunny]
    red, _, red_tris = box([-8, 0, -2], [-6, 6, 2])
    green, _, green_tris = box([6, 0, -2], [8, 6, 2])
    checker = png(CHECKER)

    def document(embed_image):
        buf = Buffer()
        prims = []
        for positions, tris, mat, uv in [(bunny, bunny_tris, 0, uvs), (red, red_tris, 1, None), (green, green_tris, 2, None)]:
            attributes = {"POSITION": buf.accessor(positions, "VEC3", 5126)}
            if uv is not None:
                attributes["TEXCOORD_0"] = buf.accessor(uv, "VEC2", 5126)
            indices = buf.accessor([i for t in tris for i in t], "SCALAR", 5123)
            prims.append({"attributes": attributes, "indices": indices, "material": mat})
        image = {"bufferView": buf.view(checker), "mimeType": "image/png"} if embed_image else {"uri": "checker.png"}
        gltf = {
            "asset": {"version": "2.0", "generator": "haarshift scripts/make_scene_assets.py"},
            "scene": 0,
            "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0, "name": "bunny and boxes"}],
            "meshes": [{"primitives": prims}],
            "materials": [material((1.0, 1.0, 1.0), 0), material(RED), material(GREEN)],
            "textures": [{"sampler": 0, "source": 0}],
            "samplers": [{"magFilter": 9729, "minFilter": 9729, "wrapS": 10497, "wrapT": 10497}],
            "images": [image],
            "bufferViews": buf.views,
            "accessors": buf.accessors,
        }
        while len(buf.data) % 4:
            buf.data += b"\0"
        return gltf, bytes(buf.data)

    gltf, binary = document(True)
    gltf["buffers"] = [{"byteLength": len(binary)}]
    text = json.dumps(gltf, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    glb = struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(text) + 8 + len(binary))
    glb += struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(binary), b"BIN\0") + binary
    write("bunny_boxes.glb", glb)

    gltf, binary = document(False)
    gltf["buffers"] = [{"byteLength": len(binary), "uri": "bunny_boxes.bin"}]
    write("bunny_boxes.gltf", (json.dumps(gltf, indent=1) + "\n").encode())
    write("bunny_boxes.bin", binary)
    write("checker.png", checker)

    # OBJ + MTL: the same vertex order (the bunny's, then the red box's, then the green box's).
    n_bunny, n_red = len(bunny), len(red)
    lines = ["# bunny_boxes.glb as OBJ + MTL (scripts/make_scene_assets.py)", "mtllib bunny_boxes.mtl"]
    lines += ["v %.9g %.9g %.9g" % tuple(p) for p in bunny + red + green]
    lines += ["vt %.9g %.9g" % (u, 1.0 - v) for u, v in uvs]
    lines.append("usemtl checker")
    lines += ["f %d/%d %d/%d %d/%d" % sum(((i + 1, i + 1) for i in t), ()) for t in bunny_tris]
    lines.append("usemtl red")
    lines += ["f %d %d %d" % tuple(i + 1 + n_bunny for i in t) for t in red_tris]
    lines.append("usemtl green")
    lines += ["f %d %d %d" % tuple(i + 1 + n_bunny + n_red for i in t) for t in green_tris]
    write("bunny_boxes.obj", ("\n".join(lines) + "\n").encode())
    mtl = ["# bunny_boxes.obj's materials", "newmtl checker", "Kd 1 1 1", "map_Kd checker.png"]
    for name, c in [("red", RED), ("green", GREEN)]:
        mtl += ["newmtl " + name, "Kd %r %r %r" % c]
    write("bunny_boxes.mtl", ("\n".join(mtl) + "\n").encode())

    # The same vertices with the colours computed here, as float PLY colours (linear).
    colours = [sample(u, v) for u, v in uvs] + [list(RED)] * n_red + [list(GREEN)] * len(green)
    positions = bunny + red + green
    tris = bunny_tris + [[i + n_bunny for i in t] for t in red_tris] + [[i + n_bunny + n_red for i in t] for t in green_tris]
    header = (
        "ply\nformat binary_little_endian 1.0\ncomment bunny_boxes.glb's vertices with its albedo (scripts/make_scene_assets.py)\n"
        "element vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
        "property float red\nproperty float green\nproperty float blue\n"
        "element face %d\nproperty list uchar int vertex_indices\nend_header\n" % (len(positions), len(tris))
    )
    body = b"".join(struct.pack("<6f", *(p + c)) for p, c in zip(positions, colours))
    body += b"".join(struct.pack("<B3i", 3, *t) for t in tris)
    write("bunny_boxes_colours.ply", header.encode() + body)


def hierarchy():
    positions, normals, tris = box([-0.5, -0.5, -0.5], [0.5, 0.5, 0.5])
    buf = Buffer()
    attributes = {"POSITION": buf.accessor(positions, "VEC3", 5126), "NORMAL": buf.accessor(normals, "VEC3", 5126)}
    indices = buf.accessor([i for t in tris for i in t], "SCALAR", 5123)
    s = math.sqrt(0.5)
    gltf = {
        "asset": {"version": "2.0", "generator": "haarshift scripts/make_scene_assets.py"},
        "scene": 0,
        "scenes": [{"nodes": [0, 3]}],
        "nodes": [
            {"name": "root", "translation": [1, 2, 3], "rotation": [0, s, 0, s], "children": [1]},
            {"name": "middle", "scale": [2, 1, 0.5], "children": [2]},
            {"name": "leaf", "translation": [0, 1, 0], "mesh": 0},
            {"name": "mirrored", "matrix": [-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -3, 0, 0, 1], "mesh": 0},
        ],
        "meshes": [{"primitives": [{"attributes": attributes, "indices": indices}]}],
        "bufferViews": buf.views,
        "accessors": buf.accessors,
        "buffers": [{"byteLength": len(buf.data), "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(buf.data)).decode()}],
    }
    write("hierarchy.gltf", (json.dumps(gltf, indent=1) + "\n").encode())


def write(name, data):
    with open(os.path.join(ROOT, name), "wb") as f:
        f.write(data)
    print("%s: %d bytes" % (name, len(data)))


if __name__ == "__main__":
    bunny_boxes()
    hierarchy()
