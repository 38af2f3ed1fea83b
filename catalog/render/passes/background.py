"""Pass 2 of the frame: the outside (or the room seen from outside) behind everything else."""

from __future__ import annotations

import math

import numpy as np

from catalog.render import bands as band_lib, scene as scene_lib
from catalog.render.camera import gl_bytes
from catalog.render.passes.gl_common import ENVIRONMENT_UNIT, Pass, set_uniform

def gl_bytes_mat3(matrix: np.ndarray) -> bytes:
    """A 3x3 matrix (column-vector convention) as GLSL's column-major mat3."""
    return np.ascontiguousarray(np.asarray(matrix, dtype=np.float32).T).tobytes()


class BackgroundPass(Pass):
    """The outside by direction (fullscreen.vert + background.frag, on the far plane so that
    only the pixels nothing covers are shaded): the clear sky of catalog/optics/sun/sky.py
    (in the renderer's bands when not 3), an environment image, the ground, the sun's disc; or
    the room behind the cloth seen from outside. Also the window capture's outside.

    In: the scene terms, frame.environment. Out: radiance into the bound framebuffer."""

    def __init__(self, frame):
        super().__init__(frame)
        self._sky_key = None
        self._sky_value = None

    def sky_model_for(self, inputs):
        """The clear sky behind the window (catalog/optics/sun/sky.py) with the irradiance and
        colour of the curtain's own sky term (inputs.sky_radiance), so the two agree."""
        from catalog.optics.sun.sky import sky_model  # noqa: PLC0415

        return sky_model(inputs.key_to_light, diffuse_horizontal=math.pi * inputs.sky_radiance,
                         ground_radiance=inputs.ground_radiance)

    def _sky(self, inputs):
        """The clear-sky model for a sun above the horizon (catalog/optics/sun/sky.py), else None."""
        if not (self.frame.sky_model and self.frame._is_sun and inputs.key_to_light[1] > 1e-3):
            return None
        key = (self.frame.terms.inputs_key, self.frame.n_bands)
        if self._sky_key != key:
            from catalog.optics.colorimetry import xyz_to_linear_srgb  # noqa: PLC0415
            from catalog.optics.sun.sky import HAZE_RAD  # noqa: PLC0415

            model = self.sky_model_for(inputs)
            self._sky_value = {
                "u_perez": np.asarray(model.perez, dtype="f4"),
                "u_zenith_xyY": tuple(float(v) for v in model.zenith),
                "u_perez_sun": tuple(float(v) for v in np.ravel(model.perez_sun)),
                "u_sky_scale": tuple(float(v) for v in model.scale_rgb),
                "u_xyz_to_rgb": gl_bytes_mat3(xyz_to_linear_srgb(np.eye(3)).T),
                "u_haze_rad": HAZE_RAD,
                "u_ground_rgb": tuple(float(v) for v in model.ground_rgb),
            }
            if self.frame.n_bands != 3:
                self._sky_value.update(self._sky_band_values(inputs))
            self._sky_key = key
        return self._sky_value

    def spectral_sky_for(self, inputs):
        """The sky of :meth:`sky_model_for` per wavelength (catalog/optics/sun/sky.py SpectralSky)."""
        from catalog.optics.sun.sky import spectral_sky  # noqa: PLC0415

        return spectral_sky(inputs.key_to_light, math.pi * inputs.sky_radiance, inputs.ground_radiance)

    def _sky_band_values(self, inputs) -> dict:
        """SKY_BANDS' uniforms: the sky and the ground integrated over the renderer's bands (the
        key light's band weights and display matrix, as the curtain's own terms)."""
        weights, to_rgb = band_lib.band_weights(self.frame.n_bands, inputs.key_irradiance)
        colours = self.spectral_sky_for(inputs).band_colours(weights, to_rgb)
        return {"u_sky_basis_rgb": np.asarray(colours["basis_rgb"], dtype="f4"),
                "u_sky_basis_luminance": tuple(float(v) for v in colours["basis_luminance"]),
                "u_ground_rgb": tuple(float(v) for v in colours["ground_rgb"])}

    def environment_scale(self, inputs) -> float:
        """The environment image's factor: its upper hemisphere's horizontal illuminance made
        the light's sky's, pi x Y(sky radiance) (the clear sky's diffuse illuminance for the
        sun, the lit backdrop's for a lamp)."""
        target = math.pi * float(np.dot(band_lib.spectrum_to_display_rgb(inputs.sky_radiance),
                                        (0.2126, 0.7152, 0.0722)))
        return target / self.frame.environment[2]

    def draw(self, view_proj, inputs, camera_position=None, sun_disc=True,
                         capture: bool = False) -> None:
        """The outside by direction; ``capture``: for the room's window capture (alpha 0)."""
        sky = None if self.frame.environment is not None else self._sky(inputs)
        program = self.gl.program("fullscreen.vert", "background.frag",
                                {"SKY_MODEL": sky is not None,
                                 "SKY_BANDS": sky is not None and self.frame.n_bands != 3,
                                 "ENVIRONMENT": self.frame.environment is not None,
                                 "ROOM_CAPTURE": capture})
        self.frame.curtain.scene_uniforms(program, view_proj, inputs, camera_position)
        if self.frame.environment is not None:
            self.frame.environment[1].use(location=ENVIRONMENT_UNIT)
            set_uniform(program, "u_environment", ENVIRONMENT_UNIT)
            set_uniform(program, "u_environment_scale", self.environment_scale(inputs))
        set_uniform(program, "u_inverse_view_proj", gl_bytes(np.linalg.inv(view_proj)))
        colours = self.frame.terms.display_colours(inputs)
        for name in ("u_sky_rgb", "u_ground_rgb", "u_sun_disc_rgb", "u_room_rgb"):
            set_uniform(program, name, colours[name])
        if sky is not None:
            for name, value in sky.items():
                set_uniform(program, name, value)
        if not sun_disc:
            set_uniform(program, "u_sun_disc_rgb", (0.0, 0.0, 0.0))
        if capture:
            placement = self.frame.placement   # the frame's room's window
            set_uniform(program, "u_capture_opening", placement.window_rect)
            set_uniform(program, "u_capture_wall_z", placement.window_z)
        self.gl.fullscreen_vao(program).render(self.mgl.TRIANGLES, vertices=3)
