"""What every pass shares: the program and vertex-array caches, uniform setting and the
texture units (one table, so no two inputs of a draw meet on one unit).

A pass (:class:`Pass`) is handed the frame (:class:`catalog.render.frame.FrameRenderer`): it
reads the scene's settings and derived terms there, draws with the frame's shared
:class:`GLPrograms`, and keeps its own GL objects.
"""

from __future__ import annotations

import numpy as np

from catalog.gl.shaderlib import create_program

#: Specialised curtain programs kept compiled (one per light/fabric/mode/bands seen lately).
MAX_SPECIALISED = 8


#: Texture unit of the fabric's pattern, and its anisotropic filtering (samples, at most).
PATTERN_UNIT = 3


#: Texture unit of the environment image (background and the curtain's see-through).
ENVIRONMENT_UNIT = 5


#: Texture unit of the key light's front-layer map (the curtain's KEY_SHADOW), and of its
#: second layer's (issue 11, seventh round).
KEY_FRONT_UNIT = 6


KEY_SECOND_UNIT = 14


#: Texture unit of the pattern's band along the hem (a lace's scallops; common.glsl HEM_BORDER).
BORDER_UNIT = 15


#: Texture unit of the occlusion maps (the curtain's SKY_OCCLUSION).
OCCLUSION_UNIT = 7


#: Texture unit of the room's irradiance on the curtain's room side (the curtain's ROOM_SIDE).
ROOM_SIDE_UNIT = 8


#: Texture unit of the cloth's exitance towards the room at the window's patches (ROOM_SIDE:
#: what a fold sees of its neighbours where they hide the room; the room's transport).
ROOM_SIDE_CLOTH_UNIT = 9


#: Texture unit of the cloth's window side's mean radiance at the window's patches (ROOM_SIDE:
#: the folds in front of the outside light the cloth behind them; the room's transport).
WINDOW_SIDE_CLOTH_UNIT = 10


#: Texture unit of the occlusion maps in the curtain pass (ROOM_SIDE: the view's continuation).
OCCLUSION_MAPS_UNIT = 11


#: Texture unit of the wall round the window as the cloth's window side sees it (WALL_GRID).
WALL_GRID_UNIT = 13


def set_uniform(program, name, value) -> None:
    """``program[name] = value`` where the variant has that uniform (optimised away: skipped);
    numpy arrays and bytes are written as float32 / raw bytes."""
    if name not in program:
        return  # optimised away in this variant
    if isinstance(value, np.ndarray):
        program[name].write(np.ascontiguousarray(value, dtype="f4").tobytes())
    elif isinstance(value, bytes):
        program[name].write(value)
    else:
        program[name].value = value


class GLPrograms:
    """The frame's compiled programs (shader files and #defines -> program) and the vertex
    arrays made for them (a key naming the geometry and the program -> vertex array)."""

    def __init__(self, ctx):
        self.ctx = ctx
        self.programs: dict[tuple, object] = {}
        self.vaos: dict[tuple, object] = {}

    def release_vaos(self, kind: str | None = None) -> None:
        """Release the vertex arrays (of geometry ``kind`` only, e.g. "rings"; None: all)."""
        for key in [k for k in self.vaos if kind is None or k[0] == kind]:
            self.vaos.pop(key).release()

    def program(self, vertex: str, fragment: str, defines: dict | None = None):
        """The program of these shader files and #defines, compiled on first use."""
        key = (vertex, fragment, tuple(sorted((defines or {}).items())))
        if key not in self.programs:
            self._evict_specialised()
            self.programs[key] = create_program(self.ctx, vertex, fragment, defines)
        return self.programs[key]

    def _evict_specialised(self) -> None:
        """Keep at most MAX_SPECIALISED specialised programs (oldest released first)."""
        specialised = [k for k in self.programs if dict(k[2]).get("SPECIALISED")]
        for key in specialised[:max(0, len(specialised) - MAX_SPECIALISED + 1)]:
            program = self.programs.pop(key)
            for coarse in (False, True):   # (CurtainMesh.curtain_vao's keys)
                vao = self.vaos.pop(("curtain", id(program), coarse), None)
                if vao is not None:
                    vao.release()
            program.release()

    def compiled_variants(self) -> list[dict]:
        """The switches of every curtain program compiled so far for the frame itself (for
        tests and reports; the room's window capture, ROOM_CAPTURE, is left out)."""
        return [{k: v for k, v in k2[2] if not k.startswith("S_")}
                for k2 in self.programs
                if k2[1] == "curtain.frag" and not dict(k2[2]).get("ROOM_CAPTURE")]

    def fullscreen_vao(self, program):
        """The attribute-less vertex array of a full-screen triangle (fullscreen.vert)."""
        key = ("fullscreen", id(program))
        if key not in self.vaos:
            self.vaos[key] = self.ctx.vertex_array(program, [])
        return self.vaos[key]

    def release(self) -> None:
        self.release_vaos()
        for program in self.programs.values():
            program.release()
        self.programs.clear()


class Pass:
    """A pass of the frame: ``frame`` holds the settings, the derived scene terms
    (``frame.terms``), the mesh (``frame.mesh``), the shared targets and the other passes."""

    def __init__(self, frame):
        self.frame = frame
        self.ctx = frame.ctx
        self.mgl = frame._moderngl
        self.gl = frame.gl
