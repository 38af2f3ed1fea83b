"""The hostile-input suite: a fixed corpus of bad files, options and output faults run
through every command, each outcome classified.

A case passes ("refused cleanly") when the command exits 2 (or 143/130 for a signal), prints
exactly one error line naming the file, key or option it was given, no traceback, and leaves
the folder it ran in as it was (its intended output absent, any file already there
untouched). The other outcomes counted: ``traceback``, ``accepted`` (exit 0 on bad input),
``vague`` (refused, but the line does not name what was given), ``litter`` (refused, but
something was left or changed).

    python -m benchmarks.hostile [--json benchmarks/hostile_inputs.json]

Cases run in process through ``catalog.commands.cli.main`` (fast), except those that need a
real fault around the process (a closed or full stdout), which run as subprocesses. The
property-based version of the same categories is tests/test_cli_hostile.py.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

from catalog.core.resources import FABRIC_DIR, PROJECT_ROOT

GOOD_SPECTRA = FABRIC_DIR / "measurements" / "lace-fwa"
#: A file outside any fabric folder that a hostile preset may name (absolute), and a climb
#: out of the preset's folder to the root (joined with it, the same file relatively).
OUTSIDE = str(Path(os.__file__).resolve())
_CLIMB = "/".join([".."] * 12)
GOOD_PRESET = """schema = 1
name = "{name}"
display_name = "test"
[btdf]
direct = 0.1
k_d = 0.7
k_s = 0.5
tau = 0.2
rho = 0.8
g_diff = 0.2
g_spec = 0.9
"""


@dataclass(frozen=True)
class Case:
    category: str
    label: str
    argv: tuple[str, ...]          # {dir} is the case's folder, {bad} the bad file
    bad_file: str | None = None    # text of the bad input file (written as {bad})
    bad_name: str = "bad.csv"
    names: str = ""                # what the error line must contain ({bad}, an option)
    stdout: str | None = None      # "closed" or "full": run as a subprocess with that stdout


def _spectrum_cases() -> list[Case]:
    texts = {
        "no header": "300,0.1\n301,0.2\n", "wrong header": "nm,value\n300,0.1\n301,0.2\n",
        "NaN": "wavelength_nm,intensity\n300,0.1\n301,nan\n",
        "infinite": "wavelength_nm,intensity\n300,0.1\n301,inf\n",
        "negative": "wavelength_nm,intensity\n300,0.1\n301,-1\n",
        "unsorted": "wavelength_nm,intensity\n301,0.1\n300,0.2\n",
        "duplicate": "wavelength_nm,intensity\n300,0.1\n300,0.2\n",
        "one row": "wavelength_nm,intensity\n300,0.1\n", "empty": "",
        "binary": "\x00\x01\x02PNG\x89", "all zero": "wavelength_nm,intensity\n300,0\n301,0\n",
        "extra column": "wavelength_nm,intensity,x\n300,0.1,1\n301,0.2,1\n",
        "text value": "wavelength_nm,intensity\n300,abc\n301,0.2\n",
        "/etc/passwd-like": "root:x:0:0:root:/root:/bin/bash\n",
    }
    cases = []
    for which in ("--excitation", "--emission"):
        other = "--emission" if which == "--excitation" else "--excitation"
        for label, text in texts.items():
            cases.append(Case("spectrum CSV", f"{which}: {label}",
                              ("fluorescence", which, "{bad}", other,
                               str(GOOD_SPECTRA / f"{other[2:]}.csv"), "--light", "D65",
                               "--plot", "{dir}/p.png"), text, names="{bad}"))
    return cases


def _gonio_cases() -> list[Case]:
    header = "light_elevation_deg,light_azimuth_deg,camera_elevation_deg,camera_azimuth_deg,transmittance"
    texts = {
        "no header": "180,0,90,0,1\n", "NaN": f"{header}\n180,0,90,0,nan\n180,0,80,0,1\n",
        "angle out of range": f"{header}\n400,0,90,0,1\n180,0,80,0,1\n",
        "all zero": f"{header}\n180,0,90,0,0\n180,0,80,0,0\n180,0,70,0,0\n",
        "short row": f"{header}\n180,0,90\n", "empty": "",
        "rgb half": f"{header},r,g\n180,0,90,0,1,1,1\n",
    }
    return [Case("gonio CSV", label, ("fit", "--gonio", "{bad}", "--name", "p",
                                      "--out", "{dir}/p.toml"), text, names="{bad}")
            for label, text in texts.items()]


def _bfc_cases() -> list[Case]:
    head = "\n".join(["; header"] * 10)
    texts = {
        "empty": "", "not BFC": "hello\nworld\n" + head,
        "truncated": "x\nBFC-450\n" + head[:20],
        "bad dimension line": "x\nBFC-450\n" + "\n".join(["; c"] * 8) + "\n380 780 x 41 300 10\nr:c:\n",
        "binary": "\x00\xff\x00BFC",
    }
    return [Case("bispectral BFC", label, ("bispectral", "{bad}", "--export", "{dir}/x"),
                 text, bad_name="BAD.BFC", names="{bad}") for label, text in texts.items()]


def _preset_cases() -> list[Case]:
    good = GOOD_PRESET.format(name="bad")
    edits = {
        "direct > 1": good.replace("direct = 0.1", "direct = 1.5"),
        "g_spec = 1": good.replace("g_spec = 0.9", "g_spec = 1.0"),
        "rho = 0": good.replace("rho = 0.8", "rho = 0.0"),
        "tau NaN": good.replace("tau = 0.2", "tau = nan"),
        "k_d text": good.replace("k_d = 0.7", 'k_d = "high"'),
        "missing g_diff": good.replace("g_diff = 0.2\n", ""),
        "schema 2": good.replace("schema = 1", "schema = 2"),
        "name differs": good.replace('name = "bad"', 'name = "other"'),
        "not TOML": good[:40] + "\n[[[",
        "quantum yield 5": good + '[fluorescence]\nxyz = [1.0, 1.0, 1.0]\nrgb = [1.0, 1.0, 1.0]\n'
                           'excitation = "e.csv"\nemission = "e.csv"\nquantum_yield = 5.0\n',
        # OUTSIDE: a file of the machine's, named by an absolute path and by climbing up
        "spectrum outside its folder": good + '[fluorescence]\nxyz = [1.0, 1.0, 1.0]\n'
                                       f'rgb = [1.0, 1.0, 1.0]\nexcitation = "{OUTSIDE}"\n'
                                       f'emission = "{OUTSIDE}"\n',
        "dye outside its folder": good + f'[dye]\ntransmittance = "{_CLIMB}{OUTSIDE}"\n',
        "fit NaN": good + "[fit]\nrmse = nan\n",
    }
    return [Case("preset TOML", label, ("snapshot", "--fabric", "{bad}", "--size", "8x8",
                                        "--out", "{dir}/o.png"), text, bad_name="bad.toml",
                 names="{bad}") for label, text in edits.items()]


def _option_cases() -> list[Case]:
    snap = ("snapshot", "--fabric", "voile-white", "--out", "{dir}/o.png")
    sim = ("simulate", "--grid", "8x8", "--steps", "2", "--out", "{dir}/c.obj")
    rows = [
        (snap + ("--size", "0x10"), "--size"), (snap + ("--size", "99999x99999"), "--size"),
        (snap + ("--size", "16000x16000"), "size"), (snap + ("--size", "axb"), "--size"),
        (snap + ("--light", "D66"), "D66"), (snap + ("--light", "sun:0"), "sun:0"),
        (snap + ("--light", "sun@2026-13-01T12:00,0,0"), "sun@"),
        (snap + ("--bands", "5"), "--bands"), (snap + ("--frame", "-1"), "--frame"),
        (snap + ("--distance", "0"), "--distance"), (snap + ("--distance", "nan"), "--distance"),
        (snap + ("--exposure", "-1"), "--exposure"), (snap + ("--hour", "25"), "--hour"),
        (snap + ("--hour", "2"), "--hour"), (snap + ("--fabric", "nope"), "nope"),
        (snap + ("--mode", "spectral"), "--mode"), (snap + ("--yaw", "inf"), "--yaw"),
        (sim[:2] + ("0x4",) + sim[3:], "--grid"), (sim + ("--dt", "0"), "--dt"),
        (sim + ("--wind", "nan"), "--wind"), (sim + ("--wind", "1e9"), "--wind"),
        (sim + ("--stiffness", "-5"), "--stiffness"), (sim + ("--backend", "cuda"), "--backend"),
        (("simulate", "--grid", "5000x5000", "--steps", "1"), "--grid"),
        (("sheet", "--lights", "D65,,A", "--size", "8x8", "--out", "{dir}/s"), "--lights"),
        (("sheet", "--lights", "", "--size", "8x8", "--out", "{dir}/s"), "--lights"),
        (("fluorescence", "--excitation", str(GOOD_SPECTRA / "excitation.csv"), "--emission",
          str(GOOD_SPECTRA / "emission.csv"), "--light", "D65", "--quantum-yield", "1.5"),
         "--quantum-yield"),
        (("lights", "--names", "D65,nope", "--plot", "{dir}/l.png"), "nope"),
        (("sun", "--paths", "22,-5"), "--paths"),
        (("bench", "--sections", "nope", "--out", "{dir}/b"), "nope"),
        (("reference", "--fabric", "voile-white", "--spp", "0", "--size", "8x8",
          "--out", "{dir}/r.exr"), "--spp"),
        (("reference", "--fabric", "voile-white", "--variant", "cuda_rgb", "--size", "8x8",
          "--spp", "1", "--out", "{dir}/r.exr"), "--variant"),
        (("render-catalog", "--fabric", "voile-white", "--lights", "D65", "--frames", "3:1",
          "--size", "8x8", "--format", "png", "--out", "{dir}/c"), "--frames"),
        (("render-catalog", "--fabric", "voile-white", "--lights", "D65", "--frames", "0:1",
          "--size", "8x8", "--format", "tiff", "--out", "{dir}/c"), "--format"),
        (("web", "--lights", "D65,nope", "--out", "{dir}/site"), "nope"),
        (("web", "--fabric", "nope", "--out", "{dir}/site"), "nope"),
    ]
    return [Case("options", " ".join(a for a in argv if not a.startswith("{dir}"))[:60], argv,
                 names=name) for argv, name in rows]


def _output_cases() -> list[Case]:
    lights_json = ("lights", "--json")
    rows = [
        (("snapshot", "--fabric", "voile-white", "--size", "8x8", "--out", "{dir}"), "--out"),
        (("snapshot", "--fabric", "voile-white", "--size", "8x8", "--out", "{dir}/keep.txt/x.png"),
         "--out"),
        (("sheet", "--lights", "D65", "--size", "8x8", "--out", "{dir}/keep.txt"), "--out"),
        (("lights", "--plot", "{dir}"), "--plot"), (("sun", "--plot", "{dir}/keep.txt/p.png"), "--plot"),
        (("simulate", "--grid", "8x8", "--steps", "1", "--out", "{dir}"), "--out"),
        (("fit", "--gonio", "{dir}/keep.txt", "--name", "keep", "--out", "{dir}/keep.txt"), "--out"),
        (("bench", "--quick", "--out", "{dir}/keep.txt"), "--out"),
        (("bispectral", "{dir}/keep.txt", "--export", "{dir}/keep.txt"), "keep.txt"),
    ]
    cases = [Case("outputs", " ".join(argv[:1] + argv[-2:-1]) + f" -> {name}", argv, names=name)
             for argv, name in rows]
    cases += [Case("outputs", f"stdout {how}", lights_json, names="stdout", stdout=how)
              for how in ("closed", "full")]
    return cases


def _round_two_cases() -> list[Case]:
    """The red team's second round (issue 37), one case per class member."""
    header = ("light_elevation_deg,light_azimuth_deg,camera_elevation_deg,camera_azimuth_deg,"
              "transmittance")
    gonio = str(FABRIC_DIR / "measurements" / "voile-white" / "gonio.csv")
    good = GOOD_PRESET.format(name="bad")
    cases = [
        # an input overwritten by an output
        Case("inputs overwritten", "snapshot --environment X --out X",
             ("snapshot", "--fabric", "voile-white", "--size", "8x8", "--environment", "{bad}",
              "--out", "{bad}"), "not read: refused first", bad_name="env.exr", names="own input"),
        Case("inputs overwritten", "fit --dye D --plot D",
             ("fit", "--gonio", gonio, "--dye", "{bad}", "--name", "p", "--out", "{dir}/p.toml",
              "--plot", "{bad}"), "wavelength_nm,transmittance\n400,0.5\n700,0.5\n",
             bad_name="d.png", names="own input"),
        Case("inputs overwritten", "fit --out onto --gonio",
             ("fit", "--gonio", "{bad}", "--name", "bad", "--out", "{bad}"), "x",
             bad_name="bad.toml", names="own input"),
        Case("inputs overwritten", "snapshot --out onto its own preset",
             ("snapshot", "--fabric", "{bad}", "--size", "8x8", "--out", "{bad}"), good,
             bad_name="bad.toml", names="own input"),
    ]
    bounds = [
        (("snapshot", "--fabric", "voile-white", "--frame", "1000000000000", "--out", "{dir}/o.png"), "--frame"),
        (("reference", "--fabric", "voile-white", "--frame", "216001", "--out", "{dir}/r.exr"), "--frame"),
        (("render-catalog", "--fabrics", "voile-white", "--lights", "D65", "--frames", "0:50000000",
          "--out", "{dir}/c"), "--frames"),
        (("reference", "--fabric", "voile-white", "--size", "16384x16384", "--out", "{dir}/r.exr"), "--size"),
        (("simulate", "--grid", "8x8", "--steps", "2", "--out", "{dir}/f{frame:0999999999999d}.obj"), "--out"),
    ]
    cases += [Case("bounds", " ".join(a for a in argv if "{dir}" not in a)[:60], argv, names=name)
              for argv, name in bounds]
    garbage = [
        (("render-catalog", "--fabrics", "voile-white", "--lights", "D65", "--distance", "1e308",
          "--out", "{dir}/c"), "--distance"),
        (("render-catalog", "--fabrics", "voile-white", "--lights", "D65", "--exposure", "1e308",
          "--out", "{dir}/c"), "--exposure"),
        (("reference", "--fabric", "voile-white", "--pitch", "90", "--out", "{dir}/r.exr"), "--pitch"),
        (("reference", "--fabric", "voile-white", "--pitch", "1e308", "--out", "{dir}/r.exr"), "--pitch"),
        (("reference", "--fabric", "voile-white", "--seed", "-1", "--out", "{dir}/r.exr"), "--seed"),
        (("reference", "--fabric", "voile-white", "--seed", str(1 << 64), "--out", "{dir}/r.exr"), "--seed"),
        (("snapshot", "--fabric", "voile-white", "--exposure", "1e-300", "--out", "{dir}/o.png"), "--exposure"),
        (("snapshot", "--fabric", "voile-white", "--distance", "0.01", "--out", "{dir}/o.png"), "(0.05"),
        (("snapshot", "--fabric", "voile-white", "--yaw", "1_0", "--out", "{dir}/o.png"), "--yaw"),
        (("fit", "--gonio", gonio, "--name", "p", "--out", "{dir}/p.toml", "--tau", "inf"), "--tau"),
        (("fit", "--gonio", gonio, "--name", "p", "--out", "{dir}/p.toml", "--plot", "{dir}/p.txt"), "--plot"),
        (("fit", "--gonio", gonio, "--name", "p", "--out", "{dir}/p.toml", "--plot", "{dir}/p"), "--plot"),
        (("fluorescence", "--excitation", str(GOOD_SPECTRA / "excitation.csv"), "--emission",
          str(GOOD_SPECTRA / "emission.csv"), "--light", "D65", "--illuminance", "1e308"), "--illuminance"),
        (("sheet", "--lights", "D65,D65", "--size", "8x8", "--out", "{dir}/s"), "--lights"),
        (("render-catalog", "--fabrics", "voile-white", "--lights", "A,A", "--out", "{dir}/c"), "--lights"),
        (("web", "--lights", "", "--out", "{dir}/site"), "--lights"),
        (("sheet", "--lights", "sun@2026-13-21T12:00,34.7,-120", "--size", "8x8", "--out", "{dir}/s"),
         "sun@2026-13-21T12:00,34.7,-120"),
    ]
    cases += [Case("options, round two", " ".join(a for a in argv if "{dir}" not in a)[:60], argv,
                   names=name) for argv, name in garbage]
    presets = {
        "cloth.weave a list": good + '[cloth]\nweave = ["lace"]\n',
        "pattern a string": good.replace("[btdf]", 'pattern = "x"\n[btdf]'),
        "cloth a number": good.replace("[btdf]", "cloth = 5\n[btdf]"),
        "nested 5000 deep": good + "[deep]\nx = " + "[" * 5000 + "]" * 5000 + "\n",
        "cloth.fullness text": good + '[cloth]\nfullness = "full"\n',
    }
    cases += [Case("preset types", label, ("snapshot", "--fabric", "{bad}", "--size", "8x8",
                                           "--out", "{dir}/o.png"), text, bad_name="bad.toml",
                   names="{bad}") for label, text in presets.items()]
    rows = "\n".join(["180,0,90,0,0_029", "180,0,80,0,0.5", "180,0,70,0,0.4"])
    huge = "\n".join(["180,0,90,0,1e300", "180,0,80,0,5e299", "180,0,70,0,4e299"])
    cases += [Case("gonio CSV", label, ("fit", "--gonio", "{bad}", "--name", "p", "--out",
                                        "{dir}/p.toml"), f"{header}\n{text}\n", names="{bad}")
              for label, text in (("underscore digits 0_029", rows), ("values x1e300", huge))]
    head = "x\nBFC-450\n" + "\n".join(["; c"] * 8)
    cases.append(Case("bispectral BFC", "dimension line claims 1e9 rows",
                      ("bispectral", "{bad}", "--export", "{dir}/x"),
                      head + "\n380 1000000380 1 49 300 10\nr:c: 300\n" + "x" * 20000,
                      bad_name="BAD.BFC", names="{bad}"))
    return cases


def corpus() -> list[Case]:
    return (_spectrum_cases() + _gonio_cases() + _bfc_cases() + _preset_cases()
            + _option_cases() + _output_cases() + _round_two_cases())


def _tree(folder: Path) -> dict[str, tuple[int, int]]:
    return {str(p.relative_to(folder)): (p.stat().st_size, p.stat().st_mtime_ns)
            for p in sorted(folder.rglob("*"))}


def _run(case: Case, folder: Path) -> tuple[int, str]:
    argv = [a.replace("{dir}", str(folder)).replace("{bad}", str(folder / case.bad_name))
            for a in case.argv]
    if case.stdout is not None:
        env = dict(os.environ, PYTHONPATH=str(PROJECT_ROOT))
        cmd = [sys.executable, "-m", "catalog", *argv]
        if case.stdout == "closed":
            done = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                                  env=env, timeout=300, preexec_fn=lambda: os.close(1))
        else:
            with open("/dev/full", "w") as full:
                done = subprocess.run(cmd, stdout=full, stderr=subprocess.PIPE, text=True,
                                      env=env, timeout=300)
        return done.returncode, done.stderr
    from catalog.commands.cli import main  # noqa: PLC0415

    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            status = main(argv)
        except SystemExit as exc:
            status = exc.code if isinstance(exc.code, int) else 1
        except BaseException:  # noqa: BLE001 - a crash is what this suite counts
            import traceback  # noqa: PLC0415

            traceback.print_exc(file=err)
            status = 1
    return status, err.getvalue()


def classify(case: Case, folder: Path) -> str:
    if case.bad_file is not None:
        (folder / case.bad_name).write_bytes(case.bad_file.encode("utf-8", "surrogatepass"))
    (folder / "keep.txt").write_text("the user's own file\n")
    before = _tree(folder)
    status, stderr = _run(case, folder)
    if "Traceback" in stderr:
        return "traceback"
    if status == 0:
        return "accepted"
    lines = [ln for ln in stderr.splitlines() if "error:" in ln]
    wanted = case.names.replace("{bad}", str(folder / case.bad_name)).replace("{dir}", str(folder))
    if status != 2 or len(lines) != 1 or wanted not in lines[0]:
        return "vague"
    if _tree(folder) != before:
        return "litter"
    return "refused cleanly"


OUTCOMES = ("refused cleanly", "vague", "litter", "accepted", "traceback")


def run_suite(cases: list[Case] | None = None) -> dict:
    cases = corpus() if cases is None else cases
    rows, failures = {}, []
    for case in cases:
        with tempfile.TemporaryDirectory(prefix="hostile-") as tmp:
            outcome = classify(case, Path(tmp))
        counts = rows.setdefault(case.category, dict.fromkeys(OUTCOMES, 0))
        counts[outcome] += 1
        if outcome != "refused cleanly":
            failures.append({"category": case.category, "case": case.label, "outcome": outcome})
    total = {k: sum(r[k] for r in rows.values()) for k in OUTCOMES}
    from benchmarks.kill_trials import _commit  # noqa: PLC0415

    return {"categories": rows, "total": total, "cases": len(cases), "failures": failures,
            "commit": _commit()}


#: The committed result the docs' generated blocks are made from (tools/docs_figures.py).
RESULT_JSON = "benchmarks/hostile_inputs.json"

def markdown_tables(result: dict) -> dict[str, str]:
    head = "| category | cases | " + " | ".join(OUTCOMES) + " |\n|---|---|" + "---|" * len(OUTCOMES)
    lines = [head]
    for name, counts in [*result["categories"].items(), ("all", result["total"])]:
        n = sum(counts.values())
        label = f"**{name}**" if name == "all" else name
        lines.append(f"| {label} | {n} | " + " | ".join(str(counts[k]) for k in OUTCOMES) + " |")
    if result.get("commit"):
        lines += ["", f"Measured on commit {result['commit']}."]
    return {"hostile": "\n".join(lines)}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--json", type=Path, default=PROJECT_ROOT / "benchmarks" / "hostile_inputs.json")
    args = parser.parse_args(argv)
    result = run_suite()
    print(markdown_tables(result)["hostile"])
    for failure in result["failures"]:
        print(f"  not clean: {failure['category']}: {failure['case']} -> {failure['outcome']}")
    from catalog.core.atomic import write_text_atomic  # noqa: PLC0415

    write_text_atomic(args.json, json.dumps(result, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
