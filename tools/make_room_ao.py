"""Precompute the room's ambient occlusion (catalog/render/room_light/geometry.py) into
catalog/render/data/room_ao.npz: the room is static, so the first frame need not pay for it.

    .venv/bin/python tools/make_room_ao.py

Re-run after changing the room's geometry or the AO settings (the renderer then computes it
at start until the table matches again; tests/test_render_room.py checks the table).
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from catalog.render import room_light  # noqa: E402

if __name__ == "__main__":
    room_light.write_ao_table()
    print(f"wrote {room_light.AO_TABLE_PATH}")
