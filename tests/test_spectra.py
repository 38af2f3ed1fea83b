"""The spectrum CSV reader (formats.md): every bad input is refused naming file, line and problem."""

from __future__ import annotations

import numpy as np
import pytest

from catalog.core.errors import InputError
from catalog.optics.spectra import GRID_NM, Spectrum, read_spectrum, resample, write_spectrum

HEADER = "wavelength_nm,intensity"


def _write(tmp_path, text: str, name: str = "s.csv"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def _refused(path, line: int | None, *words: str) -> InputError:
    with pytest.raises(InputError) as caught:
        read_spectrum(path)
    message = str(caught.value)
    assert str(path) in message
    if line is not None:
        assert f"{path}:{line}:" in message, message
        assert caught.value.line == line
    for word in words:
        assert word.lower() in message.lower(), message
    assert "\n" not in message  # one line
    return caught.value


def test_good_file_with_comments_is_read(tmp_path):
    path = _write(tmp_path, "# instrument: FluoroMax-2\n# excited at 340 nm\n"
                            f"{HEADER}\n300.0,0.5\n300.5,1.0\n# a comment between rows\n301.0,0.25\n")
    spectrum = read_spectrum(path)
    np.testing.assert_array_equal(spectrum.wavelength_nm, [300.0, 300.5, 301.0])
    np.testing.assert_array_equal(spectrum.values, [0.5, 1.0, 0.25])
    assert spectrum.comments[:2] == ("instrument: FluoroMax-2", "excited at 340 nm")
    assert spectrum.peak_nm == 300.5


def test_normalise_scales_to_peak_one(tmp_path):
    path = _write(tmp_path, f"{HEADER}\n400,2\n410,8\n420,4\n")
    spectrum = read_spectrum(path, normalise=True)
    np.testing.assert_allclose(spectrum.values, [0.25, 1.0, 0.5], rtol=0, atol=0)


def test_missing_header(tmp_path):
    path = _write(tmp_path, "# comment\n300,0.1\n301,0.2\n")
    _refused(path, 2, "header")


def test_wrong_header_names(tmp_path):
    path = _write(tmp_path, "wavelength,value\n300,0.1\n301,0.2\n")
    _refused(path, 1, "header", "wavelength_nm,intensity")


@pytest.mark.parametrize("bad", ["nan", "NaN"])
def test_nan(tmp_path, bad):
    path = _write(tmp_path, f"{HEADER}\n300,0.1\n301,{bad}\n302,0.2\n")
    _refused(path, 3, "nan")


def test_nan_wavelength(tmp_path):
    path = _write(tmp_path, f"{HEADER}\n300,0.1\nnan,0.2\n302,0.2\n")
    _refused(path, 3, "nan")


def test_infinite(tmp_path):
    path = _write(tmp_path, f"{HEADER}\n300,0.1\n301,inf\n")
    _refused(path, 3, "infinite")


def test_negative_value(tmp_path):
    path = _write(tmp_path, f"{HEADER}\n300,0.1\n301,-0.002\n302,0.2\n")
    _refused(path, 3, "negative")


def test_negative_wavelength(tmp_path):
    path = _write(tmp_path, f"{HEADER}\n-1,0.1\n301,0.2\n")
    _refused(path, 2, "negative")


def test_unsorted_wavelengths(tmp_path):
    path = _write(tmp_path, f"{HEADER}\n300,0.1\n302,0.2\n301,0.3\n")
    _refused(path, 4, "not increasing")


def test_duplicate_wavelengths(tmp_path):
    path = _write(tmp_path, f"{HEADER}\n# c\n300,0.1\n301,0.2\n301,0.3\n")
    _refused(path, 5, "duplicate")


def test_one_row_is_too_few(tmp_path):
    path = _write(tmp_path, f"{HEADER}\n300,0.1\n")
    _refused(path, 1, "1 data row")


def test_header_only_is_too_few(tmp_path):
    path = _write(tmp_path, f"# only a header\n{HEADER}\n")
    _refused(path, 2, "0 data row")


def test_empty_file(tmp_path):
    path = _write(tmp_path, "")
    _refused(path, 1, "empty")


def test_only_comments_and_blank_lines_is_empty(tmp_path):
    path = _write(tmp_path, "# nothing here\n\n   \n")
    _refused(path, 1, "empty")


def test_not_a_number(tmp_path):
    path = _write(tmp_path, f"{HEADER}\n300,0.1\n301,abc\n")
    _refused(path, 3, "not a number", "abc")


def test_wrong_field_count(tmp_path):
    path = _write(tmp_path, f"{HEADER}\n300,0.1\n301,0.2,7\n")
    _refused(path, 3, "expected 2 fields")


def test_missing_file(tmp_path):
    path = tmp_path / "absent.csv"
    with pytest.raises(InputError) as caught:
        read_spectrum(path)
    assert str(path) in str(caught.value) and "no such file" in str(caught.value)


def test_zero_everywhere_cannot_be_normalised(tmp_path):
    path = _write(tmp_path, f"{HEADER}\n300,0\n301,0\n")
    with pytest.raises(InputError) as caught:
        read_spectrum(path, normalise=True)
    assert str(path) in str(caught.value) and "zero everywhere" in str(caught.value)


def test_resample_is_linear_and_zero_outside():
    wl = np.array([400.0, 402.5, 410.0])
    values = np.array([1.0, 2.0, 0.5])
    grid = GRID_NM
    out = resample(wl, values, grid)
    # Independent reference: the straight line between the bracketing samples.
    for g, o in zip(grid, out):
        if g < 400 or g > 410:
            assert o == 0.0
        elif g <= 402.5:
            assert o == pytest.approx(1.0 + (g - 400) / 2.5 * 1.0, abs=1e-15)
        else:
            assert o == pytest.approx(2.0 + (g - 402.5) / 7.5 * (0.5 - 2.0), abs=1e-15)


def test_spectrum_resample_on_the_project_grid():
    spectrum = Spectrum(np.array([299.5, 780.5]), np.array([1.0, 1.0]))
    np.testing.assert_array_equal(spectrum.resample(), np.ones(GRID_NM.size))


def test_write_then_read_round_trip(tmp_path):
    path = tmp_path / "sub" / "w.csv"
    wl = np.arange(350.0, 360.5, 0.5)
    values = np.linspace(0.0, 1.0, wl.size) ** 2
    write_spectrum(path, wl, values, ["made by a test"])
    back = read_spectrum(path)
    np.testing.assert_allclose(back.wavelength_nm, wl, rtol=0, atol=1e-9)
    np.testing.assert_allclose(back.values, values, rtol=1e-7, atol=1e-12)
    assert back.comments == ("made by a test",)
    assert [p.name for p in path.parent.iterdir()] == ["w.csv"]  # no temporary left
