"""BTDF lobes for a fabric known only by its pattern: the nearest catalog fabric.

An imported image or U3M tells the open area (``btdf.direct``) and perhaps the weight; the
scattering lobes of eq. 7 need a gonio measurement. Without one, the lobes are taken from
the built-in (or ``--fabrics``) fabric nearest in openness and weight, so the import is a
plausible cloth and says which fabric lent its lobes.

Transfer (eq. 7): the lobe weights are a = rho e^-tau k; rho is the thread cover, 1 - LD.
Keeping the neighbour's k_d, k_s, tau and g's and setting rho = 1 - LD of the import scales
the lobes with the import's thread cover, as the same yarn woven more or less openly would.
"""

from __future__ import annotations

import math

#: One step of distance: this much open area ...
OPENNESS_SCALE = 0.05
#: ... or a factor of 2 in areal density.
WEIGHT_SCALE_LN = math.log(2.0)


def distance(direct: float, weight_kg_m2: float | None, preset) -> float:
    """Distance of a fabric (open area, optional areal density) to a catalog preset."""
    d = ((direct - preset.btdf.direct) / OPENNESS_SCALE) ** 2
    theirs = preset.table("cloth").get("areal_density_kg_m2")
    if weight_kg_m2 is not None and isinstance(theirs, (int, float)) and theirs > 0:
        d += (math.log(weight_kg_m2 / theirs) / WEIGHT_SCALE_LN) ** 2
    return math.sqrt(d)


def nearest_fabric(direct: float, weight_kg_m2: float | None = None):
    """The catalog preset nearest to (direct, weight); ties go to the first by name."""
    from catalog.presets import list_presets, load_preset  # noqa: PLC0415

    presets = [load_preset(p) for p in list_presets()]
    if not presets:
        from catalog.core.errors import InputError  # noqa: PLC0415

        raise InputError("no catalog fabric to take the lobes from; give --gonio", field="--gonio")
    return min(presets, key=lambda p: (distance(direct, weight_kg_m2, p), p.name))


def lobes_from(preset, direct: float) -> dict:
    """[btdf] for open area ``direct`` with ``preset``'s lobes (rho = 1 - direct)."""
    b = preset.btdf
    table = {"direct": direct, "k_d": b.k_d, "k_s": b.k_s, "tau": b.tau,
             "rho": max(1.0 - direct, 1e-3), "g_diff": b.g_diff, "g_spec": b.g_spec}
    anisotropy = preset.table("btdf").get("anisotropy")
    if isinstance(anisotropy, (int, float)):
        table["anisotropy"] = float(anisotropy)
    return table
