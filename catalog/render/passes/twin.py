"""The frame's float64 twin and the numpy evaluations of its per-vertex room light."""

from __future__ import annotations

import math

import numpy as np


class FrameTwin:
    """The frame's float64 twin at G-buffer pixels and its numpy evaluations of the
    per-vertex room light (what tests hold the shaders to), from the room transport's last update."""

    def __init__(self, frame):
        self.frame = frame

    def wall_light_at(self, positions) -> np.ndarray:
        """curtain.vert WALL_GRID's light in numpy at world ``positions`` (P, 3), float64 (P, 3):
        both lobes' forward transmittance of the wall's irradiance on the cloth's plane over
        pi; 0 where the room side takes the stand-ins or the outside's occlusion is off."""
        p = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
        if not self.frame.curtain.variant_defines().get("WALL_GRID"):
            return np.zeros_like(p)
        _room, _window, walled = self.frame.room_transport.cloth_light_at(p, np.zeros(len(p)))
        diffuse, directional = (np.asarray(v, dtype=np.float64) for v in
                                self.frame.terms.curtain_forward_rgb(self.frame.terms.shading_inputs()))
        return (diffuse + directional) * walled / math.pi

    def room_side_light_at(self, positions, room_hidden) -> tuple[np.ndarray, np.ndarray]:
        """curtain.vert ROOM_SIDE's light evaluated in numpy at ``positions`` (P, 3) with the
        room's side hidden by ``room_hidden`` (P,): the irradiance on the room side (the
        transport's gather where open, the folds' exitance where hidden) and the window side's
        mean radiance, float64 (P, 3) each."""
        room, window, _walled = self.frame.room_transport.cloth_light_at(positions, room_hidden)
        return room, window

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
        # held to their numpy evaluation by tests/test_room_transport_pass.py), where the folds hide the
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
                # the window wall and its reveals (WALL_GRID), each lobe's share already passed
                + ref.window_side_linear_srgb(inputs, positions, normals, self.frame.camera.position,
                                              math.pi * gbuffer["wall_light"][mask].astype(np.float64),
                                              (1.0, 1.0, 1.0)))

    def twin_linear_srgb(self, gbuffer: dict, mask) -> np.ndarray:
        """The float64 twin of the curtain's linear sRGB (P, 3) at the G-buffer pixels ``mask``
        (1 nm spectral eq. 8 plus the room side's term; tests hold the shader to it)."""
        from catalog.optics import shading_reference as ref  # noqa: PLC0415

        return ref.spectral_to_linear_srgb(self.twin_spectral(gbuffer, mask)) + self.twin_room_side_rgb(gbuffer, mask)
