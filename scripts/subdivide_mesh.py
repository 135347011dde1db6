#!/usr/bin/env python3
"""Midpoint-subdivides a triangle mesh LEVELS times (each triangle into four) and writes it as
a binary PLY with normals: the dense truth mesh of scripts/refine.sh.

    python3 scripts/subdivide_mesh.py IN.ply LEVELS OUT.ply

The input's normals are its area-weighted vertex normals (what haarshift computes for a file
without normals); a new vertex gets the normalised sum of its edge's endpoints' normals, the
rule `relight precompute --refine` follows, so the subdivided surface and its shading are the
limit that refinement approaches. Written independently of haarshift's splitting (no
bisection, no shared code), so it checks it rather than repeats it. numpy only.
"""
import sys

import numpy as np


def read_ply(path):
    """Positions (V, 3) and triangles (T, 3) of a binary little-endian PLY of float x y z and
    a uchar-counted int list of vertex indices (what testdata/meshes/bunny.ply is)."""
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    if "format binary_little_endian 1.0" not in header:
        sys.exit(f"{path}: only binary little-endian PLY is read here")
    props = [h.split()[-1] for h in header if h.startswith("property float")]
    if props[:3] != ["x", "y", "z"] or len(props) != 3:
        sys.exit(f"{path}: vertices must be float x y z alone")
    count = {h.split()[1]: int(h.split()[2]) for h in header if h.startswith("element")}
    v, f = count["vertex"], count["face"]
    positions = np.frombuffer(data, "<f4", 3 * v, end).reshape(v, 3).astype(np.float64)
    offset, triangles = end + 12 * v, []
    for _ in range(f):
        n = data[offset]
        idx = np.frombuffer(data, "<i4", n, offset + 1)
        offset += 1 + 4 * n
        triangles += [[idx[0], idx[k], idx[k + 1]] for k in range(1, n - 1)]
    return positions, np.array(triangles, dtype=np.int64)


def unit(n):
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.where(length > 0, n / np.where(length > 0, length, 1), 0)


def area_weighted_normals(p, t):
    face = np.cross(p[t[:, 1]] - p[t[:, 0]], p[t[:, 2]] - p[t[:, 0]])
    n = np.zeros_like(p)
    for k in range(3):
        np.add.at(n, t[:, k], face)
    return unit(n)


def subdivide(p, n, t):
    """One level: a midpoint per edge (shared by its triangles), four triangles per one."""
    edges = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    unique, inverse = np.unique(edges, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    mid = len(p) + inverse.reshape(3, -1).T  # (T, 3): midpoints of ab, bc, ca
    p = np.concatenate([p, 0.5 * (p[unique[:, 0]] + p[unique[:, 1]])])
    n = np.concatenate([n, unit(n[unique[:, 0]] + n[unique[:, 1]])])
    a, b, c = t.T
    ab, bc, ca = mid.T
    t = np.concatenate(
        [np.stack(x, axis=1) for x in ([a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca])]
    )
    return p, n, t


def write_ply(path, p, n, t):
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"comment midpoint-subdivided by scripts/subdivide_mesh.py\nelement vertex {len(p)}\n"
        "property double x\nproperty double y\nproperty double z\n"
        "property double nx\nproperty double ny\nproperty double nz\n"
        f"element face {len(t)}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    faces = np.zeros(len(t), dtype=[("n", "u1"), ("i", "<i4", 3)])
    faces["n"], faces["i"] = 3, t
    with open(path, "wb") as out:
        out.write(header.encode("ascii"))
        out.write(np.concatenate([p, n], axis=1).astype("<f8").tobytes())
        out.write(faces.tobytes())


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    p, t = read_ply(sys.argv[1])
    n = area_weighted_normals(p, t)
    for _ in range(int(sys.argv[2])):
        p, n, t = subdivide(p, n, t)
    write_ply(sys.argv[3], p, n, t)
    print(f"{sys.argv[3]}: {len(p)} vertices, {len(t)} triangles", file=sys.stderr)


if __name__ == "__main__":
    main()
