"""What the passes shade with, derived from the frame's settings (no GL)."""

from __future__ import annotations

import math

import numpy as np

from catalog.render import bands as band_lib, curtain_frames, scene as scene_lib


class SceneTerms:
    """What the passes shade with, derived from the frame's settings once per change (no GL):
    the :class:`~catalog.optics.shading_reference.ShadingInputs` (:meth:`shading_inputs`,
    the curtain's own without the stand-ins when the room side is solved), the curtain
    shader's banded values, the lamps', the display colours of the sky, ground, room and key,
    the dye per channel, the curtain's reflectance and transmittance of diffuse light, and the
    values the room's captures override."""

    def __init__(self, frame):
        self.frame = frame
        self._inputs = self.decision = None
        self.inputs_key = self._uniforms = self._uniforms_key = None
        self._curtain_inputs = self._curtain_inputs_key = None
        self._lamp_values = self._lamp_values_key = None
        self._window_side_values = self._window_side_key = None
        self._display = self._display_key = None
        self._dyes = self._dye_key = None
        self._scene_defines = self._scene_defines_key = None

    def curtain_inputs(self):
        """The :class:`ShadingInputs` the curtain program shades with: :meth:`shading_inputs`,
        without the stand-ins for the room's light when :meth:`room_side_active`
        (:func:`catalog.render.scene.with_room_solved`). The float64 twin of a frame takes these."""
        inputs = self.shading_inputs()
        if not self.frame.room_side_active():
            return inputs
        key = (self.inputs_key, "room_solved")
        if self._curtain_inputs_key != key:
            self._curtain_inputs = scene_lib.with_room_solved(inputs)
            self._curtain_inputs_key = key
        return self._curtain_inputs

    def shading_inputs(self):
        """The scene's :class:`catalog.optics.shading_reference.ShadingInputs` (rebuilt only on change)."""
        self.frame._require_ready()
        key = (id(self.frame.preset), self.frame.light.name, id(self.frame.light), tuple(self.frame._key_to_light),
               self.frame.mode, self.frame.viewer_inside, self.frame._is_sun)
        if key != self.inputs_key:
            # the settings' own (the path tracer's describe_scene takes the same)
            self._inputs, self.decision = self.frame.settings.shading_inputs(self.frame.placement)
            self.inputs_key = key
            self._uniforms_key = None
        return self._inputs

    def _band_uniforms(self):
        inputs = self.curtain_inputs()
        key = (self.inputs_key, self.frame.n_bands, self.frame.room_side_active())
        if key != self._uniforms_key:
            self._uniforms = band_lib.band_uniforms(inputs, self.frame.n_bands)
            self._uniforms_key = key
        return self._uniforms

    def scene_values(self) -> dict:
        """The curtain shader's per-scene values (uniform name -> value), float32-exact."""
        inputs = self.shading_inputs()
        values = {
            "u_key_to_light": tuple(float(v) for v in inputs.key_to_light),
            "u_fill_to_light": tuple(float(v) for v in inputs.fill_to_light),
            "u_sun_direction": tuple(float(v) for v in inputs.key_to_light),
            "u_sun_chord2": tuple(float(v) for v in inputs.sun_chord2),
            "u_direct": float(inputs.direct), "u_a_diff": float(inputs.a_diff),
            "u_g_diff": float(inputs.g_diff), "u_a_spec": float(inputs.a_spec),
            "u_g_spec": float(inputs.g_spec), "u_anisotropy": float(inputs.anisotropy),
        }
        for name, value in self._band_uniforms().items():
            values[name] = tuple(float(v) for v in value) if isinstance(value, tuple) else value
        return values

    def room_lamp_values(self) -> dict:
        """ROOM_LAMPS' uniforms: each lamp's position (m) and its intensity (irradiance at 1 m,
        isotropic) times the dye, in the renderer's bands (the key light's band weights)."""
        key = (self.inputs_key, self.frame.n_bands,
               tuple((light.name, position) for light, position in self.frame.room_lamps))
        if self._lamp_values_key != key:
            inputs = self.shading_inputs()
            weights, _ = band_lib.band_weights(self.frame.n_bands, inputs.key_irradiance)
            nv4 = band_lib.chunks(self.frame.n_bands)
            dyed = np.zeros((len(self.frame.room_lamps), 4 * nv4), dtype="f4")
            for j, (light, _position) in enumerate(self.frame.room_lamps):
                dyed[j, :self.frame.n_bands] = weights @ (light.irradiance_w_m2_nm * inputs.dye_transmittance)
            self._lamp_values = {
                "u_room_lamp_position": np.asarray([p for _l, p in self.frame.room_lamps], dtype="f4"),
                "u_room_lamp_dyed": dyed.reshape(-1, 4)}
            self._lamp_values_key = key
        return self._lamp_values

    def scene_values_with(self, overrides: dict | None) -> dict:
        """:meth:`scene_values` with ``overrides`` replaced, and what curtain.vert derives from
        them: the occlusion's loss of the ambient term (the outside's share hidden by the
        cloth, ``u_ambient_occluded``, and by the wall, ``u_ambient_outside``) summed over the
        bands in display RGB, as curtain.frag's shade_chunk projects a band (N_BANDS 3: the
        bands themselves)."""
        values = self.scene_values()
        if overrides:
            values = {**values, **overrides}
        n = self.frame.n_bands
        to_rgb = (np.eye(3) if n == 3 else
                  np.stack([np.asarray(values[f"u_band_to_{c}"], dtype=np.float64).reshape(-1)[:n]
                            for c in "rgb"]))
        for name in ("u_ambient_occluded", "u_ambient_outside"):
            banded = np.asarray(values[name], dtype=np.float64).reshape(-1)[:n]
            values[name + "_rgb"] = tuple(float(v) for v in to_rgb @ banded)
        return values

    def scene_defines(self, overrides: dict | None = None) -> dict[str, str]:
        """:meth:`scene_values_with` as the specialised program's #defines (``S_<NAME>``: GLSL
        literals); without overrides formatted once per change of the scene (the frame's own
        draws ask for them every frame)."""
        from catalog.gl.shaderlib import glsl_literal  # noqa: PLC0415

        if overrides:
            return {"S_" + name[2:].upper(): glsl_literal(value)
                    for name, value in self.scene_values_with(overrides).items()}
        self.shading_inputs()   # (its key follows the settings)
        key = (self.inputs_key, self.frame.n_bands, self.frame.room_side_active())
        if self._scene_defines_key != key:
            self._scene_defines = {"S_" + name[2:].upper(): glsl_literal(value)
                                   for name, value in self.scene_values_with(None).items()}
            self._scene_defines_key = key
        return self._scene_defines

    def capture_overrides(self) -> dict:
        """The curtain's values for the room transport's views of the window: without the sun's disc seen through
        it (the key light's beam reaches the room through the shadow map instead), without the
        key light scattered by the directional lobe (the beam carries it: counted in both, the
        room was up to 1.6x too bright under a low key), and without the room's light on its
        room side (the fill light and the room's share of the ambient term, stand-ins for it,
        and the lamps): the transport reflects the room's own
        light off the closed curtain (:meth:`window_albedo_rgb`), so the capture holds only
        what comes from outside and the glow."""
        values = self.scene_values()

        def zeros(value):
            return np.zeros_like(value) if isinstance(value, np.ndarray) else tuple(0.0 for _ in value)

        out = {"u_sun_disc": zeros(values["u_sun_disc"]), "u_fill_dyed": zeros(values["u_fill_dyed"]),
               "u_ambient": values["u_ambient_outside"]}
        # the directional lobe's share of the key travels in the beam (room_shadow.frag's
        # thread part), not in the window's radiance
        out["u_a_spec"] = 0.0
        if self.frame.room_lamps:
            dyed = self.room_lamp_values()["u_room_lamp_dyed"]
            out["u_room_lamp_dyed"] = np.zeros_like(dyed)
        return out

    def back_capture_overrides(self) -> dict:
        """The curtain's values for the capture of its window side (issue 11): as the room
        side's (:meth:`capture_overrides`) but with the directional lobe (its backward part is
        reflection, which the beam does not carry) and without the see-through (from outside,
        the cloth's holes show the room, which is not a source of the window wall's light)."""
        values = self.scene_values()
        out = self.capture_overrides()
        out["u_a_spec"] = values["u_a_spec"]
        out["u_direct"] = 0.0
        out.update(self._window_side_ambient())
        return out

    def _window_side_ambient(self) -> dict:
        """The ambient term of the cloth's window side seen from outside (issue 11, fourth
        round): the outside reflected by the lobes' backward factors, dye (a_diff backward(g_diff)
        + a_spec backward(g_spec)) x the outside's mean radiance, at the normal view's ratio, the
        sky and ground not split (the room eye's own terms, kept before, sent the outside's
        forward-scattered share, the light that crosses to the room, back out of the window)."""
        from dataclasses import replace  # noqa: PLC0415

        from catalog.optics.shading_reference import hg_hemisphere_factors  # noqa: PLC0415

        key = (self.inputs_key, self.frame.n_bands, self.frame.room_side_active())
        if self._window_side_key != key:
            inputs = self.curtain_inputs()
            backward = (inputs.a_diff * hg_hemisphere_factors(inputs.g_diff)[1]
                        + inputs.a_spec * hg_hemisphere_factors(inputs.g_spec)[1])
            reflected = (inputs.dye_transmittance * backward
                         * 0.5 * (inputs.sky_radiance + inputs.ground_radiance))
            banded = band_lib.band_uniforms(replace(inputs, ambient_radiance=reflected,
                                                    ambient_outside_radiance=reflected,
                                                    ambient_tilt_radiance=None), self.frame.n_bands)
            values = self.scene_values()
            self._window_side_values = {
                "u_ambient": banded["u_ambient"], "u_ambient_outside": banded["u_ambient_outside"],
                "u_ambient_occluded": banded["u_ambient_occluded"],
                "u_ambient_tilt": np.zeros_like(values["u_ambient_tilt"]),
                "u_ambient_view": band_lib.view_segments(None, None)}
            self._window_side_key = key
        return self._window_side_values

    def display_colours(self, inputs) -> dict[str, tuple]:
        """Exact linear sRGB of the background and room radiances (once per scene change)."""
        if self._display_key != self.inputs_key:
            spectra = {"u_sky_rgb": inputs.sky_radiance, "u_ground_rgb": inputs.ground_radiance,
                       "u_sun_disc_rgb": inputs.sun_disc_radiance,
                       "u_room_rgb": inputs.room_radiance,
                       "u_fill_rgb": scene_lib.ROOM_ALBEDO * inputs.fill_irradiance / math.pi,
                       "u_key_rgb": inputs.key_irradiance}
            self._display = {name: tuple(float(v) for v in band_lib.spectrum_to_display_rgb(s))
                             for name, s in spectra.items()}
            self._display_key = self.inputs_key
        return self._display

    def _dye_rgb(self, inputs, light: str) -> np.ndarray:
        """The dye per display channel (catalog.optics.dye_colour), once per scene change:
        ``"key"``, under the key, RGB(key x dye) / RGB(key), as the beam takes it; or
        ``"secondary"``, under what the key-lit cloth sends on (the key's share it passes
        and its glow), as the room's light and the folds' light between them take it."""
        from catalog.optics import dye_colour  # noqa: PLC0415

        if self._dye_key != self.inputs_key:
            self._dyes = {"key": dye_colour.key_dye_rgb(inputs), "secondary": dye_colour.secondary_dye_rgb(inputs)}
            self._dye_key = self.inputs_key
        return self._dyes[light]

    def room_colours(self, inputs) -> dict:
        """Linear sRGB of the key light (irradiance) and of the beam a thread passes: the
        directional lobe's forward-scattered part, a_spec forward(g_spec), in the dye's colour
        under the key light, per unit of thread coverage (mean coverage 1 - LD)."""
        from catalog.optics.shading_reference import hg_hemisphere_factors  # noqa: PLC0415

        colours = self.display_colours(inputs)
        key = np.asarray(colours["u_key_rgb"])
        dye_rgb = self._dye_rgb(inputs, "key")
        coverage = max(1.0 - float(inputs.direct), 1e-6)
        forward = hg_hemisphere_factors(float(inputs.g_spec))[0]
        thread = np.clip(float(inputs.a_spec) * forward * dye_rgb / coverage, 0.0, 1.0)
        lobe = key * float(inputs.a_spec) * dye_rgb
        return {"u_key_rgb": tuple(float(v) for v in key), "u_mean_coverage": 1.0 - float(inputs.direct),
                "u_thread_beam_rgb": tuple(float(v) for v in thread),
                "u_lobe_rgb": tuple(float(v) for v in lobe)}

    def key_depth_per_metre(self, inputs) -> float:
        """The key's maps' depth (0..1) per metre along the key's travel: orthographic, window
        depth = 0.5 ndc z + 0.5 with ndc z = m[2, 2] z_view + .., so a metre is -m[2, 2] / 2."""
        return abs(float(curtain_frames.light_view_projection(inputs.key_to_light, placement=self.frame.placement)[2, 2])) / 2

    def window_albedo_rgb(self, inputs) -> tuple[float, float, float]:
        """The closed curtain's room-side reflectance under diffuse light (linear sRGB): the
        lobes scattering back, dye (a_diff backward(g_diff) + a_spec backward(g_spec)), the
        dye per channel under the key as the room's colours take it; 0 when the curtain is
        open (the window reflects nothing)."""
        if self.frame.curtain_open:
            return (0.0, 0.0, 0.0)
        return self.curtain_room_reflectance_rgb(inputs)

    def curtain_forward_rgb(self, inputs) -> tuple[tuple, tuple]:
        """The cloth's transmittance of diffuse light by each lobe (linear sRGB), dye a_diff
        forward(g_diff) and dye a_spec forward(g_spec): what passes towards a viewer in the
        room of the light on the cloth's window side (curtain.frag ROOM_SIDE, the folds' light
        where they hide the outside, both lobes by the hemisphere's occlusion; and the window
        wall's, WALL_GRID). The dye per channel for the secondary light (:meth:`_dye_rgb`, since
        issue 11's seventh round; the key's before): the folds' light is the cloth's own, and
        the wall's reveals see the cloth's window side too. With no glow it is the key's."""
        from catalog.optics.shading_reference import hg_hemisphere_factors  # noqa: PLC0415

        dye_rgb = self._dye_rgb(inputs, "secondary")
        diffuse = float(inputs.a_diff) * hg_hemisphere_factors(float(inputs.g_diff))[0]
        directional = float(inputs.a_spec) * hg_hemisphere_factors(float(inputs.g_spec))[0]
        return tuple(tuple(float(v) for v in np.clip(dye_rgb * f, 0.0, 1.0)) for f in (diffuse, directional))

    def curtain_room_reflectance_rgb(self, inputs) -> tuple[float, float, float]:
        """The cloth's reflectance under the room's diffuse light (linear sRGB), dye (a_diff
        backward(g_diff) + a_spec backward(g_spec)), the dye per channel for the secondary
        light (:meth:`_dye_rgb`; the key's before issue 11's seventh round): what the
        transport's window reflects and what the curtain's room side sends back of the room's
        light (curtain.frag ROOM_SIDE)."""
        from catalog.optics.shading_reference import hg_hemisphere_factors  # noqa: PLC0415

        dye_rgb = self._dye_rgb(inputs, "secondary")
        back = (float(inputs.a_diff) * hg_hemisphere_factors(float(inputs.g_diff))[1]
                + float(inputs.a_spec) * hg_hemisphere_factors(float(inputs.g_spec))[1])
        return tuple(float(v) for v in np.clip(dye_rgb * back, 0.0, 1.0))
