"""FrameRenderer: one frame of the curtain scene into an HDR target, tone-mapped to sRGB.

The viewer and the snapshot command both drive this class (docs/render.md has the API).
It never creates a GL context: it is handed one (:mod:`catalog.gl.context`).

Passes, into an RGBA32F target of linear sRGB radiance (Y in cd m^-2):

0. the room's light (docs/room-light.md; when the scene, cloth or lamps changed): the key
   light's transmittance shadow map through the curtain (room_shadow.*, the pattern's holes
   projected), then the room's precomputed transport (passes/room_transport_light.py): the
   window's light from the flat cloth's parallel views of the aperture, the light map of the
   room's receivers through its operators, the light on the cloth's two sides;
1. the room (a room file, settings.room: room_transport.vert/.frag) and the curtain's rod and
   rings, lit by the light map and the key's beam through the window and the curtain (or,
   switched off, the constant room);
2. background (shaders/fullscreen.vert + background.frag), on the far plane so the depth test
   shades only the pixels nothing covers: the outside through the window (the clear sky by
   direction of catalog/optics/sun/sky.py or an environment image, the ground, the sun's
   disc) or the room, per camera ray;
3. the curtain (curtain.vert/.frag): eq. 8 in N bands, two-sided, no face culling, with the
   fabric's pattern (catalog/presets/patterns.py): the threads' radiance (the fitted lobes over the
   mean coverage) and coverage c into weighted blended OIT targets (McGuire & Bavoil 2013),
   resolved over the room and background drawn in 1-2 (oit_composite.frag): the holes show
   what is really behind, undimmed, and overlapping folds multiply their open fractions;
   ``patterned = False`` draws the paper's flat cloth instead (opaque, LD times the
   background by ray direction: the frame before issue 12, kept for comparison);
3b. glare (bloom_down/glow.frag at quarter size, mixed in by tonemap.frag), when on;
4. display (fullscreen.vert + tonemap.frag) into the caller's framebuffer (or our RGBA8
   target): exposure (EV100, fixed or metered from a luminance histogram of this frame),
   white balance (CAT16), tone curve, gamut compression in OKLab, the sRGB curve
   (:mod:`catalog.render.display`, docs/display.md); then FXAA (fxaa.frag, issue 12) on
   the display image; ``antialiasing="off"`` displays straight into the target.

What the frame draws with is one :class:`catalog.render.settings.FrameSettings` value
(:meth:`FrameRenderer.update`); the renderer redraws what the changed fields make stale
(``settings.STALE``).

Anti-aliasing (``FrameSettings.antialiasing``, default ``auto``): FXAA (step 4), or
MSAA where the context has MSAA_SAMPLES samples and is a GPU (:func:`choose_antialiasing`):
steps 1-3 then draw into multisampled targets (the OIT targets too), resolved before the
OIT composite.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from catalog.core.errors import CatalogError
from catalog.render import display as display_lib
from catalog.render import scene as scene_lib
from catalog.render import settings as settings_lib
from catalog.render.settings import FrameSettings, SettingsError
from catalog.render.passes.background import BackgroundPass
from catalog.render.passes.curtain import CurtainPass
from catalog.render.passes.curtain_mesh import CurtainMesh
from catalog.render.passes.display import DisplayPass
from catalog.render.passes.gl_common import GLPrograms
from catalog.render.passes.glare import GlarePass
from catalog.render.passes.pattern import PatternTexture
from catalog.render.passes.room_schedule import RoomLightSchedule
from catalog.render.passes.scene_terms import SceneTerms
from catalog.render.passes.shadow import ShadowPass
from catalog.render.passes.targets import (MSAA_SAMPLES, FrameTargets, RoomTargets,
                                           check_size, choose_antialiasing, choose_specialise)
from catalog.render.passes.twin import FrameTwin


class FrameRenderer:
    """Renders the curtain scene with a given moderngl context at a given size (w, h)."""

    def __init__(self, ctx, size: tuple[int, int], settings: FrameSettings | None = None, *,
                 specialise: bool | None = None):
        """``settings``: what to draw with (:class:`FrameSettings`; None: its defaults, with
        no fabric or light yet: :meth:`update` gives them). ``specialise``: compile the
        scene's values into the curtain shader as constants (recompiled when the light, fabric, mode or band count changes; a CPU rasteriser then
        loads no uniforms per fragment) rather than passing them as uniforms; None (default):
        :func:`choose_specialise` for this context (constants on a CPU rasteriser only)."""
        import moderngl  # noqa: PLC0415

        self._moderngl = moderngl
        self.ctx = ctx
        self.size = check_size(size, ctx)
        self.targets = FrameTargets(ctx, self.size)
        self.specialise = (choose_specialise(dict(ctx.info)) if specialise is None
                           else bool(specialise))
        #: the auto exposure's current EV100 (adapted)
        self.metered_ev100 = None
        self._last = None  # (vw, vh, fbo, viewport)
        #: the curtain pass draws the flat cloth for the room's captures (see ``patterned``)
        self.drawing_flat = False
        self.environment = None    # (path, texture, upper-hemisphere illuminance) or None
        self.antialiasing = "fxaa"   # the mode in use (settings.antialiasing resolved)
        self._settings = FrameSettings()
        self.room_targets = RoomTargets(ctx, self._settings.shadow_map_size)
        #: the room drawn and lit by its precomputed transport (settings.room; loaded at the
        #: first frame that needs it, or when the room changes: :attr:`room_transport`)
        self._room_transport = None
        #: the curtain's rings on the rod (positions, normals), drawn with the room
        self.ring_arrays = (np.zeros((0, 3), "f4"), np.zeros((0, 3), "f4"))
        # the passes, in the order a frame runs them (render_hdr, render)
        self.gl = GLPrograms(ctx)
        self.terms = SceneTerms(self)
        self.mesh = CurtainMesh(self)
        self.fabric_pattern = PatternTexture(self)
        self.shadow = ShadowPass(self)
        self.schedule = RoomLightSchedule(self)
        self.background = BackgroundPass(self)
        self.curtain = CurtainPass(self)
        self.glare = GlarePass(self)
        self.display = DisplayPass(self)
        self.twin = FrameTwin(self)
        self._apply(self._settings, frozenset({"msaa_targets"}))
        if settings is not None:
            self.update(settings)
        default = scene_lib.draped_curtain()
        self.mesh.set_mesh(default.positions, default.normals, default.uvs, default.tangents,
                           default.indices)

    # ------------------------------------------------------------------ the settings
    @property
    def settings(self) -> FrameSettings:
        """What the frame draws with (:class:`catalog.render.settings.FrameSettings`)."""
        return self._settings

    def update(self, settings: FrameSettings | None = None, **changes) -> frozenset[str]:
        """Draw with ``settings`` from now on (or ``dataclasses.replace(self.settings,
        **changes)``); returns what the change made stale (:data:`settings.STALE`), which
        this method frees, reloads or marks for the next frame."""
        new = self._settings if settings is None else settings
        if not isinstance(new, FrameSettings):
            raise SettingsError(f"{new!r} is not a FrameSettings", field="settings")
        if changes:
            new = dataclasses.replace(new, **changes)
        parts = settings_lib.stale(self._settings, new)
        self._apply(new, parts)
        return parts

    def _apply(self, new: FrameSettings, parts) -> None:
        """Act on the stale parts (see :data:`settings.STALE`), then keep ``new``."""
        if "room_transport" in parts:   # first: a bad room or lamp is refused before any change
            self._set_room_transport(new.resolved_room or new.room_spec, new.lamps)
        elif new.lamps and "room_light" in parts:
            self._check_lamps(new.lamps, self.placement)
        if "fabric_tables" in parts and new.fabric is not None:
            self.fabric_pattern.set_fabric(new.fabric)   # its tables resolved with the settings
        if "msaa_targets" in parts:
            self.antialiasing = self._resolve_antialiasing(new.antialiasing)
        if "room_targets" in parts and new.shadow_map_size != self.room_targets.shadow_texels:
            self.room_targets.release()
            self.room_targets.shadow_texels = new.shadow_map_size
        if "environment" in parts:
            self._load_environment(new.environment, new.resolved_environment)
        self._settings = new
        if "room_light" in parts:
            self.schedule.invalidate()

    @staticmethod
    def _check_lamps(lamps, placement) -> None:
        """Each lamp inside the interior of the room of ``placement`` (catalog.render.placement)."""
        from catalog.render.curtain_frames import check_lamp_position  # noqa: PLC0415

        interior = placement.interior
        for _light, position in lamps:
            try:
                check_lamp_position(position, interior)
            except CatalogError as exc:
                raise SettingsError(str(exc), field="lamps") from None

    def _set_room_transport(self, room, lamps=()) -> None:
        """The room (a loaded catalog.room.model.Room where the edge resolved one, else a
        built-in name or a .glb path) drawn and lit by its precomputed transport
        (catalog/render/passes/room_transport_light.py; its bundle from the cache, built on
        first use). A bad room, or a lamp outside it, is refused before any change."""
        from catalog.render.passes.room_transport_light import RoomTransportLight  # noqa: PLC0415

        light = RoomTransportLight(self, room if hasattr(room, "content_sha256") else str(room))
        try:
            self._check_lamps(lamps, light.placement)
        except SettingsError:
            light.release()
            raise
        self._drop_room_transport()
        self._room_transport = light

    def _drop_room_transport(self) -> None:
        if self._room_transport is not None:
            if self.ctx.fbo in self._room_transport.framebuffers():
                (self.ctx.screen or self.ctx.detect_framebuffer(0)).use()
            self._room_transport.release()
            self._room_transport = None

    @property
    def room_transport(self):
        """The room's light by its precomputed transport (RoomTransportLight), loaded on first use."""
        if self._room_transport is None:
            self._set_room_transport(self._settings.resolved_room or self._settings.room_spec)
        return self._room_transport

    def _resolve_antialiasing(self, mode: str) -> str:
        """``auto``: :func:`choose_antialiasing` for this context (FXAA on llvmpipe); ``fxaa``:
        the post-process on the display image (shaders/fxaa.frag); ``msaa``: MSAA_SAMPLES
        samples per pixel in the HDR passes (refused where the context has fewer); ``off``:
        the tone-mapped image as it is. Returns the mode in use (never ``auto``)."""
        info = dict(self.ctx.info)   # GL_RENDERER, GL_MAX_SAMPLES
        if mode == "auto":
            mode = choose_antialiasing(info)
        if mode == "msaa" and int(info.get("GL_MAX_SAMPLES", 0) or 0) < MSAA_SAMPLES:
            raise SettingsError(f"msaa: this context has fewer than {MSAA_SAMPLES} samples "
                                "(GL_MAX_SAMPLES); use fxaa", field="antialiasing")
        if mode != "msaa":
            self.targets.release_msaa()
        return mode

    def _load_environment(self, path, resolved) -> None:
        """The environment image (read with the settings) as a texture, or none."""
        if self.environment is not None:
            self.environment[1].release()
            self.environment = None
        if path is None:
            return
        pixels, upper_lx = resolved
        h, w = pixels.shape[:2]
        texture = self.ctx.texture((w, h), 3, data=np.ascontiguousarray(pixels[::-1]).tobytes(),
                                   dtype="f4")
        texture.filter = (self._moderngl.LINEAR, self._moderngl.LINEAR)
        texture.repeat_x, texture.repeat_y = True, False
        self.environment = (str(path), texture, upper_lx)

    # what the passes read, from the settings (read-only)
    preset = property(lambda self: self._settings.fabric, doc="The fabric's Preset.")
    light = property(lambda self: self._settings.key_light, doc="The key light (a Light).")
    _key_to_light = property(lambda self: self._settings.key_to_light)
    _is_sun = property(lambda self: self._settings.key_light is not None and self._settings.key_light.is_sun)
    mode = property(lambda self: self._settings.fluorescence)
    n_bands = property(lambda self: self._settings.bands)
    camera = property(lambda self: self._settings.camera)
    exposure = property(lambda self: self._settings.exposure)
    ev100 = property(lambda self: self._settings.ev, doc="The fixed EV100, None: auto exposure.")
    white_balance = property(lambda self: self._settings.white_balance)
    room_lighting = property(lambda self: self._settings.room_lighting)
    key_second_layer = property(lambda self: self._settings.key_second_layer)
    shadow_texels = property(lambda self: self._settings.shadow_map_size)
    curtain_open = property(lambda self: self._settings.curtain_open)
    room_lamps = property(lambda self: list(self._settings.lamps))
    sky_model = property(lambda self: self._settings.sky_model)
    bloom = property(lambda self: self._settings.bloom)
    room_spec = property(lambda self: self._settings.room_spec,
                         doc="The room drawn by its transport (a built-in name or a .glb path).")
    room_update_every = property(lambda self: self._settings.room_update_every)
    patterned = property(lambda self: self._settings.patterned and not self.drawing_flat,
                         doc="The pattern drawn (False: the flat cloth, or a capture's flat pass).")

    def set_rings(self, xs_m) -> None:
        """Curtain rings on the rod at these x positions (m, scene frame); empty: none. On the
        rod of the frame's room (:attr:`placement`): after a room change, set the mesh and the
        rings of that room again (catalog.render.snapshot.simulated_curtain, ring_xs_m)."""
        self.ring_arrays = scene_lib.ring_mesh(xs_m, self.placement)

    @property
    def placement(self):
        """Where the curtain, rod and camera go in the frame's room (catalog.render.placement),
        from its window (the room transport's, loaded on first use)."""
        return self.room_transport.placement

    def room_side_active(self) -> bool:
        """Whether the curtain's room side takes the room's solved light this frame: with the
        room lighting on and the viewer in the room (from outside, the room lies behind the
        cloth and the stand-ins stay)."""
        return bool(self.room_lighting and self.viewer_inside)

    def _require_ready(self) -> None:
        if self.preset is None:
            raise CatalogError("no fabric set: update(fabric=...) first")
        if self.light is None:
            raise CatalogError("no light set: update(light=...) first")

    @property
    def viewer_inside(self) -> bool:
        return self._settings.viewer_inside(self.placement)   # the frame's room's window

    def _viewport_size(self, viewport) -> tuple[int, int]:
        if viewport is None:
            return self.size
        vw, vh = int(viewport[2]), int(viewport[3])
        if not (1 <= vw <= self.size[0] and 1 <= vh <= self.size[1]):
            raise CatalogError(f"viewport {tuple(viewport)} does not fit the renderer's "
                               f"{self.size[0]}x{self.size[1]} HDR target")
        return vw, vh

    def cloth_moved(self) -> None:
        """The bound cloth buffers (bind_cloth_vertex_buffer) were rewritten on the GPU: the
        room's light follows (at its room_update_every); a sleeping cloth calls nothing."""
        self.mesh.version += 1

    def _timed(self, profile, name, work) -> None:
        """Run ``work()``; with a ``profile`` dict, finish the GL queue and add its wall time (s)."""
        if profile is None:
            work()
            return
        import time  # noqa: PLC0415

        self.ctx.finish()
        start = time.perf_counter()
        work()
        self.ctx.finish()
        profile[name] = profile.get(name, 0.0) + time.perf_counter() - start

    def draw_room_light(self, inputs, profile: dict | None = None) -> None:
        """The room's light before the frame: the key's maps, then the transport's update."""
        self._timed(profile, "room_shadow", lambda: self.shadow.draw_room_shadow(inputs))
        self._timed(profile, "room_transport", lambda: self.room_transport.update(inputs))

    def render_hdr(self, viewport=None, profile: dict | None = None) -> tuple[int, int]:
        """Background, room and curtain into the HDR target; returns the size drawn.
        ``profile``: a dict that receives each pass's wall time (s), the GL queue finished
        around each (the benchmark's per-pass shares; slower than a frame without it)."""
        mgl = self._moderngl
        inputs = self.terms.shading_inputs()
        vw, vh = self._viewport_size(viewport)
        view_proj = self.camera.view_projection(vw / vh)
        if self.schedule.stale():
            if self.room_lighting:
                # the room's transport: the beam's map (and the cloth's own), then its views of
                # the window, the operator and the cloth's two sides
                self.draw_room_light(inputs, profile)
            else:
                self._timed(profile, "cloth_shadow", lambda: self.shadow.draw_cloth_shadow_maps(inputs))
        msaa = self.targets.msaa_targets() if self.antialiasing == "msaa" else None
        hdr_fbo = msaa["hdr_fbo"] if msaa else self.targets.hdr_fbo
        hdr_fbo.use()
        self.ctx.viewport = (0, 0, vw, vh)
        hdr_fbo.clear(0.0, 0.0, 0.0, 1.0, depth=1.0, viewport=(0, 0, vw, vh))
        self.ctx.disable(mgl.BLEND)
        self.ctx.enable(mgl.DEPTH_TEST)
        self.ctx.depth_func = "<="
        if not self.curtain_open and not self.patterned:
            # the opaque flat curtain first: the depth test then skips the room behind it
            self._timed(profile, "curtain", lambda: self.curtain.draw_curtain(view_proj))
        if self.room_lighting:
            self._timed(profile, "room", lambda: self.room_transport.draw(view_proj, inputs))
        else:
            self._timed(profile, "room", lambda: self.room_transport.draw_constant(view_proj, inputs))
        # on the far plane: the depth test leaves only the pixels nothing covers
        self._timed(profile, "background", lambda: self.background.draw(view_proj, inputs))
        if not self.curtain_open and self.patterned:
            self._timed(profile, "curtain", lambda: self.curtain.draw_oit(view_proj, vw, vh, msaa))
        elif msaa:
            self.ctx.copy_framebuffer(self.targets.hdr_fbo, msaa["hdr_fbo"])   # resolve
        self.ctx.depth_func = "<"
        self.ctx.disable(mgl.DEPTH_TEST)
        return vw, vh

    def render(self, fbo=None, viewport=None, dt_s: float | None = None,
               profile: dict | None = None) -> None:
        """One frame: HDR passes, the glare (bloom, when on), then the display pass into
        ``fbo`` (default: our RGBA8 target) at ``viewport`` (x, y, w, h; default the whole
        renderer size).

        Auto exposure (``settings.ev`` None): this frame is metered (before the glare); ``dt_s``
        (the viewer's frame time) adapts the exposure toward it over
        display.ADAPTATION_TAU_S, None jumps. ``profile``: see :meth:`render_hdr` (adds
        "meter", "bloom" and "display")."""
        vw, vh = self.render_hdr(viewport, profile)
        if self.ev100 is None:
            self._timed(profile, "meter", lambda: setattr(
                self, "metered_ev100",
                display_lib.adapt_ev(self.metered_ev100, self.display.meter(vw, vh), dt_s)))
        source = {"glare": None}
        if self.bloom:
            self._timed(profile, "bloom", lambda: source.update(glare=self.glare.draw_bloom(vw, vh)))
        self._timed(profile, "display",
                    lambda: self.display.display_pass(vw, vh, fbo, viewport, source["glare"]))

    def read_linear(self) -> np.ndarray:
        """The last frame's HDR radiance: float32 (H, W, 3), linear sRGB, cd m^-2 scale, row 0 = top."""
        if self._last is None:
            raise CatalogError("nothing rendered yet")
        vw, vh = self._last[:2]
        data = self.targets.hdr_fbo.read(viewport=(0, 0, vw, vh), components=4, dtype="f4")
        return np.frombuffer(data, dtype=np.float32).reshape(vh, vw, 4)[::-1, :, :3].copy()

    def display_of(self, linear) -> np.ndarray:
        """Another radiance image (H, W, 3) linear sRGB at this renderer's size shown through
        the last frame's own display step: the glare when on (bloom), its exposure and white
        balance, the tone curve and the sRGB encoding, not its anti-aliasing (a rendering
        approximation, not a display one). uint8 (H, W, 3), row 0 = top. Overwrites the
        frame's HDR target and display image: read those first. The image bench shows the
        path-traced reference through it, so that the frame's glare is not counted as error."""
        w, h = self.size
        image = np.asarray(linear, dtype=np.float32)
        if image.shape != (h, w, 3):
            size = f"{image.shape[1]}x{image.shape[0]}" if image.ndim == 3 else str(image.shape)
            raise CatalogError(f"display_of: the image is {size} px, the frame {w}x{h} (H, W, 3 needed)")
        if self._last is None:
            raise CatalogError("display_of: render a frame first (its exposure shows the image)")
        rgba = np.concatenate([image[::-1], np.ones((h, w, 1), dtype=np.float32)], axis=-1)
        self.targets.hdr.write(np.ascontiguousarray(rgba).tobytes())
        glare = self.glare.draw_bloom(w, h) if self.bloom else None
        mode = self.antialiasing
        self.antialiasing = "off"
        try:
            self.display.display_pass(w, h, glare=glare)
        finally:
            self.antialiasing = mode
        return self.read_srgb8()

    def read_srgb8(self) -> np.ndarray:
        """The last frame tone-mapped and sRGB-encoded: uint8 (H, W, 3), row 0 = top."""
        if self._last is None:
            raise CatalogError("nothing rendered yet")
        vw, vh, fbo, viewport = self._last
        if fbo is None:
            data = self.targets.ldr_fbo.read(viewport=(0, 0, vw, vh), components=3)
        else:
            data = fbo.read(viewport=tuple(viewport) if viewport is not None else (0, 0, vw, vh),
                            components=3)
        return np.frombuffer(data, dtype=np.uint8).reshape(vh, vw, 3)[::-1].copy()

    def info(self) -> dict:
        inputs = self.terms.shading_inputs()
        decision = self.terms.decision
        metered = self.ev100 is not None or self.metered_ev100 is not None
        return {
            "fabric": self.preset.name,
            "light": self.light.name,
            "illuminance_lx": round(self.light.illuminance_lx, 3),
            "mode": decision.requested,
            "fluorescence_variant": inputs.fluorescence_mode,
            "fluorescence_needed": decision.needed,
            "fluorescence_delta_e": decision.delta_e,
            "bands": self.n_bands,
            "see_through": inputs.direct > 0,
            "key_to_light": [round(float(v), 6) for v in inputs.key_to_light],
            "camera": {"yaw_deg": self.camera.yaw_deg, "pitch_deg": self.camera.pitch_deg,
                       "distance_m": self.camera.distance_m,
                       "position_m": [round(float(v), 6) for v in self.camera.position]},
            "exposure": self.display.exposure_scale() if metered else None,
            "ev100": round(self.display.current_ev100(), 4) if metered else None,
            "auto_exposure": self.ev100 is None,
            "white_balance": self.white_balance,
            "white_balance_adapted": not np.allclose(self.display.white_balance_matrix(), np.eye(3)),
            "size": list(self.size),
            "room_lighting": self.room_lighting, "key_second_layer": self.key_second_layer,
            "shadow_map_size": self.shadow_texels,
            "curtain_open": self.curtain_open,
            "sky_model": self.sky_model, "bloom": self.bloom,
            "environment": None if self.environment is None else self.environment[0],
            "room_lamps": [[light.name, list(position)] for light, position in self.room_lamps],
        }

    # ------------------------------------------------------------------ the frame's own API
    # The mesh, the scene terms and the read-backs the viewer, the snapshot, the bench and
    # the tests use, kept on the frame; each pass's own read-backs are on the pass.
    def set_mesh(self, positions, normals, uvs, tangents, indices, fabric_size_m=None) -> None:
        """The curtain's mesh (:meth:`CurtainMesh.set_mesh`)."""
        self.mesh.set_mesh(positions, normals, uvs, tangents, indices, fabric_size_m)

    def set_fabric_size(self, fabric_size_m) -> None:
        self.mesh.set_fabric_size(fabric_size_m)

    def update_positions(self, positions, normals, tangents=None) -> None:
        self.mesh.update_positions(positions, normals, tangents)

    def bind_cloth_buffers(self, position_buffer, normal_buffer) -> None:
        self.mesh.bind_cloth_buffers(position_buffer, normal_buffer)

    def bind_cloth_vertex_buffer(self, vertex_buffer, index_buffer=None, offset_m=(0.0, 0.0, 0.0)) -> None:
        self.mesh.bind_cloth_vertex_buffer(vertex_buffer, index_buffer, offset_m)

    def set_mesh_offset(self, offset_m) -> None:
        self.mesh.set_mesh_offset(offset_m)

    @property
    def mesh_arrays(self):
        """The last mesh's (positions, normals, tangents) on the host."""
        return self.mesh.mesh_arrays

    @property
    def pattern(self):
        """The current fabric's :class:`catalog.presets.patterns.Pattern` (None: uniform coverage)."""
        return self.fabric_pattern.pattern

    def shading_inputs(self):
        """The scene's :class:`~catalog.optics.shading_reference.ShadingInputs` (SceneTerms)."""
        return self.terms.shading_inputs()

    def curtain_inputs(self):
        return self.terms.curtain_inputs()

    def white_balance_matrix(self) -> np.ndarray:
        return self.display.white_balance_matrix()

    def exposure_scale(self) -> float:
        return self.display.exposure_scale()

    def current_ev100(self) -> float:
        return self.display.current_ev100()

    def compiled_variants(self) -> list[dict]:
        return self.gl.compiled_variants()

    def render_gbuffer(self) -> dict[str, np.ndarray]:
        return self.curtain.render_gbuffer()

    def invalidate_room_light(self) -> None:
        """Redraw the room's light at the next frame (e.g. after the cloth moved on the GPU)."""
        self.schedule.invalidate()

    def twin_spectral(self, gbuffer: dict, mask) -> np.ndarray:
        return self.twin.twin_spectral(gbuffer, mask)

    def twin_room_side_rgb(self, gbuffer: dict, mask) -> np.ndarray:
        return self.twin.twin_room_side_rgb(gbuffer, mask)

    def twin_linear_srgb(self, gbuffer: dict, mask) -> np.ndarray:
        return self.twin.twin_linear_srgb(gbuffer, mask)

    def release(self) -> None:
        """Free this renderer's GL objects (not the context, not buffers bound from the cloth)."""
        ours = (self.targets.framebuffers() + self.room_targets.framebuffers()
                + self.glare.framebuffers()
                + (self._room_transport.framebuffers() if self._room_transport is not None else []))
        if self.ctx.fbo in ours:  # never leave a deleted framebuffer bound
            (self.ctx.screen or self.ctx.detect_framebuffer(0)).use()
        self.targets.release_msaa()
        self.gl.release_vaos()
        self.mesh.release()
        self._drop_room_transport()
        self.fabric_pattern.release()
        self.targets.release()
        self.gl.release()
        self.room_targets.release()
        self.glare.release()
        self.display.release()
        if self.environment is not None:
            self.environment[1].release()
            self.environment = None
