"""Gonio transmittance data: the CSV of formats.md, the paper's angle convention, the
OGM-3 measurement grid and the paper's 79-point subset.

Angle convention (model.md section 1, formats.md), all in degrees:

- camera elevation 90 = along the normal on the viewer side (+Z): the view direction
  has polar angle ``90 - camera_elevation`` from +Z and azimuth ``camera_azimuth``;
- light elevation 180 = along the normal on the far side (-Z): the direction *to the
  light* has polar angle ``180 - light_elevation`` from -Z and azimuth ``light_azimuth``;
- theta: between the light's direction of travel (minus the direction to the light)
  and the view direction; theta = 0 is straight through.
- the sample's weft runs along x (azimuth 0), its warp along y (azimuth 90): the
  renderer's tangent t and bitangent b.

The OGM-3 grid (4800 points): "X-Y in N steps" read as N values from X to Y inclusive,
the only reading that makes the paper's count: camera elevation 10-90 in 40 values
(step 80/39 deg) x camera azimuth {0, 180} x light elevation 130-180 in 5 values
(step 12.5 deg) x light azimuth 0-330 in 12 values (step 30 deg) = 40 * 2 * 5 * 12.
The paper's fit used 79 of them: light elevation 180, light azimuth 0, camera azimuth
0 and 180, all 40 camera elevations, minus the duplicate at camera elevation 90 (the
same direction seen from both azimuths).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property
from pathlib import Path

import numpy as np

from catalog.optics.btdf import STRAIGHT_THROUGH_DEG, is_straight_through, one_minus_cos_between
from catalog.core.errors import InputError

ANGLE_COLUMNS = ("light_elevation_deg", "light_azimuth_deg", "camera_elevation_deg",
                 "camera_azimuth_deg")
GONIO_COLUMNS = ANGLE_COLUMNS + ("transmittance",)
RGB_COLUMNS = ("r", "g", "b")

#: Allowed ranges (inclusive, degrees). The light is on the far side (elevation above
#: 90, where it would graze the cloth); the camera on the viewer side (elevation above 0).
ANGLE_RANGES_DEG = {
    "light_elevation_deg": (90.0, 180.0, False),   # (low, high, low inclusive)
    "light_azimuth_deg": (0.0, 360.0, True),
    "camera_elevation_deg": (0.0, 90.0, False),
    "camera_azimuth_deg": (0.0, 360.0, True),
}

#: Fewest rows a gonio file may have: eq. 7 has five identifiable parameters.
MIN_GONIO_ROWS = 6

OGM3_CAMERA_ELEVATION_DEG = np.linspace(10.0, 90.0, 40)
OGM3_CAMERA_AZIMUTH_DEG = np.array([0.0, 180.0])
OGM3_LIGHT_ELEVATION_DEG = np.linspace(130.0, 180.0, 5)
OGM3_LIGHT_AZIMUTH_DEG = np.linspace(0.0, 330.0, 12)


def view_direction(camera_elevation_deg, camera_azimuth_deg) -> np.ndarray:
    """Unit vector from the cloth to the camera (+Z hemisphere), shape (..., 3)."""
    polar = np.radians(90.0 - np.asarray(camera_elevation_deg, dtype=np.float64))
    azimuth = np.radians(np.asarray(camera_azimuth_deg, dtype=np.float64))
    return np.stack([np.sin(polar) * np.cos(azimuth), np.sin(polar) * np.sin(azimuth),
                     np.cos(polar)], axis=-1)


def light_direction(light_elevation_deg, light_azimuth_deg) -> np.ndarray:
    """Unit vector from the cloth to the light (-Z hemisphere), shape (..., 3)."""
    polar = np.radians(180.0 - np.asarray(light_elevation_deg, dtype=np.float64))
    azimuth = np.radians(np.asarray(light_azimuth_deg, dtype=np.float64))
    return np.stack([np.sin(polar) * np.cos(azimuth), np.sin(polar) * np.sin(azimuth),
                     -np.cos(polar)], axis=-1)


@dataclass(frozen=True)
class GonioData:
    """One gonio measurement set: angles (degrees), the grey ratio and optional r,g,b.

    The directions and angles derived from the angles are computed once and cached
    (the arrays are not to be modified in place; :meth:`subset` and :meth:`with_values`
    make new sets)."""

    light_elevation_deg: np.ndarray
    light_azimuth_deg: np.ndarray
    camera_elevation_deg: np.ndarray
    camera_azimuth_deg: np.ndarray
    transmittance: np.ndarray
    rgb: np.ndarray | None = None          # (n, 3) per-channel ratio, or None
    path: Path | None = None
    line_numbers: np.ndarray | None = None  # 1-based file line of each point
    comments: tuple[str, ...] = ()

    def __len__(self) -> int:
        return len(self.transmittance)

    @cached_property
    def to_light(self) -> np.ndarray:
        return light_direction(self.light_elevation_deg, self.light_azimuth_deg)

    @property
    def travel(self) -> np.ndarray:
        """The light's direction of travel (minus the direction to the light)."""
        return -self.to_light

    @cached_property
    def view(self) -> np.ndarray:
        return view_direction(self.camera_elevation_deg, self.camera_azimuth_deg)

    @cached_property
    def one_minus_cos(self) -> np.ndarray:
        """1 - cos theta, from the vectors (exact near straight through)."""
        return one_minus_cos_between(self.travel, self.view)

    @cached_property
    def anisotropy_spread(self) -> np.ndarray:
        """(delta_y^2 - delta_x^2) / 2 of delta = view - travel: how a warp/weft
        anisotropy A changes the directional lobe's 1 - cos theta (by + A spread; the
        renderer's ``woven_chord2`` / 2 with the weft along x and the warp along y)."""
        delta = self.view - self.travel
        return 0.5 * (delta[:, 1] ** 2 - delta[:, 0] ** 2)

    @property
    def theta_deg(self) -> np.ndarray:
        """Scattering angle theta (degrees); 2 asin(|a - b| / 2) keeps small angles exact."""
        chord = np.sqrt(2.0 * self.one_minus_cos)
        return np.degrees(2.0 * np.arcsin(np.clip(chord / 2.0, 0.0, 1.0)))

    @cached_property
    def straight_through(self) -> np.ndarray:
        return is_straight_through(self.one_minus_cos)

    def subset(self, mask: np.ndarray) -> "GonioData":
        mask = np.asarray(mask)
        return replace(
            self,
            light_elevation_deg=self.light_elevation_deg[mask],
            light_azimuth_deg=self.light_azimuth_deg[mask],
            camera_elevation_deg=self.camera_elevation_deg[mask],
            camera_azimuth_deg=self.camera_azimuth_deg[mask],
            transmittance=self.transmittance[mask],
            rgb=None if self.rgb is None else self.rgb[mask],
            line_numbers=None if self.line_numbers is None else self.line_numbers[mask])

    def with_values(self, transmittance: np.ndarray, rgb: np.ndarray | None = None) -> "GonioData":
        return replace(self, transmittance=np.asarray(transmittance, dtype=np.float64),
                       rgb=None if rgb is None else np.asarray(rgb, dtype=np.float64))


def ogm3_grid() -> GonioData:
    """The OGM-3 grid's 4800 angle combinations (values zero): light elevation, light
    azimuth, camera azimuth, camera elevation, the last varying fastest."""
    le, la, ca, ce = np.meshgrid(OGM3_LIGHT_ELEVATION_DEG, OGM3_LIGHT_AZIMUTH_DEG,
                                 OGM3_CAMERA_AZIMUTH_DEG, OGM3_CAMERA_ELEVATION_DEG,
                                 indexing="ij")
    return GonioData(light_elevation_deg=le.ravel(), light_azimuth_deg=la.ravel(),
                     camera_elevation_deg=ce.ravel(), camera_azimuth_deg=ca.ravel(),
                     transmittance=np.zeros(le.size))


def paper_subset_mask(data: GonioData, tolerance_deg: float = 1e-6) -> np.ndarray:
    """The paper's fitting points: light elevation 180, light azimuth 0, camera azimuth
    0 and 180, duplicate view directions (camera elevation 90 from both azimuths) kept
    once. 79 points on the OGM-3 grid."""
    close = lambda a, b: np.abs(a - b) <= tolerance_deg  # noqa: E731
    mask = (close(data.light_elevation_deg, 180.0) & close(data.light_azimuth_deg, 0.0)
            & (close(data.camera_azimuth_deg, 0.0) | close(data.camera_azimuth_deg, 180.0)))
    view = data.view
    seen: list[np.ndarray] = []
    for index in np.flatnonzero(mask):
        if any(np.linalg.norm(view[index] - other) < 1e-9 for other in seen):
            mask[index] = False
        else:
            seen.append(view[index])
    return mask


def read_gonio(path: str | Path) -> GonioData:
    """Read a gonio CSV (formats.md) and check it can be fitted.

    Refused, naming the file and line: everything :func:`read_numeric_csv` refuses
    (empty, wrong header, NaN, negative, too few rows), an angle out of range, a set
    whose transmittance is zero everywhere, and a set with no straight-through point
    (theta < STRAIGHT_THROUGH_DEG), where the direct term cannot be measured.
    """
    from catalog.core.csvtable import read_numeric_csv

    table = read_numeric_csv(path, GONIO_COLUMNS, RGB_COLUMNS, min_rows=MIN_GONIO_ROWS)
    cols = table.columns
    present_rgb = [c for c in RGB_COLUMNS if c in cols]
    if present_rgb and len(present_rgb) != 3:
        raise InputError(f"per-channel columns must be all of r,g,b, found "
                         f"{','.join(present_rgb)}", path=table.path,
                         line=int(table.line_numbers[0]) - 1)
    for name, (low, high, low_inclusive) in ANGLE_RANGES_DEG.items():
        values = cols[name]
        bad = (values < low if low_inclusive else values <= low) | (values > high)
        if bad.any():
            first = int(np.flatnonzero(bad)[0])
            lo = "[" if low_inclusive else "("
            raise InputError(f"{name} = {values[first]:g} is out of range {lo}{low:g}, "
                             f"{high:g}]", path=table.path, line=int(table.line_numbers[first]))
    data = GonioData(
        light_elevation_deg=cols["light_elevation_deg"],
        light_azimuth_deg=cols["light_azimuth_deg"],
        camera_elevation_deg=cols["camera_elevation_deg"],
        camera_azimuth_deg=cols["camera_azimuth_deg"],
        transmittance=cols["transmittance"],
        rgb=np.stack([cols[c] for c in RGB_COLUMNS], axis=-1) if present_rgb else None,
        path=table.path, line_numbers=table.line_numbers, comments=table.comments)
    header_line = int(table.line_numbers[0]) - 1
    if not np.any(data.transmittance > 0):
        raise InputError("transmittance is zero on every row: nothing to fit",
                         path=table.path, line=int(table.line_numbers[0]))
    if data.rgb is not None:
        for channel, name in enumerate(RGB_COLUMNS):
            if not np.any(data.rgb[:, channel] > 0):
                raise InputError(f"{name} is zero on every row: nothing to fit",
                                 path=table.path, line=int(table.line_numbers[0]))
    if not data.straight_through.any():
        nearest = int(np.argmin(data.theta_deg))
        raise InputError(
            f"no straight-through point (theta < {STRAIGHT_THROUGH_DEG:g} deg; the nearest "
            f"is {data.theta_deg[nearest]:.3g} deg on line {int(table.line_numbers[nearest])}): "
            "the direct see-through cannot be measured", path=table.path,
            line=max(header_line, 1))
    return data


def format_gonio_csv(data: GonioData, comments: tuple[str, ...] = ()) -> str:
    """The CSV text for ``data`` (angles to 1e-6 deg, values to 6 significant digits)."""
    header = list(GONIO_COLUMNS) + (list(RGB_COLUMNS) if data.rgb is not None else [])
    lines = [f"# {c}" for c in comments] + [",".join(header)]
    for i in range(len(data)):
        fields = [f"{data.light_elevation_deg[i]:.6f}", f"{data.light_azimuth_deg[i]:.6f}",
                  f"{data.camera_elevation_deg[i]:.6f}", f"{data.camera_azimuth_deg[i]:.6f}",
                  f"{data.transmittance[i]:.6g}"]
        if data.rgb is not None:
            fields += [f"{v:.6g}" for v in data.rgb[i]]
        lines.append(",".join(fields))
    return "\n".join(lines) + "\n"


def write_gonio(path: str | Path, data: GonioData, comments: tuple[str, ...] = ()) -> None:
    """Write ``data`` as a gonio CSV, atomically."""
    from catalog.core.atomic import write_text_atomic

    write_text_atomic(Path(path), format_gonio_csv(data, comments))


__all__ = ["GONIO_COLUMNS", "RGB_COLUMNS", "GonioData", "read_gonio", "write_gonio",
           "format_gonio_csv", "ogm3_grid", "paper_subset_mask", "view_direction",
           "light_direction", "MIN_GONIO_ROWS"]
