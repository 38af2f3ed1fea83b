"""The cached tables are exactly what colour-science and pvlib ship."""

from __future__ import annotations

import numpy as np

from catalog.optics import reference_tables


def test_cache_equals_a_fresh_copy_from_the_packages():
    fresh = reference_tables.build_tables()
    cached = reference_tables.tables()
    assert sorted(fresh) == sorted(cached)
    for key, value in fresh.items():
        np.testing.assert_array_equal(cached[key], value, err_msg=key)


def test_illuminant_lookup_matches_colour():
    import colour

    for name in ("D65", "A", "FL2", "LED-B4"):
        wl, values = reference_tables.illuminant_table(name)
        sd = colour.SDS_ILLUMINANTS[name]
        np.testing.assert_array_equal(wl, sd.wavelengths)
        np.testing.assert_array_equal(values, sd.values)
