"""A spectrum tabulated on evenly spaced wavelengths, evaluated inside Mitsuba plugins at a
ray's sampled wavelengths (linear between samples, 0 outside the table): the glow's emission
shape (catalog.pathtrace.glow) and the window filter's transmission
(catalog.pathtrace.window_filter)."""

from __future__ import annotations

import numpy as np


class TabulatedSpectrum:
    """``values`` on the evenly spaced ``wavelengths_nm`` (at least two)."""

    def __init__(self, mi, wavelengths_nm, values):
        wavelengths = np.asarray(wavelengths_nm, dtype=np.float64)
        self.values = mi.Float(np.asarray(values, dtype=np.float32))
        self.size = int(wavelengths.size)
        self.first_nm = float(wavelengths[0])
        self.step_nm = float(wavelengths[1] - wavelengths[0])

    def at(self, mi, wavelengths, active):
        """A mi.Spectrum of the table at each lane of ``wavelengths`` (si.wavelengths)."""
        import drjit as dr  # noqa: PLC0415

        lanes = []
        for k in range(len(wavelengths)):
            x = (wavelengths[k] - self.first_nm) / self.step_nm
            inside = active & (x >= 0.0) & (x <= self.size - 1)
            i = mi.UInt32(dr.clip(dr.floor(x), 0, self.size - 2))
            f = x - mi.Float(i)
            a = dr.gather(mi.Float, self.values, i, inside)
            b = dr.gather(mi.Float, self.values, i + 1, inside)
            lanes.append(dr.select(inside, a + f * (b - a), 0.0))
        return mi.Spectrum(*lanes)
