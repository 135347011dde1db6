#!/usr/bin/env python3
"""Per-vertex exitant radiance of a diffuse mesh under an environment map, by Mitsuba 3.

An outside truth for `haarshift relight render`: the geometry, normals and albedo are read
from a haarshift cache (so both see the same vertices in the same order), and everything else
is Mitsuba's (`scalar_rgb`, CPU): its ray intersection, its environment emitter, its `path`
integrator. Nothing of haarshift's light transport is called.

What is estimated, for each chosen vertex v (position p, unit normal n, albedo a):

    L_out(v) = a / pi * integral over the hemisphere of n of L_in(w) (n . w) dw

with `L_in(w)` the radiance arriving at the ray origin o from direction w: the map where the
ray escapes, and where it hits a surface, what Mitsuba's `path` integrator at
`max_depth = B + 1` returns for that ray (light after up to B bounces at other surfaces, each
one-sided diffuse: black on the far side of its shading normal). The direct part (escaping
rays) and the bounced part (hitting rays) are kept apart.

**Sampling.** N = S x S stratified cosine-weighted directions (Malley's method on jittered
strata of the unit square), each paired with one direction sampled from the map's own
importance distribution (`emitter.sample_direction`); the direct part combines the two by
the balance heuristic (Veach 1997), the bounced part uses the cosine samples. The standard
error is the spread of the N per-stratum values over sqrt(N) (conservative for strata).

**The ray origin** (where haarshift's contract and Mitsuba's intersector meet; the rule in its
own terms). eps = 1e-4 x the diagonal of the mesh's bounding box; o = p + eps n. If a triangle
of non-zero area that does not have v as a corner comes within eps / 2 of o (a vertex on a
crease, or where two objects touch), o is moved by eps along m: the sum of the unit vectors
from p to the centroids of v's own triangles, its component along n removed, normalised
(left unmoved when that is shorter than 1e-3). Without the move, a crease vertex's origin
lies in the other face's plane, and Mitsuba, which ignores hits at t = 0, sees through it.

**The map.** haarshift's lat-long map: row i at theta = (i + 1/2) pi / H from +Y, column j at
phi = (j + 1/2) 2 pi / W, direction (sin theta sin phi, cos theta, sin theta cos phi), the
function between pixel centres bilinear (wrapping in phi, clamped at the poles). Mitsuba's
`envmap` puts row r at theta = r pi / (H' - 1) and column c at the direction
(sin theta sin phi', cos theta, -sin theta cos phi'), phi' = 2 pi c / W': this script fills a
Mitsuba bitmap of H + 1 rows and W columns by evaluating haarshift's function at each of its
pixels' directions (`--check-orientation` tests the result against the function at random
directions).

Usage:
    python3 tools/mitsuba/vertex_radiance.py CACHE MAP.hdr -o OUT.npz \
        [--bounces B] [--vertices K] [--strata S] [--seed N]
OUT.npz holds `vertices` (the chosen indices), `direct`, `bounced` (K, 3) and their standard
errors `direct_se`, `bounced_se`, and `contact` (whether each chosen vertex moved).
"""
import argparse
import math
import os
import sys
import tempfile

import numpy as np


def load_mitsuba():
    try:
        import mitsuba as mi
    except ImportError as e:
        raise SystemExit(f"mitsuba is not installed (pip install mitsuba): {e}")
    mi.set_variant("scalar_rgb")
    return mi


# ---- the map, haarshift's convention --------------------------------------------------------


def read_map(path):
    """A lat-long map (H, 2H, 3) of linear radiance from .hdr/.exr (by Mitsuba) or .npy."""
    if path.endswith(".npy"):
        a = np.load(path).astype(np.float64)
    else:
        mi = load_mitsuba()
        a = np.array(mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32,
                                             srgb_gamma=False), dtype=np.float64)
    if a.ndim == 2:
        a = np.repeat(a[:, :, None], 3, axis=2)
    if a.ndim != 3 or a.shape[1] != 2 * a.shape[0] or a.shape[2] not in (1, 3):
        raise SystemExit(f"{path}: not a lat-long map of H x 2H pixels (shape {a.shape})")
    if a.shape[2] == 1:
        a = np.repeat(a, 3, axis=2)
    return a


def map_value(image, d):
    """haarshift's map at unit directions d (M, 3), bilinear between pixel centres."""
    h, w, _ = image.shape
    theta = np.arctan2(np.hypot(d[:, 0], d[:, 2]), d[:, 1])
    phi = np.mod(np.arctan2(d[:, 0], d[:, 2]), 2 * np.pi)
    y = theta / np.pi * h - 0.5
    x = phi / (2 * np.pi) * w - 0.5
    y0 = np.floor(y)
    x0 = np.floor(x)
    fy = (y - y0)[:, None]
    fx = (x - x0)[:, None]
    r0 = np.clip(y0, 0, h - 1).astype(int)
    r1 = np.clip(y0 + 1, 0, h - 1).astype(int)
    c0 = np.mod(x0, w).astype(int)
    c1 = np.mod(x0 + 1, w).astype(int)
    top = image[r0, c0] * (1 - fx) + image[r0, c1] * fx
    bottom = image[r1, c0] * (1 - fx) + image[r1, c1] * fx
    return top * (1 - fy) + bottom * fy


def mitsuba_bitmap(image):
    """Mitsuba's envmap bitmap (H + 1, W, 3) whose pixels carry haarshift's function."""
    h, w, _ = image.shape
    rows = h + 1
    theta = np.arange(rows) * np.pi / (rows - 1)
    phi = 2 * np.pi * np.arange(w) / w
    t, p = np.meshgrid(theta, phi, indexing="ij")
    d = np.stack([np.sin(t) * np.sin(p), np.cos(t), -np.sin(t) * np.cos(p)], axis=-1)
    return map_value(image, d.reshape(-1, 3)).reshape(rows, w, 3)


# ---- the origin rule -----------------------------------------------------------------------


def point_triangle_distance(q, a, b, c):
    """Distance from q (3,) to each triangle (a, b, c), each (T, 3), by the closest point."""
    ab, ac = b - a, c - a
    n = np.cross(ab, ac)
    nn = np.einsum("ij,ij->i", n, n)
    # The plane's foot, then its barycentrics; inside, the distance is to the plane.
    t = np.einsum("ij,ij->i", q - a, n) / nn
    foot = q - t[:, None] * n
    ap = foot - a
    d00, d01, d11 = (np.einsum("ij,ij->i", ab, ab), np.einsum("ij,ij->i", ab, ac),
                     np.einsum("ij,ij->i", ac, ac))
    d20, d21 = np.einsum("ij,ij->i", ap, ab), np.einsum("ij,ij->i", ap, ac)
    den = d00 * d11 - d01 * d01
    v = (d11 * d20 - d01 * d21) / den
    w = (d00 * d21 - d01 * d20) / den
    inside = (v >= 0) & (w >= 0) & (v + w <= 1)
    best = np.where(inside, np.abs(t) * np.sqrt(nn), np.inf)

    def segment(p0, p1):
        e = p1 - p0
        s = np.clip(np.einsum("ij,ij->i", q - p0, e) / np.einsum("ij,ij->i", e, e), 0, 1)
        return np.linalg.norm(q - (p0 + s[:, None] * e), axis=1)

    return np.minimum.reduce([best, segment(a, b), segment(b, c), segment(c, a)])


def ray_origins(positions, normals, triangles, chosen):
    """The origin rule of the module docs for the chosen vertices: (origins, contact)."""
    eps = 1e-4 * np.linalg.norm(positions.max(axis=0) - positions.min(axis=0))
    corners = positions[triangles]
    area2 = np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]),
                           axis=1)
    solid = area2 > 0
    origins, contact = [], []
    for v in chosen:
        p, n = positions[v], normals[v]
        o = p + eps * n
        own = np.any(triangles == v, axis=1)
        others = solid & ~own
        dist = point_triangle_distance(o, *(corners[others][:, k] for k in range(3)))
        touching = dist.size > 0 and dist.min() < eps / 2
        if touching:
            centroids = corners[own].mean(axis=1)
            u = centroids - p
            lengths = np.linalg.norm(u, axis=1)
            total = (u[lengths > 0] / lengths[lengths > 0, None]).sum(axis=0)
            tangent = total - np.dot(total, n) * n
            if np.linalg.norm(tangent) >= 1e-3:
                o = o + eps * tangent / np.linalg.norm(tangent)
        origins.append(o)
        contact.append(touching)
    return np.array(origins), np.array(contact)


# ---- the scene in Mitsuba ------------------------------------------------------------------


def write_ply(path, positions, normals, triangles, albedo):
    """A binary PLY of float positions, normals and colours (Mitsuba's `vertex_color`)."""
    v = len(positions)
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {v}\n"
        "property float x\nproperty float y\nproperty float z\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        "property float r\nproperty float g\nproperty float b\n"
        f"element face {len(triangles)}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    rows = np.hstack([positions, normals, albedo]).astype("<f4")
    faces = np.zeros(len(triangles), dtype=[("n", "u1"), ("i", "<i4", 3)])
    faces["n"] = 3
    faces["i"] = triangles
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(rows.tobytes())
        f.write(faces.tobytes())


def build_scene(mi, mesh, image, bounces):
    positions, normals, triangles, albedo = mesh
    with tempfile.TemporaryDirectory() as folder:
        ply = os.path.join(folder, "mesh.ply")
        write_ply(ply, positions, normals, triangles, albedo)
        scene = mi.load_dict({
            "type": "scene",
            "mesh": {
                "type": "ply", "filename": ply, "face_normals": False,
                "bsdf": {"type": "diffuse",
                         "reflectance": {"type": "mesh_attribute", "name": "vertex_color"}},
            },
            "light": {"type": "envmap",
                      "bitmap": mi.Bitmap(mitsuba_bitmap(image).astype(np.float32))},
        })
    integrator = mi.load_dict({"type": "path", "max_depth": bounces + 1})
    return scene, integrator


def emitter_values(mi, scene, directions):
    """The RGB radiance (M, 3) Mitsuba's environment sends towards unit directions (M, 3)."""
    emitter = scene.environment()
    out = np.empty((len(directions), 3))
    for k, d in enumerate(directions):
        si = mi.SurfaceInteraction3f()
        si.wi = mi.Vector3f(*(-d))
        out[k] = np.array(emitter.eval(si))
    return out


def check_orientation(mi, scene, image, count=2000, seed=1):
    """The largest relative difference between Mitsuba's emitter and haarshift's function."""
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(count, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    ours = map_value(image, d).mean(axis=1)
    theirs = emitter_values(mi, scene, d).mean(axis=1)
    return float(np.max(np.abs(theirs - ours)) / np.max(np.abs(ours)))


def radiance(mi, scene, integrator, mesh, origins, chosen, strata, seed):
    """Direct and bounced radiance of the chosen vertices, with standard errors."""
    positions, normals, triangles, albedo = mesh
    emitter = scene.environment()
    sampler = mi.load_dict({"type": "independent"})
    rng = np.random.default_rng(seed)
    n_dirs = strata * strata
    out = {k: np.zeros((len(chosen), 3)) for k in ("direct", "bounced", "direct_se", "bounced_se")}
    for row, (v, o) in enumerate(zip(chosen, origins)):
        sampler.seed(seed * 1_000_003 + int(v))
        n = normals[v]
        helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        t = np.cross(n, helper)
        t /= np.linalg.norm(t)
        s = np.cross(n, t)
        it = mi.Interaction3f()
        it.p = mi.Point3f(*o)
        jitter = rng.random((n_dirs, 2))
        cells = np.stack(np.meshgrid(np.arange(strata), np.arange(strata), indexing="ij"),
                         axis=-1).reshape(-1, 2)
        uv = (cells + jitter) / strata
        r, a = np.sqrt(uv[:, 0]), 2 * np.pi * uv[:, 1]
        local = np.stack([r * np.cos(a), r * np.sin(a), np.sqrt(np.maximum(0, 1 - uv[:, 0]))], 1)
        dirs = local[:, :1] * t + local[:, 1:2] * s + local[:, 2:] * n
        light = rng.random((n_dirs, 2))
        direct = np.zeros((n_dirs, 3))
        bounced = np.zeros((n_dirs, 3))
        origin = mi.Point3f(*o)
        for k in range(n_dirs):
            d = dirs[k]
            cos = float(np.dot(n, d))
            ray = mi.Ray3f(origin, mi.Vector3f(*d))
            if cos > 0:
                si = scene.ray_intersect(ray)
                if not si.is_valid():
                    q = mi.SurfaceInteraction3f()
                    q.wi = mi.Vector3f(*(-d))
                    ds = mi.DirectionSample3f()
                    ds.d = mi.Vector3f(*d)
                    pe = float(emitter.pdf_direction(it, ds))
                    pb = cos / math.pi
                    direct[k] += np.array(emitter.eval(q)) * pb / (pb + pe)
                else:
                    value, _, _ = integrator.sample(scene, sampler, ray)
                    bounced[k] = np.array(value)
            ds, weight = emitter.sample_direction(it, mi.Point2f(*light[k]), False)
            d = np.array(ds.d)
            cos = float(np.dot(n, d))
            if cos > 0 and ds.pdf > 0:
                if not scene.ray_test(mi.Ray3f(origin, ds.d)):
                    pe = float(ds.pdf)
                    value = np.array(weight) * pe  # the map's radiance in direction d
                    direct[k] += value * (cos / math.pi) / (cos / math.pi + pe)
        a_v = albedo[v]
        for name, values in (("direct", direct), ("bounced", bounced)):
            out[name][row] = a_v * values.mean(axis=0)
            out[name + "_se"][row] = a_v * values.std(axis=0, ddof=1) / math.sqrt(n_dirs)
    return out


def read_cache(path):
    from haarshift import relight
    cache = relight.Cache.read(path)
    return (np.asarray(cache.positions, dtype=np.float64),
            np.asarray(cache.normals, dtype=np.float64),
            np.asarray(cache.triangles, dtype=np.int64),
            np.asarray(cache.albedo, dtype=np.float64))


def choose(count, total, seed):
    """`count` distinct vertices of `total`, in increasing order (all when count >= total)."""
    if count >= total:
        return np.arange(total)
    return np.sort(np.random.default_rng(seed).choice(total, size=count, replace=False))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("cache", help="a haarshift cache (`haarshift relight precompute -o`)")
    ap.add_argument("map", help="a lat-long map, H x 2H (.hdr, .exr or .npy), haarshift's axes")
    ap.add_argument("-o", "--output", required=True, help="the .npz to write")
    ap.add_argument("--bounces", type=int, default=0)
    ap.add_argument("--vertices", type=int, default=300, help="how many vertices (at random)")
    ap.add_argument("--strata", type=int, default=128, help="S: S x S directions a vertex")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--mirror", action="store_true",
                    help="mirror the map left to right (a control that must disagree)")
    ap.add_argument("--force", action="store_true", help="replace an existing output")
    args = ap.parse_args(argv)
    if os.path.exists(args.output) and not args.force:
        raise SystemExit(f"{args.output}: exists (pass --force to replace it)")
    mi = load_mitsuba()
    mesh = read_cache(args.cache)
    image = read_map(args.map)
    if args.mirror:
        image = image[:, ::-1].copy()
    scene, integrator = build_scene(mi, mesh, image, args.bounces)
    orientation = check_orientation(mi, scene, image)
    chosen = choose(args.vertices, len(mesh[0]), args.seed)
    origins, contact = ray_origins(mesh[0], mesh[1], mesh[2], chosen)
    out = radiance(mi, scene, integrator, mesh, origins, chosen, args.strata, args.seed)
    folder = os.path.dirname(os.path.abspath(args.output))
    with tempfile.NamedTemporaryFile(dir=folder, suffix=".npz", delete=False) as f:
        np.savez(f, vertices=chosen, contact=contact, orientation_error=orientation, **out)
    os.replace(f.name, args.output)
    print(f"{args.output}: {len(chosen)} vertices, {args.strata ** 2} directions each, "
          f"{int(contact.sum())} moved off a crease or contact, map orientation within "
          f"{orientation:.2e}")


if __name__ == "__main__":
    sys.exit(main())
