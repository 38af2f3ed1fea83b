"""Import Mitsuba 3 with an LLVM library that its JIT can use.

Dr.Jit's LLVM backend loads ``libLLVM`` at run time. Mesa's LLVM 14/15 (what the GL
rasteriser brings) fails in the JIT ("Cannot select fminimum"); LLVM 19 works. The path
is taken from ``DRJIT_LIBLLVM_PATH`` when set, else from the usual Debian/Ubuntu places
(tools/setup.sh installs ``libllvm19``). A missing library is an environment failure
(:class:`catalog.core.errors.EnvironmentFailure`, exit 3), reported in one line.
"""

from __future__ import annotations

import glob
import os

from catalog.core.errors import EnvironmentFailure, InputError

#: The variants a reference may use: RGB (default) or spectral, both on the CPU.
VARIANTS = ("llvm_ad_rgb", "llvm_ad_spectral")
DEFAULT_VARIANT = "llvm_ad_rgb"
#: The oldest LLVM major version the JIT is known to work with here.
MIN_LLVM_MAJOR = 16
_SEARCH = ("/usr/lib/x86_64-linux-gnu/libLLVM-{v}.so", "/usr/lib/x86_64-linux-gnu/libLLVM.so.{v}*",
           "/usr/lib/aarch64-linux-gnu/libLLVM-{v}.so", "/usr/lib/aarch64-linux-gnu/libLLVM.so.{v}*",
           "/usr/lib/llvm-{v}/lib/libLLVM.so*", "/usr/lib/llvm-{v}/lib/libLLVM-{v}.so",
           "/usr/local/lib/libLLVM-{v}.so", "/opt/homebrew/opt/llvm@{v}/lib/libLLVM.dylib")


def find_llvm() -> str | None:
    """Path of a usable libLLVM (``DRJIT_LIBLLVM_PATH`` first, then LLVM 22..16), or None."""
    given = os.environ.get("DRJIT_LIBLLVM_PATH")
    if given:
        return given if os.path.isfile(given) else None
    for version in range(22, MIN_LLVM_MAJOR - 1, -1):
        for pattern in _SEARCH:
            hits = sorted(glob.glob(pattern.format(v=version)))
            if hits:
                return hits[0]
    return None


def check_variant(variant: str) -> str:
    if variant not in VARIANTS:
        raise InputError(f"unknown variant {variant!r}; choose {' or '.join(VARIANTS)}",
                         field="--variant")
    return variant


_LOADED: dict[str, object] = {}


def load_mitsuba(variant: str = DEFAULT_VARIANT):
    """The ``mitsuba`` module with ``variant`` set (the woven BSDF, the glow texture and the
    window filter registered)."""
    check_variant(variant)
    if variant in _LOADED:
        import mitsuba as mi  # noqa: PLC0415

        mi.set_variant(variant)
        return mi
    library = find_llvm()
    if library is None:
        where = os.environ.get("DRJIT_LIBLLVM_PATH")
        raise EnvironmentFailure(
            f"DRJIT_LIBLLVM_PATH={where} is not a file" if where else
            f"no LLVM >= {MIN_LLVM_MAJOR} library found for Mitsuba's JIT: install libllvm19 "
            "(tools/setup.sh) or set DRJIT_LIBLLVM_PATH to libLLVM-19.so")
    os.environ["DRJIT_LIBLLVM_PATH"] = library
    from catalog.core.extras import require  # noqa: PLC0415

    mi = require("mitsuba", "the path-traced reference")
    try:
        mi.set_variant(variant)
    except (ImportError, AttributeError, RuntimeError) as exc:
        raise EnvironmentFailure(f"Mitsuba variant {variant} is unavailable: "
                                 f"{str(exc).splitlines()[0] if str(exc) else type(exc).__name__}"
                                 f" (LLVM library {library})") from None
    from catalog.pathtrace import glow, window_filter, woven  # noqa: PLC0415

    woven.register(mi)
    glow.register(mi)
    window_filter.register(mi)
    _LOADED[variant] = mi
    return mi
