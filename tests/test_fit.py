"""Fitting eq. 7 and Cook-Torrance (catalog/fit/fitting.py) and the ``catalog fit`` command."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from catalog.optics import btdf
from catalog.fit import fitting
from catalog.fit import gonio
from catalog.commands.cli import main as catalog_main

GRID = gonio.ogm3_grid()
SUBSET = gonio.paper_subset_mask(GRID)

TRUTHS = [
    dict(direct=0.30, a_diff=0.25, a_spec=0.40, g_diff=0.30, g_spec=0.93),
    dict(direct=0.05, a_diff=0.40, a_spec=0.15, g_diff=-0.20, g_spec=0.80),
    dict(direct=0.60, a_diff=0.05, a_spec=0.10, g_diff=0.55, g_spec=0.985),
]


def eq7_data(truth, data=GRID, noise=0.02, seed=0):
    clean = btdf.eq7_transmittance(data.one_minus_cos, **truth,
                                   straight_through=data.straight_through)
    rng = np.random.default_rng(seed)
    return clean * (1 + noise * rng.standard_normal(len(clean)))


# --- recovery from eq. 7 itself ---------------------------------------------------------------

@pytest.mark.parametrize("points", ["all", "79"])
@pytest.mark.parametrize("case", range(len(TRUTHS)))
def test_recovers_eq7_parameters_within_three_standard_errors(points, case):
    truth = TRUTHS[case]
    data = GRID if points == "all" else GRID.subset(SUBSET)
    for seed in (1, 2):
        values = eq7_data(truth, data, seed=seed + 10 * case)
        result = fitting.fit_gonio_hg(data, values)
        for name, true_value in truth.items():
            error = result.stderr[name]
            assert np.isfinite(error) and error > 0, name
            assert abs(result.params[name] - true_value) < 3 * error, (name, result.params)
        assert abs(result.params["g_spec"] - truth["g_spec"]) < 0.01
        if points == "all":   # 79 points with 2 % noise pin a broad lobe's g to ~0.02 only
            assert abs(result.params["g_diff"] - truth["g_diff"]) < 0.01


def test_standard_errors_match_the_scatter_of_repeated_fits():
    """The Jacobian's sigma^2 (J^T J)^-1 against the spread over 40 noise draws."""
    truth = TRUTHS[0]
    data = GRID.subset(SUBSET)
    fits = [fitting.fit_gonio_hg(data, eq7_data(truth, data, seed=100 + k)) for k in range(40)]
    for name in ("a_diff", "a_spec", "g_diff", "g_spec"):
        spread = np.std([f.params[name] for f in fits], ddof=1)
        reported = np.median([f.stderr[name] for f in fits])
        assert 0.6 < reported / spread < 1.6, (name, reported, spread)


def test_noise_free_eq7_is_recovered_exactly():
    truth = TRUTHS[1]
    result = fitting.fit_gonio_hg(GRID, eq7_data(truth, noise=0.0))
    for name, value in truth.items():
        assert result.params[name] == pytest.approx(value, rel=1e-6, abs=1e-9)
    assert result.rmse < 1e-9


# --- independence from the start ------------------------------------------------------------

GUESSES = [
    dict(direct=0.0, a_diff=1.0, a_spec=1.0, g_diff=0.0, g_spec=0.5),
    dict(direct=0.9, a_diff=0.01, a_spec=2.0, g_diff=0.8, g_spec=0.99),
    dict(direct=0.5, a_diff=0.5, a_spec=0.01, g_diff=-0.5, g_spec=0.0),
    dict(direct=0.1, a_diff=3.0, a_spec=0.2, g_diff=0.9, g_spec=0.3),
]


@pytest.mark.parametrize("measured", [False, True])
@pytest.mark.slow
def test_fit_does_not_depend_on_the_initial_guess(measured):
    """Far-off guesses, alone (no scan) or with the scan, end where the scan's starts do
    (to 1e-5: LM's stopping tolerance; the standard errors are ~1e-3)."""
    if measured:
        data = gonio.read_gonio(_measurement("lace-fwa"))
        values = data.transmittance
    else:
        data, values = GRID, eq7_data(TRUTHS[0], seed=5)
    reference = fitting.fit_gonio_hg(data, values)
    for guess in GUESSES:
        alone = fitting.fit_gonio_hg(data, values, starts=[guess], scan=False)
        with_scan = fitting.fit_gonio_hg(data, values, starts=[guess])
        for name in fitting.HG_NAMES:
            assert alone.params[name] == pytest.approx(reference.params[name], rel=1e-5,
                                                       abs=1e-6), (guess, name)
            assert with_scan.params[name] == pytest.approx(reference.params[name], rel=1e-5,
                                                           abs=1e-6)


def test_lobes_are_named_by_sharpness():
    result = fitting.fit_gonio_hg(GRID, eq7_data(TRUTHS[0], seed=3),
                                  starts=[dict(direct=0.3, a_diff=0.4, a_spec=0.25,
                                               g_diff=0.93, g_spec=0.3)], scan=False)
    assert result.params["g_spec"] > result.params["g_diff"]
    assert result.params["a_spec"] == pytest.approx(0.40, rel=0.02)


# --- per channel, Cook-Torrance, helpers ---------------------------------------------------

def test_channel_fits_recover_per_channel_amplitudes():
    g_diff, g_spec, direct = 0.2, 0.9, 0.25
    amplitudes = [(0.05, 0.10), (0.20, 0.30), (0.30, 0.25)]
    rng = np.random.default_rng(8)
    columns = []
    for a_diff, a_spec in amplitudes:
        clean = btdf.eq7_transmittance(GRID.one_minus_cos, direct, a_diff, a_spec, g_diff, g_spec,
                                       straight_through=GRID.straight_through)
        columns.append(clean * (1 + 0.01 * rng.standard_normal(len(clean))))
    fits = fitting.fit_channels(GRID.one_minus_cos, GRID.straight_through,
                                np.stack(columns, axis=1), g_diff, g_spec, direct=direct)
    for fit, (a_diff, a_spec) in zip(fits, amplitudes):
        assert fit["params"]["direct"] == direct and fit["stderr"]["direct"] == 0.0
        assert abs(fit["params"]["a_diff"] - a_diff) < 3 * fit["stderr"]["a_diff"]
        assert abs(fit["params"]["a_spec"] - a_spec) < 3 * fit["stderr"]["a_spec"]


def test_cook_torrance_fit_recovers_its_own_model():
    truth = dict(direct=0.2, k_lambert=0.15, k_spec=0.6, roughness=0.25)
    clean = btdf.cook_torrance_transmittance(GRID.to_light, GRID.view, **truth,
                                             straight_through=GRID.straight_through)
    values = clean * (1 + 0.01 * np.random.default_rng(4).standard_normal(len(clean)))
    result = fitting.fit_gonio_ct(GRID, values)
    for name, value in truth.items():
        assert abs(result.params[name] - value) < 3 * result.stderr[name] + 1e-12, name


def test_split_amplitudes_inverts_the_products():
    k_d, k_s = fitting.split_amplitudes(0.3, 0.2, rho=0.6, tau=0.4)
    assert 0.6 * math.exp(-0.4) * k_d == pytest.approx(0.3)
    assert 0.6 * math.exp(-0.4) * k_s == pytest.approx(0.2)
    with pytest.raises(ValueError):
        fitting.split_amplitudes(0.3, 0.2, rho=0.0, tau=0.0)


# --- the yarn-level measurements: HG beats Cook-Torrance ---------------------------------------

def _measurement(name):
    from catalog.core.resources import FABRIC_DIR

    return FABRIC_DIR / "measurements" / name / "gonio.csv"


def _catalog_fabrics():
    from catalog.core.resources import FABRIC_DIR

    return sorted(p.parent.name for p in (FABRIC_DIR / "measurements").glob("*/gonio.csv"))


@pytest.mark.parametrize("name", _catalog_fabrics())
def test_hg_beats_cook_torrance_on_yarn_level_data(name):
    data = gonio.read_gonio(_measurement(name))
    for part in (data, data.subset(gonio.paper_subset_mask(data))):
        for weighting in ("relative", "none"):
            hg = fitting.fit_gonio_hg(part, weighting=weighting, anisotropy=False)  # eq. 7
            ct = fitting.fit_gonio_ct(part, weighting=weighting)
            assert hg.rmse < ct.rmse, (len(part), weighting, hg.rmse, ct.rmse)
            assert hg.weighted_rms < ct.weighted_rms


def test_anisotropy_is_recovered_from_anisotropic_eq7_data():
    truth = dict(TRUTHS[0])
    for anisotropy in (0.0, 0.15, -0.3):
        omc_spec = GRID.one_minus_cos + anisotropy * GRID.anisotropy_spread
        clean = (truth["direct"] * GRID.straight_through
                 + truth["a_diff"] * btdf.hg_phase_one_minus_cos(GRID.one_minus_cos, truth["g_diff"])
                 + truth["a_spec"] * btdf.hg_phase_one_minus_cos(omc_spec, truth["g_spec"]))
        values = clean * (1 + 0.02 * np.random.default_rng(21).standard_normal(len(clean)))
        result = fitting.fit_gonio_hg(GRID, values)
        assert "anisotropy" in result.params
        assert abs(result.params["anisotropy"] - anisotropy) < 3 * result.stderr["anisotropy"]
        for name, value in truth.items():
            assert abs(result.params[name] - value) < 3 * result.stderr[name], name


def test_anisotropy_matches_the_renderer_chord():
    """GonioData's spread is the renderer's woven_chord2 / 2 minus the isotropic part."""
    travel, view = GRID.travel, GRID.view
    for anisotropy in (-0.4, 0.25):
        assert np.allclose(GRID.one_minus_cos + anisotropy * GRID.anisotropy_spread,
                           btdf.woven_one_minus_cos(travel, view, anisotropy), atol=1e-14)


def test_anisotropy_is_left_out_where_the_data_cannot_tell():
    assert fitting.anisotropy_identifiable(GRID)
    assert not fitting.anisotropy_identifiable(GRID.subset(SUBSET))
    result = fitting.fit_gonio_hg(GRID.subset(SUBSET), eq7_data(TRUTHS[0], GRID.subset(SUBSET)))
    assert "anisotropy" not in result.params


def test_yarn_level_anisotropy_has_the_generator_sign():
    """The generator spreads more across the warp (sigma_x > sigma_y): a positive A,
    larger for linen (11 vs 9 deg) than for voile (7.5 vs 6.5)."""
    fits = {name: fitting.fit_gonio_hg(gonio.read_gonio(_measurement(name)))
            for name in ("voile-white", "linen-dense")}
    assert 0 < fits["voile-white"].params["anisotropy"] < fits["linen-dense"].params["anisotropy"]


def test_yarn_level_data_is_not_eq7_itself():
    """The fit leaves structured residuals well above the instrument noise (~1 %)."""
    data = gonio.read_gonio(_measurement("voile-white"))
    hg = fitting.fit_gonio_hg(data)
    assert hg.weighted_rms > 0.03


# --- catalog fit ----------------------------------------------------------------------------

def run_fit(capsys, *argv):
    status = catalog_main(["fit", *map(str, argv)])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def test_catalog_fit_writes_the_preset_and_json(tmp_path, capsys):
    from catalog.presets import load_preset

    out = tmp_path / "lace-fwa.toml"
    folder = _measurement("lace-fwa").parent
    status, stdout, stderr = run_fit(
        capsys, "--gonio", folder / "gonio.csv", "--excitation", folder / "excitation.csv",
        "--emission", folder / "emission.csv", "--name", "lace-fwa", "--out", out, "--json")
    assert status == 0, stderr
    summary = json.loads(stdout)
    assert set(summary["identifiable"]) == {"direct", "a_diff", "a_spec", "g_diff", "g_spec"}
    assert summary["points"] == 4800 and summary["rmse"] > 0 and summary["ct_rmse"] > summary["rmse"]
    for key in ("direct", "k_d", "k_s", "tau", "rho", "g_diff", "g_spec", "stderr", "iterations"):
        assert key in summary
    preset = load_preset(out)
    b = preset.btdf
    assert b.a_diff == pytest.approx(summary["identifiable"]["a_diff"], rel=1e-5)
    assert b.a_spec == pytest.approx(summary["identifiable"]["a_spec"], rel=1e-5)
    assert b.rho == pytest.approx(1 - b.direct, rel=1e-5)
    assert preset.fit["points"] == 4800
    # self-contained: the preset names copies in its own folder, byte-equal to the inputs
    own = (tmp_path / "lace-fwa").resolve()
    source = preset.resolve(preset.fit["source"])
    assert source.is_relative_to(own) and source.read_bytes() == (folder / "gonio.csv").read_bytes()
    fl = preset.fluorescence
    assert fl is not None and fl.xyz[1] == pytest.approx(100.0)
    assert fl.excitation.is_relative_to(own)
    assert fl.excitation.read_bytes() == (folder / "excitation.csv").read_bytes()
    assert preset.table("cloth")["weave"] == "lace"


@pytest.mark.slow
def test_catalog_fit_79_points_dye_and_plot(tmp_path, capsys):
    from catalog.presets import load_preset

    out, plot = tmp_path / "sheer-teal.toml", tmp_path / "fig11.png"
    status, stdout, stderr = run_fit(capsys, "--gonio", _measurement("sheer-teal"),
                                     "--name", "sheer-teal", "--out", out, "--points", "79",
                                     "--plot", plot)
    assert status == 0, stderr
    assert "rmse HG" in stdout
    preset = load_preset(out)
    assert preset.fit["points"] == 79
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rgb = preset.raw["btdf"]["rgb"]
    assert len(rgb["a_spec"]) == 3 and rgb["a_spec"][0] < 0.6 * rgb["a_spec"][1]   # teal
    assert preset.resolve(preset.raw["dye"]["transmittance"]).is_file()
    assert preset.btdf.tau > 0.3                                                     # from the dye


BROKEN_FIT = {
    "empty": "",
    "wrong header": "a,b,c,d,e\n1,2,3,4,5\n",
    "nan": gonio.format_gonio_csv(GRID.subset(SUBSET).with_values(np.ones(79))).replace(
        "90.000000,0.000000,1\n", "90.000000,0.000000,nan\n", 1),
    "negative": gonio.format_gonio_csv(GRID.subset(SUBSET).with_values(-np.ones(79))),
    "all zero": gonio.format_gonio_csv(GRID.subset(SUBSET).with_values(np.zeros(79))),
    "one row": ",".join(gonio.GONIO_COLUMNS) + "\n180,0,90,0,1\n",
    "angle out of range": ",".join(gonio.GONIO_COLUMNS) + "\n180,0,90,0,1\n"
                          + "\n".join(f"180,0,{e},0,0.5" for e in (80, 70, 60, 50, 100)) + "\n",
    "no straight-through": gonio.format_gonio_csv(
        GRID.subset(SUBSET & ~GRID.straight_through).with_values(np.ones(78))),
}


@pytest.mark.parametrize("case", sorted(BROKEN_FIT))
def test_catalog_fit_refuses_broken_input_and_writes_nothing(tmp_path, capsys, case):
    bad = tmp_path / "bad.csv"
    bad.write_text(BROKEN_FIT[case])
    out = tmp_path / "out" / "broken.toml"
    status, stdout, stderr = run_fit(capsys, "--gonio", bad, "--name", "broken", "--out", out,
                                     "--plot", tmp_path / "out" / "fig.png")
    assert status == 2
    assert stdout == ""
    assert len(stderr.strip().splitlines()) == 1
    assert f"{bad}:" in stderr and stderr.split(f"{bad}:")[1].split(":")[0].isdigit(), stderr
    assert not out.exists()
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_catalog_fit_refuses_bad_options(tmp_path, capsys):
    gonio_path = _measurement("voile-white")
    status, _, stderr = run_fit(capsys, "--gonio", gonio_path, "--name", "other",
                                "--out", tmp_path / "voile.toml")
    assert status == 2 and "--name" in stderr
    status, _, stderr = run_fit(capsys, "--gonio", gonio_path, "--name", "voile",
                                "--out", tmp_path / "voile.toml", "--excitation", "x.csv")
    assert status == 2 and "--emission" in stderr
    status, _, stderr = run_fit(capsys, "--gonio", gonio_path, "--name", "voile",
                                "--out", tmp_path / "voile.toml", "--rho", "1.5")
    assert status == 2 and "--rho" in stderr
    assert not any(tmp_path.iterdir())


# --- catalog fit --pattern IMAGE (issue 34) -------------------------------------------------

def test_match_open_area_remaps_to_the_fitted_ld_and_keeps_holes():
    """c^gamma hits LD to 1e-6, keeps c = 0 and c = 1 and every pixel's order; an image whose
    holes alone exceed LD is refused naming --pattern."""
    from catalog.core.errors import InputError
    from catalog.presets.patterns import match_open_area

    rng = np.random.default_rng(7)
    c = rng.uniform(0.0, 1.0, (32, 32))
    c[:4] = 0.0
    c[-2:] = 1.0
    out = match_open_area(c, 0.3)
    assert abs(1.0 - out.mean(dtype=np.float64) - 0.3) < 1e-6
    assert np.all(out[:4] == 0.0) and np.all(out[-2:] == 1.0)
    order = np.argsort(c.ravel(), kind="stable")
    assert np.all(np.diff(out.ravel()[order]) >= -1e-7)
    with pytest.raises(InputError, match="--pattern"):
        match_open_area(c, 0.05)     # 12.5 % of the image is holes


@pytest.mark.slow   # a fit and its pattern written (0.75 s here)
def test_fit_with_a_pattern_writes_a_self_contained_preset(tmp_path):
    """``catalog fit --pattern IMAGE --pattern-repeat W``: the preset gets a [pattern] whose
    image lies beside it and whose open area is the fit's LD within formats' 1 %."""
    from catalog.core.resources import FABRIC_DIR
    from catalog.presets import load_preset
    from catalog.presets.patterns import OPEN_AREA_TOLERANCE, load_pattern

    out = tmp_path / "mine.toml"
    assert catalog_main(["fit", "--gonio", str(FABRIC_DIR / "measurements/voile-white/gonio.csv"),
                         "--name", "mine", "--out", str(out), "--pattern",
                         str(FABRIC_DIR / "patterns/jacquard-white.png"),
                         "--pattern-repeat", "0.1"]) == 0
    preset = load_preset(out)
    pattern = load_pattern(preset)
    assert (tmp_path / "mine" / "patterns" / "mine.png").is_file()   # in its own folder
    assert pattern.repeat_m == pytest.approx((0.1, 0.1))
    assert abs(pattern.open_area - preset.btdf.direct) <= OPEN_AREA_TOLERANCE * preset.btdf.direct
    assert catalog_main(["fit", "--gonio", str(FABRIC_DIR / "measurements/voile-white/gonio.csv"),
                         "--name", "other", "--out", str(tmp_path / "other.toml"), "--pattern",
                         str(FABRIC_DIR / "patterns/jacquard-white.png")]) == 2
