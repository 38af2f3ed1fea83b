"""A dense fabric hides the outside (issue 33): under daylight the curtain of `linen-dense`
carries no more of the outside's detail than the reference shows.

The measure (benchmarks/see_through.py): on the curtain's pixels of the default view, the
relative high-pass energy of luminance H = mean((Y - G * Y)^2) / mean(Y)^2 (G a Gaussian of
1.5 px), the reference's own noise removed with its two halves. Bound (the issue's): frame /
reference within 1.5x either way. The reference at 128 spp (its noise is subtracted). Met at
noon; missed at 8, 17 and 19 h (a strict xfail with the figures).
"""

from __future__ import annotations

import numpy as np
import pytest


def test_high_pass_energy_closed_forms():
    """H of a flat image is 0; of a checkerboard (all energy above the blur's band) close to
    its closed form (the blur leaves almost nothing of a 1-px checker: H -> contrast^2); the
    noise image's energy is subtracted."""
    pytest.importorskip("scipy")
    from benchmarks.see_through import high_pass_energy

    mask = np.ones((40, 60), dtype=bool)
    mask[:3] = mask[-3:] = False
    mask[:, :3] = mask[:, -3:] = False
    flat = np.full((40, 60), 2.0)
    assert high_pass_energy(flat, mask) == 0.0
    checker = 2.0 + 0.5 * (np.indices((40, 60)).sum(axis=0) % 2 * 2 - 1)
    assert high_pass_energy(checker, mask) == pytest.approx((0.5 / 2.0) ** 2, rel=0.05)
    assert high_pass_energy(checker, mask, noise=checker - 2.0) == pytest.approx(0.0, abs=1e-12)


def _ratios(hours) -> dict:
    """The measure in a child process: Mitsuba's JIT and an EGL context in the suite's own
    process (after the hundreds of frames and references other tests drew in it) crashed it
    once in a full run (a segfault inside mi.render), never alone."""
    pytest.importorskip("mitsuba")
    import json
    import subprocess
    import sys

    code = ("import json, sys; from benchmarks.see_through import run; "
            f"rows = run('linen-dense', spp=128, hours={tuple(hours)!r})['rows']; "
            "print(json.dumps({str(r['hour']): r['ratio'] for r in rows}))")
    from catalog.core.resources import PROJECT_ROOT

    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=1200,
                          cwd=PROJECT_ROOT)   # (python -c puts the cwd first: benchmarks/ there)
    assert done.returncode == 0, done.stderr[-2000:]
    return {float(h): r for h, r in json.loads(done.stdout.strip().splitlines()[-1]).items()}


@pytest.mark.slow
def test_dense_linen_hides_the_outside_at_noon():
    """Measured 1.31 at 12 h (128 spp)."""
    ratio = _ratios((12.0,))[12.0]
    assert ratio is not None and 1 / 1.5 <= ratio <= 1.5, ratio


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="issue 33 goal missed: frame / reference 1.58 at 8 h, 1.56 at "
                                      "17 h, 3.24 at 19 h (128 spp, 160x90): the frame's dense linen "
                                      "shows more of the low sun's detail than the reference")
def test_dense_linen_hides_the_outside_under_every_daylight():
    ratios = _ratios((8.0, 17.0, 19.0))
    for hour, ratio in ratios.items():
        assert ratio is not None and 1 / 1.5 <= ratio <= 1.5, ratios
