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
import os
import re
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


@pytest.mark.slow   # each example resolves the whole catalog and the sheet's room (1.3 s)
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
    """The benchmark's fixed corpus (benchmarks.hostile, ~90 cases in six categories):
    every case exits 2 with one line naming what was given, and leaves nothing behind."""
    from benchmarks.hostile import run_suite

    result = run_suite()
    assert result["failures"] == [], result["failures"]
    assert result["cases"] >= 90


# --------------------------------------------------------------------------- round two (issue 37)
# Each class of the red team's second round: inputs never overwritten, work bounded before
# it starts, typed preset fields, one validation per option; then a fuzz of preset TOML and
# of every command's numeric options, and the signals (subprocesses, slow).

def _inputs_digest(paths) -> dict[str, bytes]:
    return {str(p): Path(p).read_bytes() for p in paths}


def _lace_copy(tmp_path: Path, project_root: Path) -> Path:
    """lace-fwa's preset with its spectra and pattern images beside it, in tmp_path."""
    import shutil

    fabrics = project_root / "fabrics"
    for folder in ("patterns", "measurements/lace-fwa"):
        (tmp_path / folder).mkdir(parents=True, exist_ok=True)
    for name in ("lace-fwa.png", "lace-fwa-height.png"):
        shutil.copyfile(fabrics / "patterns" / name, tmp_path / "patterns" / name)
    for name in ("excitation.csv", "emission.csv"):
        shutil.copyfile(fabrics / "measurements" / "lace-fwa" / name,
                        tmp_path / "measurements" / "lace-fwa" / name)
    shutil.copyfile(fabrics / "lace-fwa.toml", tmp_path / "lace-fwa.toml")
    return tmp_path / "lace-fwa.toml"


@pytest.mark.parametrize("how", ["coverage", "height", "spectrum", "through a symlinked folder",
                                 "through a hard link"])
def test_no_output_replaces_a_file_the_preset_names(tmp_path, capsys, project_root, how):
    preset = _lace_copy(tmp_path, project_root)
    inputs = [preset, *(tmp_path / "patterns").iterdir(),
              *(tmp_path / "measurements" / "lace-fwa").iterdir()]
    (tmp_path / "link").symlink_to(tmp_path, target_is_directory=True)
    out = {"coverage": tmp_path / "patterns" / "lace-fwa.png",
           "height": tmp_path / "patterns" / "lace-fwa-height.png",
           "spectrum": tmp_path / "measurements" / "lace-fwa" / "emission.csv",
           "through a symlinked folder": tmp_path / "link" / "patterns" / "lace-fwa.png",
           "through a hard link": tmp_path / "hard.png"}[how]
    if how == "through a hard link":
        os.link(tmp_path / "patterns" / "lace-fwa.png", out)
    before = _inputs_digest(inputs)
    line = _refused(["snapshot", "--fabric", str(preset), "--size", "8x8", "--out", str(out)],
                    capsys, tmp_path, [])
    assert "own input" in line and "--out" in line, line
    assert _inputs_digest(inputs) == before


def test_no_output_replaces_an_environment_or_a_dye(tmp_path, capsys, project_root):
    env = tmp_path / "env.exr"
    env.write_bytes(b"an environment (never read: refused first)")
    line = _refused(["snapshot", "--fabric", "voile-white", "--size", "8x8", "--environment",
                     str(env), "--out", str(env)], capsys, tmp_path, [])
    assert "own input" in line
    dye = tmp_path / "d.png"
    dye.write_text("wavelength_nm,transmittance\n400,0.5\n700,0.5\n")
    gonio = project_root / "fabrics" / "measurements" / "voile-white" / "gonio.csv"
    line = _refused(["fit", "--gonio", str(gonio), "--dye", str(dye), "--name", "p", "--out",
                     str(tmp_path / "p.toml"), "--plot", str(dye)], capsys, tmp_path,
                    [tmp_path / "p.toml"])
    assert "--plot" in line and "own input" in line


def test_an_output_never_replaces_a_device_or_a_pipe(tmp_path, capsys):
    from catalog.core.atomic import OutputError, check_target, write_bytes_atomic

    fifo = tmp_path / "pipe.png"
    os.mkfifo(fifo)
    line = _refused(["snapshot", "--fabric", "voile-white", "--size", "8x8", "--out", str(fifo)],
                    capsys, tmp_path, [])
    assert "not a regular file" in line
    with pytest.raises(OutputError, match="not a regular file"):
        check_target("/dev/null")
    link = tmp_path / "null.png"
    link.symlink_to("/dev/null")
    with pytest.raises(OutputError, match="not a regular file"):
        write_bytes_atomic(link, b"x")
    assert link.is_symlink() and Path("/dev/null").is_char_device()


@pytest.mark.slow
def test_fit_publishes_its_plot_and_preset_together_or_neither(tmp_path, capsys, project_root,
                                                               monkeypatch):
    """--plot and --out: when the preset cannot be written the new plot does not appear."""
    from catalog.core.errors import CatalogError
    import catalog.presets as presets

    gonio = project_root / "fabrics" / "measurements" / "voile-white" / "gonio.csv"
    plot, out = tmp_path / "p.png", tmp_path / "p.toml"
    plot.write_bytes(b"the old plot")

    def refuse(*args, **kw):
        raise CatalogError("the preset cannot be written (simulated)")

    monkeypatch.setattr(presets, "write_text_atomic", refuse, raising=False)
    import catalog.core.atomic as atomic
    real = atomic.write_text_atomic
    monkeypatch.setattr(atomic, "write_text_atomic",
                        lambda target, *a, **k: refuse() if str(target).endswith(".toml")
                        else real(target, *a, **k))
    status = main(["fit", "--gonio", str(gonio), "--name", "p", "--out", str(out),
                   "--plot", str(plot)])
    assert status == 2
    assert plot.read_bytes() == b"the old plot" and not out.exists()
    from catalog.core.atomic import TEMP_MARK
    assert not [p for p in tmp_path.iterdir() if TEMP_MARK in p.name]
    monkeypatch.undo()
    assert main(["fit", "--gonio", str(gonio), "--name", "p", "--out", str(out),
                 "--plot", str(plot)]) == 0
    assert plot.read_bytes()[:4] == b"\x89PNG" and out.is_file()


def test_staging_lives_on_the_destinations_file_system(tmp_path):
    """An existing destination (a mount point) gets its stage inside itself: the renames
    never cross a file system; a missing one gets it beside, where it will be made."""
    from catalog.core.atomic import STAGE_MARKER, staged_folder

    dest = tmp_path / "mounted"
    dest.mkdir()
    with staged_folder(dest) as stage:
        assert stage.parent == dest and (stage / STAGE_MARKER).is_file()
        assert os.stat(stage).st_dev == os.stat(dest).st_dev
        (stage / "a.png").write_text("a")
    assert sorted(p.name for p in dest.iterdir()) == ["a.png"]
    with staged_folder(tmp_path / "new" / "deep") as stage:
        assert stage.parent == tmp_path / "new"
        (stage / "b.png").write_text("b")
    assert (tmp_path / "new" / "deep" / "b.png").read_text() == "b"
    with pytest.raises(RuntimeError):
        with staged_folder(tmp_path / "made" / "for" / "it") as stage:
            raise RuntimeError("failed")
    assert not (tmp_path / "made").exists()  # folders made above it are removed again


def test_weaves_the_validator_knows_are_the_cloth_models():
    from catalog.cloth.params import WEAVE_DEFAULTS
    from catalog.core.validate import WEAVES

    assert tuple(WEAVE_DEFAULTS) == WEAVES


@pytest.mark.parametrize("argv, named", [
    (["snapshot", "--fabric", "voile-white", "--frame", "1000000000000"], "--frame"),
    (["snapshot", "--fabric", "voile-white", "--frame", "216001"], "216000"),
    (["reference", "--fabric", "voile-white", "--frame", "1e12"], "--frame"),
    (["render-catalog", "--fabrics", "voile-white", "--lights", "D65", "--frames", "0:50000000"],
     "216000"),
    (["reference", "--fabric", "voile-white", "--size", "16384x16384"], "MiB"),
    (["simulate", "--grid", "8x8", "--steps", "2", "--out", "{tmp}/f{frame:0999999999999d}.obj"],
     "--out"),
    (["simulate", "--grid", "8x8", "--steps", "2", "--out", "{tmp}/f{frame}{other}.obj"], "--out"),
    (["render-catalog", "--fabrics", "voile-white", "--lights", "D65", "--distance", "1e308"],
     "--distance"),
    (["render-catalog", "--fabrics", "voile-white", "--lights", "D65", "--exposure", "1e308"],
     "--exposure"),
    (["render-catalog", "--fabrics", "voile-white", "--lights", "D65", "--pitch", "90"], "--pitch"),
    (["reference", "--fabric", "voile-white", "--pitch", "90"], "--pitch"),
    (["reference", "--fabric", "voile-white", "--pitch", "1e308"], "--pitch"),
    (["reference", "--fabric", "voile-white", "--seed", "-1"], "--seed"),
    (["reference", "--fabric", "voile-white", "--seed", str(1 << 64)], "4294967295"),
    (["reference", "--fabric", "voile-white", "--distance", "0.01"], "0.05"),
    (["snapshot", "--fabric", "voile-white", "--exposure", "1e-300"], "--exposure"),
    (["snapshot", "--fabric", "voile-white", "--distance", "0.01"], "(0.05, 50]"),
    (["snapshot", "--fabric", "voile-white", "--yaw", "1_0"], "--yaw"),
    (["fit", "--gonio", "{gonio}", "--name", "p", "--tau", "inf"], "--tau"),
    (["fit", "--gonio", "{gonio}", "--name", "p", "--rho", "0_5"], "--rho"),
    (["fit", "--gonio", "{gonio}", "--name", "p", "--plot", "{tmp}/fig"], "--plot"),
    (["fit", "--gonio", "{gonio}", "--name", "p", "--plot", "{tmp}/fig.txt"], "--plot"),
    (["lights", "--plot", "{tmp}/fig.svgz"], "--plot"),
    (["fluorescence", "--excitation", "{spectra}/excitation.csv", "--emission",
      "{spectra}/emission.csv", "--light", "D65", "--illuminance", "1e308"], "--illuminance"),
    (["sheet", "--lights", "D65,D65", "--size", "8x8"], "twice"),
    (["render-catalog", "--fabrics", "voile-white", "--lights", "A,A"], "twice"),
    (["web", "--lights", ""], "--lights"),
    (["web", "--lights", "D65,D65"], "twice"),
    (["sheet", "--lights", "sun@2026-13-21T12:00,34.7,-120", "--size", "8x8"],
     "sun@2026-13-21T12:00,34.7,-120"),
])
def test_round_two_options_are_refused_naming_the_bound(tmp_path, capsys, project_root, argv,
                                                        named):
    outputs = {"snapshot": ["--out", "{tmp}/o.png"], "reference": ["--out", "{tmp}/r.exr"],
               "render-catalog": ["--out", "{tmp}/c"], "fit": ["--out", "{tmp}/p.toml"],
               "sheet": ["--out", "{tmp}/s"], "web": ["--out", "{tmp}/site"]}
    if "--out" not in argv:
        argv = argv + outputs.get(argv[0], [])
    fills = {"{tmp}": str(tmp_path), "{spectra}": str(project_root / "fabrics" / "measurements"
                                                       / "lace-fwa"),
             "{gonio}": str(project_root / "fabrics" / "measurements" / "voile-white" / "gonio.csv")}
    for key, value in fills.items():
        argv = [a.replace(key, value) for a in argv]
    line = _refused(argv, capsys, tmp_path, [])
    assert named in line, line


def test_light_lists_keep_a_dated_sun_whole():
    from catalog.core.errors import InputError
    from catalog.core.validate import parse_light_list

    assert parse_light_list("D65,sun@2026-06-21T12:00,34.7,-120,A") == [
        "D65", "sun@2026-06-21T12:00,34.7,-120", "A"]
    for bad in ("", " ", "D65,,A", "D65,D65", ","):
        with pytest.raises(InputError):
            parse_light_list(bad)


@pytest.mark.parametrize("label, edit", [
    ("cloth.weave a list", lambda t: t + '[cloth]\nweave = ["lace"]\n'),
    ("cloth.weave unknown", lambda t: t + '[cloth]\nweave = "tulle"\n'),
    ("cloth a number", lambda t: t.replace("[btdf]", "cloth = 5\n[btdf]")),
    ("pattern a string", lambda t: t.replace("[btdf]", 'pattern = "x"\n[btdf]')),
    ("pattern.coverage a number", lambda t: t + "[pattern]\ncoverage = 3\nrepeat_m = 0.01\n"),
    ("cloth.fullness text", lambda t: t + '[cloth]\nfullness = "full"\n'),
    ("cloth.areal_density huge", lambda t: t + "[cloth]\nareal_density_kg_m2 = 1e300\n"),
    ("nested 5000 deep", lambda t: t + "[deep]\nx = " + "[" * 5000 + "]" * 5000 + "\n"),
    ("nested tables", lambda t: t + "x = " + "{a = " * 3000 + "1" + "}" * 3000 + "\n"),
])
def test_preset_fields_of_the_wrong_type_are_refused(tmp_path, capsys, make_preset, label, edit):
    path = make_preset("typed", fluorescent=False)
    path.write_text(edit(path.read_text()))
    out = tmp_path / "o.png"
    line = _refused(["snapshot", "--fabric", str(path), "--size", "8x8", "--out", str(out)],
                    capsys, tmp_path, [out])
    assert str(path) in line, line


def _gonio_text(project_root: Path, transform) -> str:
    lines = (project_root / "fabrics" / "measurements" / "voile-white" / "gonio.csv") \
        .read_text().splitlines()
    head = [i for i, ln in enumerate(lines) if ln.startswith("light_elevation_deg")][0]
    return "\n".join(lines[:head + 1] + [transform(ln) for ln in lines[head + 1:]]) + "\n"


@pytest.mark.parametrize("label, transform, named", [
    ("underscore digits", lambda ln: ln.rsplit(",", 1)[0] + ",0_029", "0_029"),
    ("values x1e300", lambda ln: ln.rsplit(",", 1)[0] + ","
     + repr(float(ln.rsplit(",", 1)[1]) * 1e300), "1e+12"),
])
def test_gonio_values_are_plain_decimals_within_reach(tmp_path, capsys, project_root, label,
                                                      transform, named):
    bad = tmp_path / "gonio.csv"
    bad.write_text(_gonio_text(project_root, transform))
    line = _refused(["fit", "--gonio", str(bad), "--name", "p", "--out", str(tmp_path / "p.toml")],
                    capsys, tmp_path, [tmp_path / "p.toml"])
    assert str(bad) in line and named in line, line


def test_sizes_are_read_from_headers_before_the_data(tmp_path, capsys, make_preset):
    """A BFC whose dimension line claims 1e9 rows and a PNG whose header claims 40000x40000
    are refused from their headers (the process stays small: nothing is allocated)."""
    import resource
    import struct
    import zlib

    bfc = tmp_path / "BIG.BFC"
    bfc.write_text("x\nBFC-450\n" + "\n".join(["; c"] * 8) + "\n380 1000000380 1 49 300 10\n"
                   "r:c: 300\n" + "x" * 20000)
    line = _refused(["bispectral", str(bfc), "--export", str(tmp_path / "x")], capsys,
                    tmp_path, [tmp_path / "x"])
    assert "1e+09" in line

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 40000, 40000, 8, 0, 0, 0, 0))
           + chunk(b"IDAT", zlib.compress(b"\x00" * 1000)) + chunk(b"IEND", b""))
    from catalog.core.errors import InputError
    from catalog.presets.patterns import read_image

    (tmp_path / "big.png").write_bytes(png)
    rss_before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with pytest.raises(InputError, match="big.png"):
        read_image(tmp_path / "big.png")
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - rss_before < 200_000  # KiB
    from catalog.core.validate import check_image_header

    with pytest.raises(InputError, match="40000x40000"):
        check_image_header("big.png", 40000, 40000, 1)
    check_image_header("ok.png", 4096, 4096, 4)


def test_snapshot_size_is_checked_against_the_gl_limits_before_allocating():
    from types import SimpleNamespace

    from catalog.core.errors import InputError
    from catalog.render.snapshot import check_gl_size

    llvmpipe = SimpleNamespace(info={"GL_RENDERER": "llvmpipe (LLVM 19.1.7, 256 bits)",
                                     "GL_MAX_TEXTURE_SIZE": 16384,
                                     "GL_MAX_RENDERBUFFER_SIZE": 16384,
                                     "GL_MAX_VIEWPORT_DIMS": (16384, 16384)})
    with pytest.raises(InputError, match="--size.*12000x12000.*1024 MiB"):
        check_gl_size(llvmpipe, (12000, 12000))
    check_gl_size(llvmpipe, (8000, 8000))  # 977 MiB: rendered (checked by hand here)
    small = SimpleNamespace(info={"GL_RENDERER": "NVIDIA H200", "GL_MAX_TEXTURE_SIZE": 8192})
    with pytest.raises(InputError, match="8192"):
        check_gl_size(small, (9000, 10))
    check_gl_size(small, (8192, 8192))  # a GPU has no software per-resource cap


def test_an_output_name_that_is_not_text_is_refused(tmp_path, capsys):
    name = os.fsdecode(bytes(tmp_path) + b"/bad\xff.png")
    line = _refused(["snapshot", "--fabric", "voile-white", "--size", "8x8", "--out", name],
                    capsys, tmp_path, [])
    assert "UTF-8" in line


# ---- the fuzz: generated garbage, never a traceback, never exit 0, no input changed ----

#: Typed garbage for a preset's fields: each value is wrong for every field it is put in.
_WRONG_NUMBER = st.one_of(st.text(max_size=6).map(repr), st.booleans().map(str).map(str.lower),
                          st.just("[1.0, 2.0]"), st.just("{ a = 1 }"), st.just("nan"),
                          st.just("-inf"), st.just("1e308"), st.just("-1e-9"))
_NUMBER_FIELDS = [("btdf", k) for k in ("direct", "k_d", "tau", "rho", "g_diff", "g_spec")] + [
    ("cloth", "areal_density_kg_m2"), ("cloth", "fullness"), ("cloth", "stretch_stiffness_n_m"),
    ("pattern", "height_m")]
_TEXT_FIELDS = [("cloth", "weave"), ("pattern", "coverage"), ("dye", "transmittance")]
_WRONG_TEXT = st.one_of(st.integers().map(str), st.just("[\"lace\"]"), st.just("true"),
                        st.just("{ x = 1 }"), st.just('""'), st.just('"no-such-weave"'))


@pytest.mark.slow
@settings(max_examples=40, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(field=st.sampled_from(_NUMBER_FIELDS + _TEXT_FIELDS), data=st.data())
def test_fuzz_preset_toml_garbage_is_refused(tmp_path, capsys, make_preset, field, data):
    table, key = field
    wrong = data.draw(_WRONG_TEXT if field in _TEXT_FIELDS else _WRONG_NUMBER)
    if wrong == "1e308" and key in ("k_d", "tau", "stretch_stiffness_n_m"):
        wrong = "nan"  # no upper bound there (or one above 1e308's reach): not garbage
    if wrong == "-1e-9" and key in ("g_diff", "g_spec"):
        wrong = "-1.0"  # (-1, 1): -1e-9 is a valid shape
    path = make_preset("fuzzed", fluorescent=False)
    text = path.read_text()
    if table == "btdf":
        text = re.sub(rf"(?m)^{key} = .*$", lambda _: f"{key} = {wrong}", text)
    else:
        text += f"\n[{table}]\n{key} = {wrong}\n"
        if table == "pattern" and key != "coverage":
            text += 'coverage = "none.png"\n'
    path.write_text(text)
    inputs = _inputs_digest([path])
    out = tmp_path / "o.png"
    out.unlink(missing_ok=True)  # hypothesis reuses the folder between examples
    _refused(["snapshot", "--fabric", str(path), "--size", "8x8", "--out", str(out)],
             capsys, tmp_path, [out])
    assert _inputs_digest([path]) == inputs


#: Every command's numeric options: (command argv without the option, option, low, high,
#: whole). Values are drawn outside the bounds, or malformed.
_NUMERIC_OPTIONS = [
    (["snapshot", "--fabric", "voile-white", "--out", "{tmp}/o.png"], opt, lo, hi, whole)
    for opt, lo, hi, whole in [("--frame", 0, 216000, True), ("--distance", 0.05, 50, False),
                               ("--exposure", 2 ** -20, 2 ** 20, False), ("--yaw", -360, 360, False),
                               ("--pitch", -89, 89, False)]
] + [
    (["reference", "--fabric", "voile-white", "--out", "{tmp}/r.exr"], opt, lo, hi, whole)
    for opt, lo, hi, whole in [("--frame", 0, 216000, True), ("--distance", 0.05, 50, False),
                               ("--spp", 1, 65536, True), ("--seed", 0, 2 ** 32 - 1, True),
                               ("--max-depth", 1, 256, True), ("--pitch", -89, 89, False)]
] + [
    (["render-catalog", "--fabrics", "voile-white", "--lights", "D65", "--out", "{tmp}/c"],
     opt, lo, hi, whole)
    for opt, lo, hi, whole in [("--distance", 0.05, 50, False), ("--exposure", 2 ** -20, 2 ** 20, False),
                               ("--pitch", -89, 89, False)]
] + [
    (["fit", "--gonio", "{gonio}", "--name", "p", "--out", "{tmp}/p.toml"], opt, lo, hi, whole)
    for opt, lo, hi, whole in [("--tau", 0, 50, False), ("--rho", 0, 1, False),
                               ("--quantum-yield", 0, 1, False)]
] + [
    (["fluorescence", "--excitation", "{spectra}/excitation.csv", "--emission",
      "{spectra}/emission.csv", "--light", "D65"], "--illuminance", 0, 1e6, False),
    (["simulate", "--grid", "8x8", "--out", "{tmp}/c.obj", "--steps", "2"], "--wind", 0, 50, False),
    (["simulate", "--grid", "8x8", "--out", "{tmp}/c.obj"], "--steps", 1, 10_000_000, True),
]


def _outside(low, high, whole):
    below = (st.integers(max_value=int(math.ceil(low)) - 1) if whole
             else st.floats(max_value=low, allow_nan=False, allow_infinity=False)
             .filter(lambda v: v < low))
    above = (st.integers(min_value=int(high) + 1) if whole
             else st.floats(min_value=high, allow_nan=False).filter(lambda v: v > high))
    malformed = st.sampled_from(["nan", "inf", "-inf", "1_0", "0x10", "", " ", "1e", "--1",
                                 "１", "1,5", "1e999", "NaN", "Infinity"])
    if whole:
        malformed = st.one_of(malformed, st.sampled_from(["1.5", "1e3", "2.0"]))
    return st.one_of(below.map(repr), above.map(repr), malformed)


@settings(max_examples=10, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(case=st.sampled_from(_NUMERIC_OPTIONS), data=st.data())
def test_fuzz_numeric_options_garbage_is_refused(tmp_path, capsys, project_root, case, data):
    argv, option, low, high, whole = case
    value = data.draw(_outside(low, high, whole))
    if option == "--rho" and value in ("0", "0.0"):
        value = "-0.5"
    fills = {"{tmp}": str(tmp_path), "{spectra}": str(project_root / "fabrics" / "measurements"
                                                       / "lace-fwa"),
             "{gonio}": str(project_root / "fabrics" / "measurements" / "voile-white" / "gonio.csv")}
    args = [a for a in argv]
    for key, fill in fills.items():
        args = [a.replace(key, fill) for a in args]
    line = _refused(args + [f"{option}={value}"], capsys, tmp_path, [])
    assert option in line, line


@pytest.mark.slow
@settings(max_examples=120, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])
@given(case=st.sampled_from(_NUMERIC_OPTIONS), data=st.data())
def test_fuzz_numeric_options_garbage_is_refused_long(tmp_path, capsys, project_root, case, data):
    test_fuzz_numeric_options_garbage_is_refused.hypothesis.inner_test(
        tmp_path, capsys, project_root, case, data)


# ---- signals (subprocesses) ----

def _signal_run(argv: list[str], delay_s: float, signum: int, tmp_path: Path):
    import signal as signal_lib  # noqa: F401
    import subprocess
    import sys
    import time

    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parent.parent))
    proc = subprocess.Popen([sys.executable, "-m", "catalog", *argv], env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    time.sleep(delay_s)
    sent = time.monotonic()
    proc.send_signal(signum)
    _, err = proc.communicate(timeout=30)
    return proc.returncode, time.monotonic() - sent, err


@pytest.mark.slow
@pytest.mark.parametrize("signum", [15, 2])
def test_reference_honours_signals_inside_the_mitsuba_render(tmp_path, signum):
    """SIGTERM/SIGINT while Mitsuba renders (native code, the main thread never returns to
    Python): exit 143/130 within a second, the old EXR untouched, no temporary left."""
    from catalog.core.atomic import TEMP_MARK

    out = tmp_path / "r.exr"
    out.write_bytes(b"the old reference")
    status, latency, err = _signal_run(["reference", "--fabric", "voile-white", "--size", "64x48",
                                        "--spp", "4096", "--out", str(out)], 7.0, signum, tmp_path)
    assert status == 128 + signum, err
    assert latency < 1.0 and "Traceback" not in err
    assert out.read_bytes() == b"the old reference"
    assert not [p for p in tmp_path.iterdir() if TEMP_MARK in p.name]
