"""catalog/web/prune.py: the recorded pixel work nothing on the page reads is left out (the
views only a host step the page does not run reads back), everything else is kept as it was.

The small structures are written by hand with the answer worked out by hand (which draws feed
the screen); the lit room's recording is checked against its own host step's inputs."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from catalog.web.prune import prune_unread

ASSETS = Path(__file__).resolve().parents[1] / "catalog" / "web" / "assets"

#: 1: the screen (colour 10, depth renderbuffer 11); 2: a view into texture 20 that only a host
#: step reads; 3: a view into texture 30 the screen's draw samples; 4: a depth-only view into
#: 40, drawn first, that the screen samples from the next frame on (bound after the screen's
#: pass, at the end of the structure: the page's loop); 5: shares the screen's depth
#: renderbuffer 11 (a depth pre-pass the screen tests).
FRAMEBUFFERS = {1: {"colour": [10], "depth": 11}, 2: {"colour": [20], "depth": None},
                3: {"colour": [30], "depth": None}, 4: {"colour": [], "depth": 40},
                5: {"colour": [], "depth": 11}}


def _pass(fb, *extra):
    return [{"op": "framebuffer", "framebuffer": fb}, {"op": "clear", "framebuffer": fb},
            {"op": "uniform", "program": 7, "name": f"u_{fb}", "slot": fb}, *extra,
            {"op": "draw", "vertex_array": 100 + fb}]


def _structure():
    return [*_pass(4), *_pass(2), {"op": "mipmaps", "texture": 20},
            *_pass(3), *_pass(5),
            {"op": "host", "name": "step", "inputs": {"view": {"texture": {"object": 20}}}},
            {"op": "texture_write", "texture": 50, "slot": 9},
            {"op": "host_end", "name": "step"},
            *_pass(1, {"op": "texture", "unit": 0, "texture": 30},
                   {"op": "texture", "unit": 1, "texture": 50}),
            {"op": "texture", "unit": 2, "texture": 40}]


def test_only_the_views_a_host_step_reads_are_dropped():
    structure = _structure()
    kept = prune_unread(structure, FRAMEBUFFERS)
    dropped = [c for c in structure if c not in kept]
    # pass 2 (its clear, its draw) and its mip chain: read only by the host step
    assert dropped == [{"op": "clear", "framebuffer": 2}, {"op": "draw", "vertex_array": 102},
                       {"op": "mipmaps", "texture": 20}]
    # the rest in its order, state, uniforms and writes of pass 2 included
    assert [c for c in structure if c in kept] == kept
    assert {"op": "uniform", "program": 7, "name": "u_2", "slot": 2} in kept
    # pass 4 feeds the next frame's screen (unit 2 still bound), pass 5 the screen's depth test
    assert {"op": "draw", "vertex_array": 104} in kept and {"op": "draw", "vertex_array": 105} in kept


def test_a_host_step_the_page_runs_keeps_its_views():
    structure = _structure()
    assert prune_unread(structure, FRAMEBUFFERS, page_steps=("step",)) == structure


def test_a_pass_read_through_a_chain_is_kept():
    """View 2 is sampled by view 3, which the screen samples: both kept; unbound, both go."""
    structure = [*_pass(2), *_pass(3, {"op": "texture", "unit": 0, "texture": 20}),
                 *_pass(1, {"op": "texture", "unit": 1, "texture": 30})]
    assert prune_unread(structure, FRAMEBUFFERS) == structure
    # (the screen binds another texture to unit 0: while 20 stays bound a draw may sample it)
    unread = [*_pass(2), *_pass(3, {"op": "texture", "unit": 0, "texture": 20}),
              *_pass(1, {"op": "texture", "unit": 0, "texture": 60})]
    kept = prune_unread(unread, FRAMEBUFFERS)
    assert [c["vertex_array"] for c in kept if c["op"] == "draw"] == [101]


def test_the_page_registers_no_host_step_the_export_does_not_know():
    """export.PAGE_HOST_STEPS names exactly the steps the page's scripts register."""
    from catalog.web.export import PAGE_HOST_STEPS

    registered = set()
    for path in ASSETS.glob("*.js"):
        registered |= set(re.findall(r"CatalogHost\.register\(\s*['\"]([^'\"]+)['\"]",
                                     path.read_text(encoding="utf-8")))
    assert registered == set(PAGE_HOST_STEPS)


@pytest.mark.gl
@pytest.mark.slow   # a recorded lit frame
def test_the_lit_rooms_views_only_its_host_step_reads_are_not_exported(lit_recording):
    """A lit-room scene through SiteExporter.record: no draw into the window's captures, the
    window side's view or the outside's, no mip chain of them (the host step's inputs, read
    by nothing on the page: the recorded writes stand for them); the room's depth map, which
    the room's pass samples, is still drawn; as many uniforms as the unpruned recording."""
    exporter, recorded, structure = lit_recording
    rec = exporter.ctx.recording
    host = next(c for c in structure if c["op"] == "host")
    inputs = host["inputs"]
    views = {inputs[k]["texture"]["object"] for k in ("captures", "window_side", "outside")}
    view_fbos = {rid for rid, f in rec.framebuffers.items() if set(f["colour"]) & views}
    depth = inputs["room_depth"]["texture"]["object"]
    depth_fbos = {rid for rid, f in rec.framebuffers.items() if f["depth"] == depth}
    bound, drawn = None, set()
    for c in structure:
        if c["op"] == "framebuffer":
            bound = c["framebuffer"]
        elif c["op"] in ("draw", "clear"):
            drawn.add(c.get("framebuffer", bound))
    assert view_fbos and not drawn & view_fbos
    assert not {c["texture"] for c in structure if c["op"] == "mipmaps"} & views
    assert drawn & depth_fbos
    assert len(recorded["values"]) == sum(c["op"] in ("uniform", "buffer_write",
                                                      "texture_write") for c in structure)
