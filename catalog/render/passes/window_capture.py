"""Pass 0b of the frame: what the room sees in the window (the captures)."""

from __future__ import annotations

import numpy as np

from catalog.render import bands as band_lib, room_light, scene as scene_lib
from catalog.render.passes.gl_common import Pass, set_uniform


class WindowCapturePass(Pass):
    """What the room sees in the window (issue 13, docs/room.md): the flat curtain and the
    outside captured from the room's middle, two side eyes and (with the box round the folds)
    two wall eyes, one texel per window patch at a mip level; the curtain's window side from
    outside. Also the window's light inputs common.glsl WINDOW_LIGHT reads.

    In: the curtain and background passes (drawn with the captures' overrides), the scene
    terms. Out: ``luminaire``, ``luminaire_sides``, ``luminaire_walls``, ``luminaire_back``
    of frame.room_targets."""

    def __init__(self, frame):
        super().__init__(frame)

    def window_front_z(self) -> float:
        """The plane of the room side's window patches (m): the front of the box around the
        closed curtain's folds (room_light.WINDOW_FRONT_Z), or the opening's when the curtain
        is open or ``window_box`` is off (before issue 11's ninth round)."""
        if not self.frame.curtain_open:
            return room_light.WINDOW_FRONT_Z
        return scene_lib.ROOM_BOX[2][0]

    def box_active(self) -> bool:
        """Whether the room sees the curtain through the box round its folds (its front before
        the opening's plane: ``window_box`` on and the curtain closed)."""
        return self.window_front_z() > scene_lib.ROOM_BOX[2][0]

    def window_near(self) -> bool:
        """Whether room.frag takes the window's light per pixel on the window wall beside the
        opening (WINDOW_NEAR): with the box (its sides stand on that wall)."""
        return self.box_active()

    def wall_eyes_active(self) -> bool:
        """Whether the box's sides are captured from the wall eyes too (WALL_EYES)."""
        return self.box_active()

    def read_luminaire_back(self, level: int) -> np.ndarray:
        """The window-side capture at mip ``level``, float32 (H, W, 3), row 0 = the opening's bottom."""
        return self.read_luminaire(level, "luminaire_back")

    def read_window_near(self) -> np.ndarray:
        """room_window_near.frag's grid, float32 (N, N, 3), row 0 = its rectangle's bottom."""
        texture = self.frame.room_targets.get()["window_near"]
        w, h = texture.size
        return np.frombuffer(texture.read(), dtype="f2").reshape(h, w, 4)[..., :3].astype(np.float32)

    def read_wall_captures(self) -> np.ndarray:
        """The wall eyes' captures of the box's sides at their patch level, float32 (2, 9, 3)
        (left, right; row 0 = the opening's bottom)."""
        both = self.read_luminaire(room_light.WALL_EYE_LEVEL, "luminaire_walls")
        return np.stack([both[:, 0], both[:, 1]])

    def read_side_captures(self) -> np.ndarray:
        """The side eyes' captures at their patch level, float32 (2, H, W, 3) (left, right; row
        0 = the opening's bottom), as room_lightmap.frag reads them."""
        level = room_light.SIDE_LUMINAIRE_LEVEL
        both = self.read_luminaire(level, "luminaire_sides")
        width = both.shape[1] // 2
        return np.stack([both[:, :width], both[:, width:]])

    def read_luminaire(self, level: int, name: str = "luminaire") -> np.ndarray:
        """The room-side capture (or ``name``) at mip ``level``, float32 (H, W, 3), row 0 = the
        opening's bottom."""
        texture = self.frame.room_targets.get()[name]
        w, h = (max(v >> level, 1) for v in texture.size)
        data = texture.read(level=level)
        return np.frombuffer(data, dtype="f4").reshape(h, w, 4)[..., :3].copy()

    def draw_room_luminaire(self, inputs) -> None:
        """Pass R2: what the room sees in the window (the curtain's room-side radiance, or the
        outside where it is open), one texel per window patch, the sun's disc left out; from
        the room's middle and from two eyes towards the side walls. The window
        side's capture R2b first: through the holes, the room's captures see it on the folds
        behind (curtain.frag FOLDS_BEHIND)."""
        mgl, gl = self.mgl, self.frame.room_targets.get()
        # the window side, from outside: nothing where there is no cloth (the room behind it
        # is not a source), and no see-through (it would show the outside, not the room)
        gl["luminaire_back_fbo"].use()
        self.ctx.viewport = (0, 0) + room_light.luminaire_capture_size(room_light.BACK_LUMINAIRE_LEVEL)
        gl["luminaire_back_fbo"].clear(0.0, 0.0, 0.0, 1.0, depth=1.0)
        self.ctx.enable(mgl.DEPTH_TEST)
        self.ctx.depth_func = "<="
        if not self.frame.curtain_open:
            self.frame.curtain.draw_flat(room_light.back_luminaire_view_projection(),
                                    room_light.BACK_LUMINAIRE_EYE, self.frame.terms.back_capture_overrides())
        gl["luminaire_back"].build_mipmaps()
        # alpha: the key's irradiance on the cloth (curtain.frag ROOM_CAPTURE), 0 where none
        overrides = self.frame.terms.capture_overrides()
        # the side eyes' side by side, a tile a power of 2 wide at the patch level: the mipmaps
        # keep them apart
        targets = [("luminaire", room_light.LUMINAIRE_EYE, 0, room_light.LUMINAIRE_LEVEL)]
        targets += [("luminaire_sides", eye, k, room_light.SIDE_LUMINAIRE_LEVEL)
                    for k, eye in enumerate(room_light.CAPTURE_SIDE_EYES)]
        for name, eye, tile, level in targets:
            lw, lh = room_light.luminaire_capture_size(level)
            if tile == 0:
                gl[name + "_fbo"].use()
                gl[name + "_fbo"].clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
            self.ctx.viewport = (tile * lw, 0, lw, lh)
            view_proj = room_light.luminaire_view_projection(eye, self.window_front_z())
            if not self.frame.curtain_open:
                self.frame.curtain.draw_flat(view_proj, eye, overrides, folds_behind=True)
            self.frame.background.draw(view_proj, inputs, camera_position=eye, sun_disc=False, capture=True)
        for name in sorted({name for name, _eye, _tile, _level in targets}):   # a fixed order: the page replays these calls
            gl[name].build_mipmaps()   # level LUMINAIRE_LEVEL: each patch's mean radiance
        if self.wall_eyes_active():   # the box's sides from the wall eyes (no outside: their ways
            gl["luminaire_walls_fbo"].use()   # through a side rise into the room)
            gl["luminaire_walls_fbo"].clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
            ww, wh = room_light.wall_eye_capture_size()
            for k, eye in enumerate(room_light.WALL_EYES):
                self.ctx.viewport = (k * ww, 0, ww, wh)
                self.frame.curtain.draw_flat(room_light.wall_eye_view_projection(k == 1, self.window_front_z()), eye,
                                        overrides, folds_behind=True)
            gl["luminaire_walls"].build_mipmaps()
        self.ctx.depth_func = "<"
        self.ctx.disable(mgl.DEPTH_TEST)

    def window_light_defines(self) -> dict:
        """common.glsl WINDOW_LIGHT's defines (room_lightmap.frag and the lit room.frag define
        WINDOW_LIGHT itself): the box's sides also captured from the wall's side (WALL_EYES,
        with the box)."""
        return {"WALL_EYES": True} if self.wall_eyes_active() else {}

    def window_light_uniforms(self, program, inputs) -> None:
        """common.glsl WINDOW_LIGHT's inputs (the room's captures on units 3-5, the box, the
        key's lobe, the lamps), for the light map (room_lightmap.frag) and the window wall
        beside the opening per pixel (room.frag WINDOW_NEAR)."""
        gl = self.frame.room_targets.get()
        gl["luminaire"].use(location=5)
        set_uniform(program, "u_luminaire", 5)
        gl["luminaire_sides"].use(location=4)
        set_uniform(program, "u_luminaire_sides", 4)
        set_uniform(program, "u_luminaire_sides_level", room_light.SIDE_LUMINAIRE_LEVEL)
        set_uniform(program, "u_side_eye", np.asarray(room_light.CAPTURE_SIDE_EYES, dtype="f4"))
        set_uniform(program, "u_middle_eye", room_light.LUMINAIRE_EYE)
        set_uniform(program, "u_luminaire_size", room_light.LUMINAIRE_TEXELS)
        set_uniform(program, "u_luminaire_level", room_light.LUMINAIRE_LEVEL)
        gl["luminaire_back"].use(location=3)
        set_uniform(program, "u_luminaire_back", 3)
        set_uniform(program, "u_luminaire_back_level", room_light.BACK_LUMINAIRE_LEVEL)
        set_uniform(program, "u_back_plane_z", scene_lib.CURTAIN_Z)
        set_uniform(program, "u_front_z", self.window_front_z())
        if self.wall_eyes_active():   # the box's sides from the wall's side (WALL_EYES)
            gl["luminaire_walls"].use(location=7)
            set_uniform(program, "u_luminaire_walls", 7)
            set_uniform(program, "u_luminaire_walls_level", room_light.WALL_EYE_LEVEL)
            set_uniform(program, "u_wall_eye", np.asarray(room_light.WALL_EYES, dtype="f4"))
        colours = self.frame.terms.room_colours(inputs)
        set_uniform(program, "u_lobe_rgb", colours["u_lobe_rgb"] if not self.frame.curtain_open
                  else (0.0, 0.0, 0.0))
        set_uniform(program, "u_g_spec", float(inputs.g_spec))
        lamps = self.frame.room_lamps
        positions = np.zeros((room_light.MAX_ROOM_LAMPS, 3), dtype="f4")
        rgbs = np.zeros((room_light.MAX_ROOM_LAMPS, 3), dtype="f4")
        for k, (light, position) in enumerate(lamps):
            positions[k] = position
            rgbs[k] = band_lib.spectrum_to_display_rgb(light.irradiance_w_m2_nm)
        set_uniform(program, "u_lamp_count", len(lamps))
        set_uniform(program, "u_lamp_position", positions)
        set_uniform(program, "u_lamp_rgb", rgbs)
