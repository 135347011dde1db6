"""All-frequency relighting from Python.

`precompute` turns a mesh or scene file into a `Cache` (every vertex's sparse Haar transport,
what `haarshift relight precompute` writes), `Cache.read` reads one, and a `Shader` built from
a cache with `relight render`'s options gives every vertex's outgoing radiance frame after
frame. `scene` relights a dynamic scene file, by n-function product integrals on sparse Haar
coefficients ("haar") or by ray casting ("reference"). See `haarshift relight render --help`
and `haarshift relight scene --help`.
"""
from ._native import relight as _relight

Cache = _relight.Cache
Shader = _relight.Shader
precompute = _relight.precompute
scene = _relight.scene

__all__ = ["Cache", "Shader", "precompute", "scene"]
