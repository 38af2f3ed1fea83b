"""The room transport cached on disk, keyed by the room file's content and the parameters.

``CATALOG_CACHE`` (default ~/.cache/catalog) / room_transport / NAME-KEY.npz, where KEY is
the SHA-256 of the room file's bytes, the :class:`catalog.room.transport.TransportParams`
and TRANSPORT_VERSION (bumped when the method changes). A changed file has another key, so
its old entry is never read. Written to a temporary file and renamed: a reader never sees a
half-written entry.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

import numpy as np

from catalog.room.model import Window
from catalog.room.receivers import Receivers
from catalog.room.transport import Transport, TransportParams, precompute

TRANSPORT_VERSION = 3
_ARRAYS = ("direct", "window_operator", "kept_index", "window_basis", "window_modes",
           "bounce_left", "bounce_right", "frame")
_RECEIVERS = ("corners", "normal", "area_m2", "albedo", "triangle", "divisions", "first", "triangles")
_RECEIVER_TREE = ("node_corners", "children", "leaf", "exposed")      # present when refined / measured


def cache_dir() -> Path:
    return Path(os.environ.get("CATALOG_CACHE", Path.home() / ".cache" / "catalog")) / "room_transport"


def cache_key(room, params: TransportParams) -> str:
    text = json.dumps({"room": room.content_sha256, "params": params.key(), "version": TRANSPORT_VERSION},
                      sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()


def cache_path(room, params: TransportParams) -> Path:
    return cache_dir() / f"{room.name}-{cache_key(room, params)[:24]}.npz"


def save(transport: Transport, path: Path, key: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    arrays = {name: getattr(transport, name) for name in _ARRAYS if getattr(transport, name) is not None}
    arrays.update({f"receivers_{name}": getattr(transport.receivers, name) for name in _RECEIVERS + _RECEIVER_TREE
                   if getattr(transport.receivers, name) is not None})
    f = transport.form_factors.tocsr()
    arrays.update({"f_data": f.data, "f_indices": f.indices, "f_indptr": f.indptr})
    arrays["window_corners"] = transport.window.corners
    arrays["window_normal"] = transport.window.normal
    meta = {"key": key, "params": transport.params.key(), "timings_s": transport.timings_s}
    arrays["meta"] = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
    from catalog.core.atomic import atomic_path  # noqa: PLC0415

    with atomic_path(path) as tmp:   # the project's atomic write (its temporaries, signals)
        np.savez(tmp, **arrays)


def load(path: Path, key: str) -> Transport | None:
    """The cached transport, or None when absent, unreadable or of another key."""
    try:
        with np.load(path) as data:
            meta = json.loads(bytes(data["meta"]).decode())
            if meta.get("key") != key:
                return None
            params = meta["params"]
            params["patches"] = tuple(params["patches"])
            receivers = Receivers(**{name: data[f"receivers_{name}"] for name in _RECEIVERS},
                                  **{name: (data[f"receivers_{name}"] if f"receivers_{name}" in data else None)
                                     for name in _RECEIVER_TREE})
            window = Window(data["window_corners"], data["window_normal"])
            arrays = {name: (data[name] if name in data else None) for name in _ARRAYS}
            import scipy.sparse  # noqa: PLC0415

            count = receivers.corners.shape[0]
            arrays["form_factors"] = scipy.sparse.csr_matrix(
                (data["f_data"], data["f_indices"], data["f_indptr"]), shape=(count, count))
    except (OSError, ValueError, KeyError, json.JSONDecodeError):
        return None
    return Transport(params=TransportParams(**params), receivers=receivers, window=window,
                     timings_s=dict(meta.get("timings_s", {}), from_cache=True), **arrays)


def room_transport(room, params: TransportParams = TransportParams(), backend: str = "mitsuba") -> Transport:
    """The room's transport from the cache, computed and stored when it is not there."""
    path = cache_path(room, params)
    key = cache_key(room, params)
    cached = load(path, key)
    if cached is not None:
        return cached
    transport = precompute(room, params, backend)
    transport.timings_s["from_cache"] = False
    save(transport, path, key)
    return transport
