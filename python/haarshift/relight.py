"""All-frequency relighting of dynamic scene files: `scene` gives every vertex's outgoing
radiance, by n-function product integrals on sparse Haar coefficients ("haar") or by ray
casting ("reference"). See `haarshift relight scene --help` for the scene file's format.
"""
from ._native import relight as _relight

scene = _relight.scene

__all__ = ["scene"]
