"""A pattern's prefiltered mip chain on disk: computed once per texture.

:func:`catalog.presets.patterns.mip_chain` (a periodic Gaussian and a Fourier resampling per
level) costs about 1.7 s of CPU for a lace's texture and its hem band on llvmpipe's machine:
every process that draws the fabric (a snapshot, each batch task, each worker) paid it
again. The chain is a pure function of the texels, the number of levels and the code of
catalog/presets/patterns.py, so it is kept beside the settled drapes (the user's cache
folder, ``fabric-catalog/mips``; ``$CATALOG_CACHE_DIR``: catalog.core.resources.cache_folder) under
the SHA-256 of all of these and numpy's version (its FFT may round differently).

The levels above 0 are stored as float32, what mip_chain returns (level 0 is the texels as
float32, made again from them), so a cached chain is bit for bit the computed one. Writes are atomic; a file that cannot be read back as the key's chain is
ignored and written again; a folder that cannot be written costs the computation next time
and never fails a command.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np

#: Bumped when the file's layout changes.
FORMAT = 1

_CODE_HASH: str | None = None


def code_hash() -> str:
    """SHA-256 of catalog/presets/patterns.py (its mip_chain and the constants it reads)."""
    global _CODE_HASH
    if _CODE_HASH is None:
        source = Path(__file__).resolve().parent / "patterns.py"
        _CODE_HASH = hashlib.sha256(source.read_bytes()).hexdigest()
    return _CODE_HASH


def chain_key(texels: np.ndarray, levels: int | None) -> str:
    """The content key (hex SHA-256) of ``mip_chain(texels, levels)``."""
    array = np.ascontiguousarray(texels)
    digest = hashlib.sha256()
    head = (f"format={FORMAT};shape={array.shape};dtype={array.dtype.str};levels={levels};"
            f"code={code_hash()};numpy={'.'.join(np.__version__.split('.')[:2])};")
    digest.update(head.encode())
    digest.update(array.tobytes())
    return digest.hexdigest()


def _path(key: str) -> Path | None:
    from catalog.core.resources import cache_folder  # noqa: PLC0415

    folder = cache_folder("mips")
    return None if folder is None else folder / f"{key}.npz"


def load(key: str, shape: tuple[int, ...]) -> list[np.ndarray] | None:
    """The cached levels 1, 2, ... of ``key`` (texels of ``shape``), or None."""
    from catalog.core.keyed_npz import UNREADABLE, read_keyed  # noqa: PLC0415

    data = read_keyed(_path(key), key)
    if data is None:
        return None
    try:
        chain = [data[f"level{k}"] for k in range(1, int(data["count"]))]
    except UNREADABLE:
        return None
    h, w = shape[:2]
    for k, level in enumerate(chain, start=1):
        if level.dtype != np.float32 or level.shape != (max(1, h >> k), max(1, w >> k)) + tuple(shape[2:]):
            return None
    return chain


def store(key: str, chain: list[np.ndarray]) -> Path | None:
    """Publish ``chain``'s levels above 0 under ``key`` atomically; None (and nothing
    left) when it cannot."""
    from catalog.core.keyed_npz import write_keyed  # noqa: PLC0415

    return write_keyed(_path(key), key, {"count": np.array(len(chain)),
                                         **{f"level{k}": level for k, level in enumerate(chain) if k > 0}})


def cached_mip_chain(texels: np.ndarray, levels: int | None = None) -> list[np.ndarray]:
    """``mip_chain(texels, levels)``, read from the cache when it is there (else computed
    and stored)."""
    from catalog.presets.patterns import mip_chain  # noqa: PLC0415

    key = chain_key(texels, levels)
    above = load(key, np.shape(texels))
    if above is None:
        chain = mip_chain(texels, levels)
        store(key, chain)
        return chain
    # level 0 as mip_chain makes it (through float64, exact for float32 texels)
    return [np.asarray(texels, dtype=np.float64).astype(np.float32), *above]
