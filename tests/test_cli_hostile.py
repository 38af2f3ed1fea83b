"""The whole CLI against generated bad input (hypothesis): every command refuses a bad file
or option with exit status 2 and one line naming it, never a traceback, and leaves the file
system as it was (the intended output does not appear, nothing else changes).

The categories: malformed measurement files (spectrum CSV, gonio CSV, BFC matrix),
malformed or out-of-range presets (TOML), and out-of-range or malformed option values for
each command that renders, simulates or fits. Commands run in process (``main(argv)``) so
that a few hundred examples take seconds; the subprocess paths (signals, stdout, full disk)
are in test_output_layer.py.
"""

from __future__ import annotations

import math
import string
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from catalog.commands.cli import main

SETTINGS = settings(max_examples=30, deadline=None,
                    suppress_health_check=[HealthCheck.function_scoped_fixture,
                                           HealthCheck.too_slow])


def _tree(folder: Path) -> dict[str, tuple[int, int]]:
    return {str(p.relative_to(folder)): (p.stat().st_size, p.stat().st_mtime_ns)
            for p in sorted(folder.rglob("*"))}


def _refused(argv: list[str], capsys, folder: Path, outputs: list[Path]) -> str:
    """Run the CLI; assert a clean refusal and an untouched folder; return the error line."""
    before = _tree(folder)
    capsys.readouterr()
    try:
        status = main(argv)
    except SystemExit as exc:  # not expected: refusals return 2, they do not exit
        status = f"SystemExit({exc.code})"
    captured = capsys.readouterr()
    assert status == 2, (argv, captured.err)
    assert "Traceback" not in captured.err
    error_lines = [ln for ln in captured.err.splitlines() if "error:" in ln]
    assert len(error_lines) == 1, captured.err
    for path in outputs:
        assert not path.exists(), f"{path} written despite the refusal"
    assert _tree(folder) == before
    return error_lines[0]


# --------------------------------------------------------------------------- files

_HEADERS = ["wavelength_nm,intensity", "wavelength_nm, intensity", "nm,intensity", ""]
_BAD_ROWS = st.one_of(
    st.tuples(st.floats(allow_nan=True, allow_infinity=True), st.floats(allow_nan=True, allow_infinity=True))
    .map(lambda t: f"{t[0]},{t[1]}"),
    st.text(alphabet=string.printable, max_size=30).map(lambda s: s.replace("\n", " ")),
    st.just("500,-1"), st.just("400,0.1,0.2"), st.just("300,0.5"))


@st.composite
def bad_spectrum_text(draw) -> str:
    header = draw(st.sampled_from(_HEADERS))
    rows = draw(st.lists(_BAD_ROWS, max_size=6))
    text = "\n".join([header, *rows]) + "\n"
    return text


def _is_valid_spectrum(text: str) -> bool:
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.startswith("#")]
    if not lines or lines[0].replace(" ", "") != "wavelength_nm,intensity":
        return False
    try:
        rows = [tuple(float(f) for f in ln.split(",")) for ln in lines[1:]]
    except ValueError:
        return False
    if len(rows) < 2 or any(len(r) != 2 for r in rows):
        return False
    wl = [r[0] for r in rows]
    values = [r[1] for r in rows]
    return (all(math.isfinite(v) for r in rows for v in r) and all(v >= 0 for v in values)
            and all(b > a for a, b in zip(wl, wl[1:])) and max(values) > 0)


@SETTINGS
@given(text=bad_spectrum_text(), which=st.sampled_from(["--excitation", "--emission"]))
@pytest.mark.slow
def test_fluorescence_refuses_bad_spectra(tmp_path, capsys, project_root, text, which):
    if _is_valid_spectrum(text):
        return  # hypothesis drew a valid file: not this test's subject
    bad = tmp_path / "bad.csv"
    bad.write_text(text)
    good = project_root / "fabrics" / "measurements" / "lace-fwa"
    files = {"--excitation": str(good / "excitation.csv"), "--emission": str(good / "emission.csv")}
    files[which] = str(bad)
    plot = tmp_path / "plot.png"
    line = _refused(["fluorescence", *sum(([k, v] for k, v in files.items()), []),
                     "--light", "D65", "--plot", str(plot)], capsys, tmp_path, [plot])
    assert str(bad) in line


@SETTINGS
@given(text=st.one_of(st.text(max_size=200), st.binary(max_size=200).map(lambda b: b.decode("latin-1")),
                      st.lists(st.text(alphabet="0123456789.,- e\n", max_size=40), max_size=15)
                      .map(lambda ls: "\n".join(["; header"] * 10 + ls))))
@pytest.mark.slow
def test_bispectral_refuses_bad_matrix_files(tmp_path, capsys, text):
    bad = tmp_path / "BAD.BFC"
    bad.write_bytes(text.encode("utf-8", "surrogatepass"))
    export = tmp_path / "export"
    line = _refused(["bispectral", str(bad), "--export", str(export)], capsys, tmp_path, [export])
    assert str(bad) in line


@SETTINGS
@given(columns=st.sampled_from(["light_elevation_deg,light_azimuth_deg,camera_elevation_deg,"
                                "camera_azimuth_deg,transmittance", "a,b,c,d,e", ""]),
       rows=st.lists(st.lists(st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                                        st.text(alphabet="xyz-", max_size=3)),
                              min_size=4, max_size=6).map(lambda r: ",".join(map(str, r))),
                     max_size=5))
@pytest.mark.slow
def test_fit_refuses_bad_gonio_files(tmp_path, capsys, columns, rows):
    bad = tmp_path / "gonio.csv"
    bad.write_text("\n".join([columns, *rows]) + "\n")
    out = tmp_path / "p.toml"
    plot = tmp_path / "p.png"
    line = _refused(["fit", "--gonio", str(bad), "--name", "p", "--out", str(out),
                     "--plot", str(plot)], capsys, tmp_path, [out, plot])
    assert "gonio.csv" in line or "--" in line


_NOT_NUMBERS = st.one_of(st.sampled_from([float("nan"), float("inf"), float("-inf")]),
                        st.text(alphabet=string.ascii_letters, min_size=1, max_size=6)
                        .map(lambda s: f'"{s}"'))
#: Values outside each key's range (formats doc / catalog.presets), besides non-numbers.
_OUT_OF_RANGE = {
    "direct": [-1e-9, 1.0000001, 2.0], "rho": [0.0, -0.5, 1.5], "g_diff": [-1.0, 1.0, 3.0],
    "g_spec": [-1.0, 1.0, -7.0], "k_d": [-1e-9, -1.0], "tau": [-1e-9, -3.0],
    "quantum_yield": [-0.1, 1.01, 5.0], "peak_absorptance": [0.0, -1.0, 1.5],
    "schema": [0, 2, 99], "name": [1.0],
}
_BTDF_KEYS = ["direct", "rho", "g_diff", "g_spec", "k_d", "tau"]


@SETTINGS
@given(key=st.sampled_from(_BTDF_KEYS + ["quantum_yield", "peak_absorptance", "schema",
                                         "name", "<drop>", "<garbage>"]), data=st.data())
@pytest.mark.slow
def test_snapshot_refuses_bad_presets(tmp_path, capsys, make_preset, key, data):
    value = data.draw(st.one_of(_NOT_NUMBERS, st.sampled_from(_OUT_OF_RANGE.get(key, [-1.0]))))
    path = make_preset("hostile")
    text = path.read_text()
    if key == "<drop>":
        text = text.replace("g_spec", "# g_spec")
    elif key == "<garbage>":
        text = text[: len(text) // 2] + "\n[[[ not toml"
    elif key in ("quantum_yield", "peak_absorptance"):
        text = text.replace("[fluorescence]", f"[fluorescence]\n{key} = {value}", 1)
    elif key in ("schema", "name"):
        text = text.replace(f"{key} = ", f"{key} = {value}\n# ", 1)
    else:
        text = text.replace(f"\n{key} = ", f"\n{key} = {value}\n# ", 1)
    path.write_text(text)
    out = tmp_path / "o.png"
    line = _refused(["snapshot", "--fabric", str(path), "--size", "8x8", "--out", str(out)],
                    capsys, tmp_path, [out])
    assert str(path) in line


# --------------------------------------------------------------------------- options

_BAD_SIZES = st.one_of(st.sampled_from(["0x10", "10x0", "-5x5", "5x", "x5", "10x10x10", "axb",
                                        "1e3x10", "999999x999999", "100000x1", " ", "", "NaNxNaN",
                                        "3.5x2"]),
                       st.text(alphabet="0123456789x-. ", max_size=8)
                       .filter(lambda s: not _valid_size(s)))


def _valid_size(text: str) -> bool:
    """What catalog.core.cliargs.parse_wxh accepts (sides 1..4096 render here in seconds)."""
    import re

    match = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", text)
    return match is not None and all(1 <= int(g) for g in match.groups())


@SETTINGS
@given(option=st.sampled_from(["--size", "--light", "--frame", "--bands", "--distance",
                               "--exposure", "--mode", "--fabric"]),
       draw=st.data())
def test_snapshot_refuses_bad_options(tmp_path, capsys, option, draw):
    value = {
        "--size": _BAD_SIZES,
        "--light": st.sampled_from(["D66", "sun:", "sun:-3", "sun:abc", "sun:nan", "UV-B",
                                    "sun@2026-13-01T12:00,0,0", "sun@2026-06-21T12:00,95,0", ""]),
        "--frame": st.sampled_from(["-1", "1.5", "abc", "1e9"]),
        "--bands": st.sampled_from(["0", "2", "5", "17", "x"]),
        "--distance": st.sampled_from(["0", "-1", "nan", "inf", "0.0001", "abc"]),
        "--exposure": st.sampled_from(["0", "-2", "nan", "inf", "abc"]),
        "--mode": st.sampled_from(["", "spectral", "PAPER"]),
        "--fabric": st.sampled_from(["no-such-fabric", "../" * 9 + "etc/passwd", "", "x.toml"]),
    }[option]
    argv = {"--size": "8x8", "--light": "D65", "--fabric": "voile-white"}
    argv[option] = draw.draw(value)
    out = tmp_path / "o.png"
    args = ["snapshot", *sum(([k, v] for k, v in argv.items()), []), "--out", str(out)]
    line = _refused(args, capsys, tmp_path, [out])
    assert option in line or argv[option].strip() in line, line


@SETTINGS
@given(option=st.sampled_from(["--grid", "--steps", "--dt", "--stiffness", "--wind", "--backend"]),
       draw=st.data())
def test_simulate_refuses_bad_options(tmp_path, capsys, option, draw):
    value = {
        "--grid": _BAD_SIZES,
        "--steps": st.sampled_from(["-1", "abc", "1.5", "1e12"]),
        "--dt": st.sampled_from(["0", "-0.01", "nan", "inf", "10"]),
        "--stiffness": st.sampled_from(["0", "-1", "nan", "inf", "abc"]),
        "--wind": st.sampled_from(["-1", "nan", "inf", "1e9"]),
        "--backend": st.sampled_from(["cuda", "", "GPU"]),
    }[option]
    argv = {"--grid": "8x8", "--steps": "2"}
    argv[option] = draw.draw(value)
    out = tmp_path / "c.obj"
    _refused(["simulate", *sum(([k, v] for k, v in argv.items()), []), "--out", str(out)],
             capsys, tmp_path, [out])


@SETTINGS
@given(option=st.sampled_from(["--size", "--lights", "--bands"]), draw=st.data())
def test_sheet_refuses_bad_options(tmp_path, capsys, option, draw):
    value = {
        "--size": _BAD_SIZES,
        "--lights": st.sampled_from(["", ",", "D65,,A", "D65,nope", "sun:0", "sun:1e9x"]),
        "--bands": st.sampled_from(["0", "4", "x"]),
    }[option]
    argv = {"--size": "8x8", "--lights": "D65"}
    argv[option] = draw.draw(value)
    out = tmp_path / "sheet"
    _refused(["sheet", *sum(([k, v] for k, v in argv.items()), []), "--out", str(out)],
             capsys, tmp_path, [out])


@pytest.mark.parametrize("argv", [
    ["snapshot", "--fabric", "voile-white", "--size", "8x8", "--out", "{tmp}"],
    ["snapshot", "--fabric", "voile-white", "--size", "8x8", "--out", "{tmp}/file.txt/x.png"],
    ["sheet", "--lights", "D65", "--size", "8x8", "--out", "{tmp}/file.txt"],
    ["lights", "--plot", "{tmp}"],
    ["sun", "--plot", "{tmp}/file.txt/p.png"],
    ["simulate", "--grid", "8x8", "--steps", "1", "--out", "{tmp}"],
    ["bench", "--quick", "--out", "{tmp}/file.txt"],
])
def test_unwritable_outputs_are_refused_before_the_work(tmp_path, capsys, argv):
    (tmp_path / "file.txt").write_text("the user's file")
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    line = _refused(argv, capsys, tmp_path, [])
    assert "--" in line and str(tmp_path) in line, line


@pytest.mark.slow
def test_the_fixed_hostile_corpus_is_refused_cleanly():
    """The benchmark's fixed corpus (catalog.bench.hostile, ~90 cases in six categories):
    every case exits 2 with one line naming what was given, and leaves nothing behind."""
    from catalog.bench.hostile import run_suite

    result = run_suite()
    assert result["failures"] == [], result["failures"]
    assert result["cases"] >= 90
