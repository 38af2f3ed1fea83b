"""The pattern's mip chain on disk (catalog/presets/mip_cache.py): a cached chain is
mip_chain's own, bit for bit; the second call reads the file instead of filtering; other
texels, another level count or changed code are another key; a torn, foreign or misshapen
file is ignored and replaced; with the cache off nothing is written."""

from __future__ import annotations

import numpy as np
import pytest

from catalog.core.resources import CACHE_ENV
from catalog.presets import mip_cache, patterns


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv(CACHE_ENV, str(tmp_path))
    return tmp_path / "mips"


def _texels(seed=0, shape=(48, 32, 4)):
    return np.random.default_rng(seed).random(shape, dtype=np.float32)


def _same(a, b) -> bool:
    return len(a) == len(b) and all(x.dtype == y.dtype == np.float32 and np.array_equal(x, y)
                                    for x, y in zip(a, b))


def test_cached_chain_is_the_computed_one_and_is_read_back(cache, monkeypatch):
    texels = _texels()
    computed = patterns.mip_chain(texels)
    first = mip_cache.cached_mip_chain(texels)
    assert _same(first, computed)
    assert len(list(cache.glob("*.npz"))) == 1

    def refuse(*args, **kwargs):
        raise AssertionError("computed again: the cache was not read")

    monkeypatch.setattr(patterns, "mip_chain", refuse)
    assert _same(mip_cache.cached_mip_chain(texels), computed)
    band = np.concatenate([texels, texels[::-1]])   # another texture: computed, so refused
    with pytest.raises(AssertionError, match="computed again"):
        mip_cache.cached_mip_chain(band)


def test_the_key_follows_the_texels_the_levels_and_the_code(monkeypatch):
    texels = _texels()
    key = mip_cache.chain_key(texels, None)
    assert key == mip_cache.chain_key(texels.copy(), None)        # content, not identity
    changed = texels.copy()
    changed[3, 4, 1] = np.nextafter(changed[3, 4, 1], np.float32(2))
    others = {mip_cache.chain_key(changed, None), mip_cache.chain_key(texels, 3),
              mip_cache.chain_key(texels.reshape(32, 48, 4), None),
              mip_cache.chain_key(texels.astype(np.float64), None)}
    monkeypatch.setattr(mip_cache, "_CODE_HASH", "other code")
    others.add(mip_cache.chain_key(texels, None))
    assert key not in others and len(others) == 5


@pytest.mark.parametrize("damage", ["torn", "foreign", "misshapen"])
def test_a_bad_file_is_ignored_and_replaced(cache, damage):
    texels = _texels(1)
    computed = patterns.mip_chain(texels)
    key = mip_cache.chain_key(texels, None)
    path = mip_cache.store(key, computed)
    if damage == "torn":
        path.write_bytes(path.read_bytes()[:200])
    elif damage == "foreign":
        other = _texels(2)
        mip_cache.store(mip_cache.chain_key(other, None), patterns.mip_chain(other))
        (cache / f"{mip_cache.chain_key(other, None)}.npz").replace(path)
    else:   # the right key over levels of another size
        small = patterns.mip_chain(texels[:16, :16])
        mip_cache.store(key, small)
    assert mip_cache.load(key, texels.shape) is None
    assert _same(mip_cache.cached_mip_chain(texels), computed)
    assert mip_cache.load(key, texels.shape) is not None   # written again, whole


def test_cache_off_writes_nothing(tmp_path, monkeypatch):
    monkeypatch.setenv(CACHE_ENV, "off")
    texels = _texels(3)
    assert _same(mip_cache.cached_mip_chain(texels), patterns.mip_chain(texels))
    assert mip_cache.store(mip_cache.chain_key(texels, None), [texels]) is None
    assert not any(tmp_path.iterdir())
