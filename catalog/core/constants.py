"""Constants more than one room needs, each written once. Python code imports them from
here; the shaders receive the ones they need as #defines (:data:`SHADER_DEFINES`, injected
by catalog.gl.shaderlib into every program), never as a second literal in GLSL."""

#: Maximum luminous efficacy of radiation, lm W^-1 (the SI candela definition: 683 lm/W at
#: 540 THz). XYZ = 683 sum cmf(l) S(l) dl puts Y in lux for an irradiance, cd m^-2 for a radiance.
LUMINOUS_EFFICACY_LM_W = 683.0

#: The cloth's frame step (s): what one rendered frame advances the simulation by wherever the
#: frame count, not the wall clock, sets the time (``--frame N``, ``view --frames``, the drape's
#: settling, the batch renderer, the cloth benchmark). Substeps are chosen inside a step.
FRAME_DT_S = 1.0 / 60.0

#: Relative luminance of linear sRGB / Rec. 709 primaries (Y = 0.2126 R + 0.7152 G + 0.0722 B).
LUMA_REC709 = (0.2126, 0.7152, 0.0722)

#: The fluorescence modes of eq. 8 (docs/model.md section 6): none, the paper's, physical.
FLUORESCENCE_MODES = ("off", "paper", "physical")
#: The modes that draw fluorescence (the command lines' --mode choices).
FLUORESCENT_MODES = FLUORESCENCE_MODES[1:]

#: Eq. 6's denominator d = 1 + g^2 - 2 g cos(theta) is formed as (1 - g)^2 + 2 g (1 - cos)
#: for g >= HG_MIRROR_BELOW and as the mirrored (1 + g)^2 - 2 g (1 + cos) below it. Both are
#: exact algebra; the forward form cancels only for a strongly backward lobe near theta = pi:
#: for g >= -0.2 it loses at most |g| 5e-7 / (1 + g)^2 < 3e-7 (relative, float32) there, so
#: the anti-chord is formed only where it is needed. One threshold for Python and GLSL.
HG_MIRROR_BELOW = -0.2

#: The cloth's ambient term by view (issue 11, docs/model.md section 9) is tabulated at this
#: many values of mu = |n . v|, evenly from 0 to 1 (linear between), held in
#: AMBIENT_VIEW_NODES - 1 vec4 segments in the shaders (catalog/render/bands.py view_segments).
AMBIENT_VIEW_NODE_COUNT = 17

#: What every shader program gets as #define (name -> value), from the constants above.
SHADER_DEFINES = {"HG_MIRROR_BELOW": HG_MIRROR_BELOW,
                  "AMBIENT_VIEW_NODES": AMBIENT_VIEW_NODE_COUNT}
