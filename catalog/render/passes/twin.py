"""The frame's float64 twin and the numpy evaluations of its per-vertex room light."""

from __future__ import annotations

import math

import numpy as np

from catalog.render import room_light


class FrameTwin:
    """The frame's float64 twin at G-buffer pixels and its numpy evaluations of the
    per-vertex room light (what tests hold the shaders to); reads the room's maps back."""

    def __init__(self, frame):
        self.frame = frame

    def wall_light_at(self, positions, walled_share) -> np.ndarray:
        """curtain.vert WALL_LIGHT's light evaluated in numpy at world ``positions`` (P, 3) with
        the outside's walled share ``walled_share`` (P,) (the per-vertex occlusion's y), float64
        (P, 3): the diffuse lobe's forward transmittance times the walled hemisphere's radiance
        (:func:`room_light.walled_radiance`), the directional lobe's times its samples about
        the view's continuation (:func:`room_light.wall_lobe_radiance`) plus the walled share
        of the outside's mean; 0 where the room side takes the stand-ins or the outside's
        occlusion is off."""
        p = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
        if not self.frame.curtain.variant_defines().get("WALL_LIGHT"):
            return np.zeros_like(p)
        sources = self.wall_light_sources()
        view = p - np.asarray(self.frame.camera.position, dtype=np.float64)
        view /= np.linalg.norm(view, axis=-1, keepdims=True)
        inputs = self.frame.terms.shading_inputs()
        lobe = room_light.wall_lobe_radiance(p, view, sources, room_light.wall_lobe_directions(float(inputs.g_spec)))
        outside_mean = (np.asarray(sources.reveal_sky) + np.asarray(sources.reveal_ground)) / math.pi
        share = np.asarray(walled_share, dtype=np.float64).reshape(-1, 1)
        diffuse, directional = (np.asarray(v, dtype=np.float64) for v in self.frame.terms.curtain_forward_rgb(inputs))
        return diffuse * room_light.walled_radiance(p, sources) + directional * (lobe + share * outside_mean)

    def room_side_irradiance_at(self, positions) -> np.ndarray:
        """(P, 3) the room-side grid's last irradiance read as curtain.frag ROOM_SIDE reads it
        at world ``positions`` (bilinear, clamped to the opening's edge), float64."""
        return room_light.sample_bilinear(self.frame.lightmap.read_room_side(), room_light.curtain_side_uv(positions))

    def room_side_light_at(self, positions, room_hidden) -> tuple[np.ndarray, np.ndarray]:
        """curtain.vert ROOM_SIDE's light evaluated in numpy at ``positions`` (P, 3) with the
        room's side hidden by ``room_hidden`` (P,): the irradiance on the room side (the grid,
        bilinear, where open; pi x the room's capture at the patch where hidden) and the
        window-side capture's radiance at the patch, float64 (P, 3) each."""
        uv = np.clip(room_light.curtain_side_uv(positions), 0.0, 0.999)
        columns = (uv[:, 0] * room_light.LUMINAIRE_TEXELS[0]).astype(int)
        rows = (uv[:, 1] * room_light.LUMINAIRE_TEXELS[1]).astype(int)
        hidden = np.asarray(room_hidden, dtype=np.float64).reshape(-1, 1)
        room = self.frame.capture.read_luminaire(room_light.LUMINAIRE_LEVEL)[rows, columns].astype(np.float64)
        window = self.frame.capture.read_luminaire_back(room_light.BACK_LUMINAIRE_LEVEL)[rows, columns].astype(np.float64)
        return (1.0 - hidden) * self.room_side_irradiance_at(positions) + hidden * math.pi * room, window

    def wall_light_sources(self) -> room_light.WallLightSources:
        """What the window wall and its reveals show the cloth's window side, from the room's
        last light (:func:`room_light.walled_radiance`'s inputs, as the GL pass binds them)."""
        inputs = self.frame.terms.shading_inputs()
        reveals = self.frame.terms.reveal_inputs(inputs)
        return room_light.WallLightSources(
            lightmap=self.frame.lightmap.read_room_lightmap(),
            back=self.frame.capture.read_luminaire_back(reveals["back_level"]),
            reveal_sky=np.asarray(reveals["sky_half"], dtype=np.float64),
            reveal_ground=np.asarray(reveals["ground_half"], dtype=np.float64),
            key_rgb=np.asarray(self.frame.terms.room_colours(inputs)["u_key_rgb"], dtype=np.float64),
            to_light=np.asarray(inputs.key_to_light, dtype=np.float64))

    def twin_spectral(self, gbuffer: dict, mask) -> np.ndarray:
        """The float64 twin's spectral radiance (P, L) at the G-buffer pixels ``mask``: eq. 8 with
        :meth:`curtain_inputs` and the pixels' shadows (without the room side's RGB term,
        :meth:`twin_room_side_rgb`)."""
        from catalog.optics import shading_reference as ref  # noqa: PLC0415

        return ref.shade_spectral(self.frame.terms.curtain_inputs(), gbuffer["position"][mask], gbuffer["normal"][mask],
                                  gbuffer["tangent"][mask], self.frame.camera.position,
                                  **ref.shadow_terms(gbuffer["shadows"][mask], gbuffer["second_coverage"][mask]))

    def twin_room_side_rgb(self, gbuffer: dict, mask) -> np.ndarray:
        """The twin of ROOM_SIDE's term (P, 3) linear sRGB at the G-buffer pixels (0 when the
        room side takes the stand-ins), from the per-vertex light the G-buffer carries (its
        values against their numpy evaluation: :meth:`room_side_light_at`)."""
        from catalog.optics import shading_reference as ref  # noqa: PLC0415

        positions = gbuffer["position"][mask]
        if not self.frame.room_side_active():
            return np.zeros((positions.shape[0], 3))
        # the per-vertex light curtain.vert read (the G-buffer's, interpolated; its values are
        # held to their numpy evaluation by tests/test_render_room.py), where the folds hide the
        # outside (the hemisphere's share, for both lobes since issue 11's sixth round) passed
        # by each lobe
        inputs, normals = self.frame.terms.curtain_inputs(), gbuffer["normal"][mask]
        hidden_outside = gbuffer["shadows"][mask][:, 2].astype(np.float64)[:, None]
        window_side = gbuffer["window_side_light"][mask].astype(np.float64)
        return (ref.room_side_linear_srgb(inputs, positions, normals, self.frame.camera.position,
                                          gbuffer["room_side_light"][mask].astype(np.float64),
                                          self.frame.terms.curtain_room_reflectance_rgb(self.frame.terms.shading_inputs()))
                + sum(ref.window_side_linear_srgb(inputs, positions, normals, self.frame.camera.position,
                                                  math.pi * share * window_side, transmittance)
                      for share, transmittance in zip((hidden_outside, hidden_outside),
                                                      self.frame.terms.curtain_forward_rgb(self.frame.terms.shading_inputs())))
                # the window wall and its reveals (WALL_LIGHT), each lobe's share already passed
                + ref.window_side_linear_srgb(inputs, positions, normals, self.frame.camera.position,
                                              math.pi * gbuffer["wall_light"][mask].astype(np.float64),
                                              (1.0, 1.0, 1.0)))

    def twin_linear_srgb(self, gbuffer: dict, mask) -> np.ndarray:
        """The float64 twin of the curtain's linear sRGB (P, 3) at the G-buffer pixels ``mask``
        (1 nm spectral eq. 8 plus the room side's term; tests hold the shader to it)."""
        from catalog.optics import shading_reference as ref  # noqa: PLC0415

        return ref.spectral_to_linear_srgb(self.twin_spectral(gbuffer, mask)) + self.twin_room_side_rgb(gbuffer, mask)
