"""Reduced re-radiation matrices: a bispectral material in a few colour channels.

The idea (after Fichet, Belcour and Barla 2024, "Non-orthogonal reduction for rendering
fluorescent materials in non-spectral engines"; this is our own code from the idea): an
RGB engine carries the light as k numbers c = S_in^T E (the responses of k sensor curves
S_in, e.g. the colour-matching functions), not as a spectrum. To apply a re-radiation
operator P (a Donaldson matrix: exitance = P E), the engine must guess a spectrum with
those responses. Pick k basis spectra B (columns); the only combination of them with
responses c is

    E' = B (S_in^T B)^-1 c                                    (1)

and the colour the material returns, seen through the output sensors S_out, is

    c_out = S_out^T P E' = R c,   R = S_out^T P B (S_in^T B)^-1     (2)

a k_out x k matrix per material. Choices of B:

- B = S_in (the dual basis, "non-orthogonal reduction"): R is independent of the light;
  with S_in = the CIE 1931 CMFs it is the 3x3 of the paper; adding a UV box to S_in (the
  light's UV as a fourth channel) gives the 3x4 "with a UV band".
- B = the light itself cut into k boxes (:func:`light_boxes`): E is then in the span of
  B, (1) returns E exactly and R is exact for that light, for any material: a per-light
  matrix, the reduced form of what the renderer's per-(material, light) pre-integration
  does.

Closed forms the tests check: a grey matrix P = r I reduces to r I for the dual basis;
any material is exact for a light in the span of B.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

# UV_BAND_NM: the UV band added to the colour-matching functions (nm), the light's UV below
# the visible carried as a fourth channel; the same band as the bispectral study's
from catalog.optics.bispectral.study import UV_BAND_NM
from catalog.optics.spectra import GRID_NM

#: Box edges (nm) of the per-light basis: UV + blue, green, red.
LIGHT_BOX_EDGES_NM = (300.0, 490.0, 580.0, 781.0)
LIGHT_BOX_EDGES_UV_NM = (300.0, 380.0, 490.0, 580.0, 781.0)

Operator = Callable[[np.ndarray], np.ndarray]


def box(low_nm: float, high_nm: float, grid_nm: np.ndarray = GRID_NM) -> np.ndarray:
    """1 on [low, high) of the grid, else 0."""
    return ((grid_nm >= low_nm) & (grid_nm < high_nm)).astype(np.float64)


def cmf_sensors(with_uv: bool = False) -> np.ndarray:
    """(L, 3) CIE 1931 CMFs on GRID_NM, or (L, 4) with a UV box as a fourth sensor."""
    from catalog.optics.colorimetry import cmfs  # noqa: PLC0415

    sensors = np.asarray(cmfs(GRID_NM), dtype=np.float64)
    if with_uv:
        sensors = np.hstack([sensors, box(UV_BAND_NM[0], UV_BAND_NM[1] + 1.0)[:, None]])
    return sensors


def light_boxes(irradiance: np.ndarray, with_uv: bool = False) -> np.ndarray:
    """(L, k) the light cut into boxes whose columns sum to the light (E in their span)."""
    edges = LIGHT_BOX_EDGES_UV_NM if with_uv else LIGHT_BOX_EDGES_NM
    light = np.asarray(irradiance, dtype=np.float64)
    return np.stack([light * box(a, b) for a, b in zip(edges[:-1], edges[1:])], axis=1)


def reduce_operator(operator: Operator, sensors_out: np.ndarray, sensors_in: np.ndarray,
                    basis: np.ndarray | None = None, step_nm: float = 1.0) -> np.ndarray:
    """Eq. (2): R = S_out^T P B (S_in^T B)^-1, a (k_out, k) matrix.

    ``operator`` maps a light on GRID_NM to the exitance on GRID_NM (linear);
    ``basis`` defaults to ``sensors_in`` (the dual-basis reduction). Responses are sums
    over the grid times ``step_nm``: apply R to ``sensors_in.T @ E * step_nm``.
    """
    basis = sensors_in if basis is None else np.asarray(basis, dtype=np.float64)
    gram = sensors_in.T @ basis * step_nm  # (k, k): responses of the basis lights
    if not np.all(np.isfinite(gram)):
        raise ValueError("the basis lights' sensor responses are not finite")
    # (L, k): the light with unit response in channel j. The pseudo-inverse equals the
    # inverse when the basis is independent; a light-box basis of a lamp dark in a box
    # (the UV-A lamp has no red) has a zero column, which the pseudo-inverse leaves out.
    upsample = basis @ np.linalg.pinv(gram, rcond=1e-12)
    returned = np.stack([operator(upsample[:, j]) for j in range(upsample.shape[1])], axis=1)
    return sensors_out.T @ returned * step_nm


def apply_reduced(reduced: np.ndarray, sensors_in: np.ndarray, irradiance: np.ndarray,
                  step_nm: float = 1.0) -> np.ndarray:
    """c_out = R (S_in^T E): the reduced material's output responses under a light."""
    return reduced @ (sensors_in.T @ np.asarray(irradiance, dtype=np.float64) * step_nm)


def matrix_operator(matrix) -> Operator:
    """A Donaldson matrix as an operator on GRID_NM lights (the exact rendering of
    :func:`catalog.optics.bispectral.matrix.exact_exitance_on_grid`)."""
    from catalog.optics.bispectral.matrix import exact_exitance_on_grid  # noqa: PLC0415

    return lambda light: exact_exitance_on_grid(matrix, light)


def fichet_reduced(matrix, with_uv: bool = False) -> np.ndarray:
    """The light-independent reduced matrix of a Donaldson matrix: 3x3 (XYZ -> XYZ), or 3x4
    (XYZ + UV -> XYZ) with the UV band."""
    return reduce_operator(matrix_operator(matrix), cmf_sensors(False), cmf_sensors(with_uv))


def per_light_reduced(matrix, irradiance: np.ndarray) -> np.ndarray:
    """The 3x3 reduced with the light's own boxes as basis: exact for that light."""
    sensors = cmf_sensors(False)
    return reduce_operator(matrix_operator(matrix), sensors, sensors,
                           basis=light_boxes(irradiance))
