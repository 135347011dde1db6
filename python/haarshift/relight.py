"""All-frequency relighting from Python.

`precompute` turns a mesh or scene file into a `Cache` (every vertex's sparse Haar transport,
what `haarshift relight precompute` writes, with every one of its flags as a keyword of the
same name: `--visibility-samples 2` is `visibility_samples=2`), or with `shard="i/n"` one
shard of it into a file, so that Dask (`client.map`) or Ray workers share the work; `merge` joins the shards into
the cache an unsharded run makes, byte for byte. `Cache.read` reads a cache, and a `Shader` built from
a cache with `relight render`'s options gives every vertex's outgoing radiance frame after
frame. `scene` relights a dynamic scene file, by n-function product integrals on sparse Haar
coefficients ("haar") or by ray casting ("reference"). See `haarshift relight render --help`
and `haarshift relight scene --help`.
"""
from ._native import relight as _relight

Cache = _relight.Cache
Shader = _relight.Shader
merge = _relight.merge
precompute = _relight.precompute
scene = _relight.scene

__all__ = ["Cache", "Shader", "merge", "precompute", "scene"]
