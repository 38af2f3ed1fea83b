"""A fitted fabric's default pattern for its weave (catalog.presets.weave_patterns; ``catalog
fit`` without ``--pattern``): the open area is the fit's LD, the repeat tiles, the files travel
with the preset."""

from __future__ import annotations

import numpy as np
import pytest

from catalog.commands.cli import main as catalog_main
from catalog.core.validate import WEAVES
from catalog.presets.patterns import check_tileable
from catalog.presets.weave_patterns import WEAVE_DEFAULTS, default_pattern

#: formats.md: a pattern's open area within 1 % of LD (relative)
OPEN_AREA_TOLERANCE = 0.01


def test_every_weave_has_a_default():
    assert set(WEAVE_DEFAULTS) == set(WEAVES)


@pytest.mark.parametrize("weave", WEAVES)
@pytest.mark.parametrize("direct", [0.03, 0.29, 0.6])
def test_default_pattern_opens_the_fitted_area_and_tiles(weave, direct):
    coverage, height, repeat, info = default_pattern(weave, direct)
    assert abs((1.0 - coverage.mean(dtype=np.float64)) - direct) <= OPEN_AREA_TOLERANCE * direct
    assert coverage.min() >= 0.0 and coverage.max() <= 1.0
    assert height.min() >= 0.0 and height.max() <= 1.0
    assert all(0 < r < 0.1 for r in repeat) and 0 < info["height_m"] < 0.01
    check_tileable(coverage, "default", "coverage")   # the loader's own rule (raises)


def test_weaves_differ_in_structure():
    """A lace's net, a voile's sheer plain weave and a satin are told apart by their coverage."""
    nets = {w: default_pattern(w, 0.2)[0] for w in ("lace", "voile", "satin")}
    assert nets["lace"].shape != nets["voile"].shape or not np.allclose(nets["lace"], nets["voile"])
    assert np.std(nets["satin"]) < np.std(nets["voile"])   # a satin's floats hide its holes


@pytest.mark.slow
@pytest.mark.parametrize("weave,kind", [("lace", "net"), ("satin", "damask")])
def test_fit_without_a_pattern_draws_its_weave(tmp_path, weave, kind):
    from catalog.core.resources import FABRIC_DIR
    from catalog.presets import load_preset
    from catalog.presets.patterns import load_pattern

    out = tmp_path / "mine.toml"
    assert catalog_main(["fit", "--gonio", str(FABRIC_DIR / "measurements/voile-white/gonio.csv"),
                         "--name", "mine", "--weave", weave, "--out", str(out)]) == 0
    preset = load_preset(out)
    pattern = load_pattern(preset)
    assert (tmp_path / "mine" / "patterns" / "mine.png").is_file()
    assert (tmp_path / "mine" / "patterns" / "mine-height.png").is_file()
    assert pattern.height is not None
    assert abs(pattern.open_area - preset.btdf.direct) <= OPEN_AREA_TOLERANCE * preset.btdf.direct
    import tomllib

    assert tomllib.loads(out.read_text())["pattern"]["kind"] == kind
