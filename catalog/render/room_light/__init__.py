"""The room lit through the curtain (issue 13, model.md section 9): the static room's geometry
as a light-map atlas, its precomputed ambient occlusion, the light-space frame of the key
light's transmittance shadow map and the window's luminaire grid. No GL here: numpy arrays
and matrices the renderer (:mod:`catalog.render.frame`) uploads.

The room is the box ``scene.ROOM_BOX`` with the window opening ``scene.WINDOW_RECT`` in its
wall z = WINDOW_Z. Its six inside faces are parametrised as
``P(s, t) = origin + s * axis_s + t * axis_t`` (s, t in [0, 1]); the light-map atlas holds
them side by side, FACE_TEXELS x FACE_TEXELS each (face k at columns k R .. (k + 1) R - 1).
Irradiance (linear sRGB, the renderer's cd m^-2 scale times pi) is stored per texel:

- direct: the curtain (and the sky through the window) as an area light, one patch per
  texel of the luminaire capture (:data:`LUMINAIRE_TEXELS`), ``E = sum L cos_p cos_r A / r^2``;
  the key light's beam through the window and the curtain (the transmittance shadow map);
  lamps placed in the room (isotropic points, ``E = I cos_r / r^2``);
- bounces, all of them: the coarse patches' total irradiance ``T = (I - K)^-1 S`` (the radiosity
  solve of model.md section 9, :func:`radiosity_operator`: S the direct light of each coarse patch, K
  the patch-to-patch transfer below, precomputed once as the matrix ``(I - K)^-1 - I``),
  then per texel ``E(x) = E_direct(x) + ao(x) / pi sum_j rho_j T_j F_j(x)`` (F_j pi times the
  exact form factor of patch j, :func:`rectangle_irradiance_factor`)
  over the coarse patches (rho_j the wall's albedo, or in the window opening the closed
  curtain's room-side reflectance: the cloth sends part of the room's light back) (the room is a convex box: every patch sees every other), with
  the ambient occlusion below. One bounce alone (issue 13's frame) left the walls 30 % and
  the floor 45 % darker than the path-traced reference (issue 11): with walls of albedo 0.6
  the bounces after the first double the first.

Ambient occlusion (precomputed once, the room is static): the cosine-weighted fraction of
the hemisphere over a texel that is free of the window's reveals and the rod within
AO_RADIUS_M (obscurance), by ray casting against their boxes in numpy. The room's faces are
not occluders: the bounce's form factors are exact (Lambert's polygon formula,
:func:`rectangle_irradiance_factor`), so a corner gets the light of the faces that meet there.
"""

# The room light's numpy side, by part (re-exported: callers write room_light.NAME).
from catalog.render.room_light.geometry import *  # noqa: F401,F403
from catalog.render.room_light.radiosity import *  # noqa: F401,F403
from catalog.render.room_light.views import *  # noqa: F401,F403
from catalog.render.room_light.window import *  # noqa: F401,F403
from catalog.render.room_light.wall_light import *  # noqa: F401,F403
