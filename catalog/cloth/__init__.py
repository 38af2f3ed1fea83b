"""Cloth: a mass-spring curtain on a rod (Provot springs, XPBD, long-range attachments).

Public API (see docs/cloth.md): :class:`ClothParams`, :class:`ClothSimulation`,
:func:`curtain_mesh`, :class:`CurtainMesh`, :func:`export_mesh`, :func:`export_sequence`.
Importing this package imports numpy only; numba and moderngl load with their backends.
"""

from catalog.cloth.mesh import CurtainMesh, curtain_mesh, export_mesh, export_sequence
from catalog.cloth.params import WEAVE_DEFAULTS, ClothParams
from catalog.cloth.simulation import BACKENDS, ClothSimulation

__all__ = ["BACKENDS", "ClothParams", "ClothSimulation", "CurtainMesh", "WEAVE_DEFAULTS",
           "curtain_mesh", "export_mesh", "export_sequence"]
