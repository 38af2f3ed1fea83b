"""The frame's room transport draws the room the edge resolved: a loaded Room finds its
bundle by the hash its loader took, without reading the room's file again (issue 31's
"no file read below the edge")."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from catalog.render import room_operators as ops_lib
from catalog.room.load import load_room


@pytest.mark.slow
def test_a_loaded_room_finds_the_named_rooms_bundle_without_reading_its_file(monkeypatch):
    named = ops_lib.room_operators("box")          # cached (or built) by name, as the viewer does
    room = load_room("box")
    assert ops_lib.bundle_path(room) == ops_lib.bundle_path("box")

    real_read = Path.read_bytes

    def refuse_glb(self):
        if self.suffix == ".glb":
            raise AssertionError(f"{self} read below the edge")
        return real_read(self)

    monkeypatch.setattr(Path, "read_bytes", refuse_glb)
    with pytest.raises(AssertionError, match="below the edge"):
        ops_lib.bundle_path("box")                 # (the check can fail: a name is hashed)
    resolved = ops_lib.room_operators(room)
    np.testing.assert_array_equal(resolved.window_corners, named.window_corners)
    assert resolved.count == named.count
