"""A frame's host step: work done on the CPU between GL commands (read pixels back, compute,
upload), which a replay of the frame's GL commands alone cannot do.

``with host_step(ctx, name, inputs):`` around the reads, the computation and the uploads.
On a plain moderngl context it does nothing. A recording context (catalog.web.record) notes
a ``host`` command with the step's name and its inputs (the GL objects it reads and writes,
by their recorded ids, and the constants it needs) before them and a ``host_end`` after
them; the GL commands between are the step's outputs as the desktop computed them (buffer
and texture writes with the scene's bytes): the web page replays them unless it runs the
named step itself (catalog/web/assets/host_steps.js).
"""

from __future__ import annotations

import contextlib


def host_step(ctx, name: str, inputs: dict):
    """The context manager of host step ``name`` on ``ctx`` (see the module doc). ``inputs``:
    JSON-able values, numpy arrays and GL objects (a recording notes the objects' ids)."""
    sink = getattr(ctx, "host_step_sink", None)
    if sink is None:
        return contextlib.nullcontext()
    return sink(name, inputs)
