"""Validated physical parameters of a hanging curtain.

Units are in the names (``_m``, ``_kg_m2``, ``_n_m``, ``_s``). Coordinates: metres, y up;
the rod runs along x at ``rod_height_m``, centred on x = 0; the curtain hangs in the
plane z = 0 with its room side towards +z; the window wall is the plane
z = -``wall_gap_m`` and the floor is y = 0.

Stiffness is a membrane stiffness in N/m (force per unit width per unit strain). On a
square grid a structural spring then has exactly that stiffness in N/m whatever the
spacing (k = K * width / length), so ``--stiffness`` means the same on every grid.

A bad value is refused with :class:`catalog.core.errors.InputError` naming the field.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace
from typing import Any, Mapping

from catalog.core.errors import InputError

#: Standard gravity, m s^-2 (the one value used everywhere in the cloth code).
GRAVITY_M_S2 = 9.80665
#: Air density at 20 C, sea level, kg m^-3.
AIR_DENSITY_KG_M3 = 1.204
#: Strain above the limit that the last substep's sweeps accept before stopping (both cpu
#: backends; the gpu backend runs a fixed number of sweeps instead).
STRAIN_TOLERANCE = 5e-4

#: Defaults by weave: (areal density kg/m^2, stretch stiffness N/m, bend stiffness N/m).
#: Orders of magnitude for curtain fabrics: a voile or lace is light and open, a plain
#: weave cotton heavier and stiffer, a twill or satin drapery heavier still.
WEAVE_DEFAULTS: dict[str, tuple[float, float, float]] = {
    "lace": (0.06, 5.0e3, 0.5),
    "voile": (0.05, 8.0e3, 0.4),
    "plain": (0.12, 2.0e4, 2.0),
    "twill": (0.20, 3.0e4, 4.0),
    "satin": (0.18, 2.5e4, 3.0),
}
DEFAULT_WEAVE = "plain"


def _finite(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"must be a number, found {value!r}", field=name)
    value = float(value)
    if not math.isfinite(value):
        raise InputError(f"must be finite, found {value}", field=name)
    return value


def _positive(name: str, value: Any) -> float:
    value = _finite(name, value)
    if value <= 0.0:
        raise InputError(f"must be > 0, found {value:g}", field=name)
    return value


def _non_negative(name: str, value: Any) -> float:
    value = _finite(name, value)
    if value < 0.0:
        raise InputError(f"must be >= 0, found {value:g}", field=name)
    return value


def _fraction(name: str, value: Any, low_exclusive: bool = False) -> float:
    value = _finite(name, value)
    if value > 1.0 or value < 0.0 or (low_exclusive and value == 0.0):
        bound = "(0, 1]" if low_exclusive else "[0, 1]"
        raise InputError(f"must be in {bound}, found {value:g}", field=name)
    return value


@dataclass(frozen=True)
class ClothParams:
    """Everything the simulation needs, checked at construction.

    ``grid_w`` particles across the rod (columns), ``grid_h`` down the curtain (rows);
    row 0 is the row of rings on the rod.
    """

    grid_w: int = 48
    grid_h: int = 64
    width_m: float = 1.4  # rest width of the fabric (when closed the rings span it)
    height_m: float = 2.2  # rest length of the fabric from the rings down
    areal_density_kg_m2: float = WEAVE_DEFAULTS[DEFAULT_WEAVE][0]
    stretch_stiffness_n_m: float = WEAVE_DEFAULTS[DEFAULT_WEAVE][1]
    shear_stiffness_n_m: float | None = None  # None: 10% of the stretch stiffness
    bend_stiffness_n_m: float = WEAVE_DEFAULTS[DEFAULT_WEAVE][2]
    damping_per_s: float = 0.5  # mass-proportional velocity damping (halves in 1.4 s)
    drag_coefficient: float = 1.2  # C_d of a flat plate, on the normal relative velocity
    air_density_kg_m3: float = AIR_DENSITY_KG_M3
    gravity_m_s2: float = GRAVITY_M_S2
    wind_speed_m_s: float = 0.0  # mean wind from the window (+z blows into the room)
    wind_direction: tuple[float, float, float] = (0.0, 0.0, 1.0)
    gust_strength: float = 0.6  # relative amplitude of the gusts, 0 = steady wind
    gust_length_m: float = 0.8  # spatial scale of the gust noise
    gust_period_s: float = 2.5  # time scale of the gust noise
    max_stretch: float = 0.10  # Provot's strain limit on stretch and shear springs
    opening: float = 1.0  # fraction of the rest width the rings span (1 = closed)
    ring_spacing_m: float = 0.10  # rest fabric between two rings (a ring every k columns)
    ring_speed_m_s: float = 0.6  # how fast the rings slide to a new opening
    rod_height_m: float | None = None  # None: height_m + 0.05 (hem just above the floor)
    wall_gap_m: float = 0.12  # the window wall is the plane z = -wall_gap_m
    thickness_m: float = 0.004  # collision offset from the wall and floor planes
    contact_damping_per_s: float = 5.0  # tangential velocity lost per second in contact
    strain_passes: int = 1  # strain-limiting sweeps per substep (after the LRA)
    final_strain_passes: int = 64  # at most this many in a frame's last substep (adaptive)
    max_substep_s: float = 1.0 / 600.0  # substeps per frame = ceil(frame_dt / this)
    # sleep (simulation.py, "Sleep"): calm when the largest particle speed is under
    # sleep_speed_m_s and the RMS speed under sleep_rms_speed_m_s (the kinetic energy,
    # 1/2 M v_rms^2); asleep after sleep_hold_s of simulated time calm; the calm spell only
    # ends above wake_factor times either threshold (hysteresis)
    sleep_speed_m_s: float = 5.0e-3
    sleep_rms_speed_m_s: float = 1.0e-3
    wake_factor: float = 2.0
    sleep_hold_s: float = 0.5
    extra: Mapping[str, Any] = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        for name in ("grid_w", "grid_h"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int):
                raise InputError(f"must be an integer, found {value!r}", field=name)
            if value < 2:
                raise InputError(f"needs at least 2 particles, found {value}", field=name)
            if value > 4096:
                raise InputError(f"at most 4096 particles a side, found {value}", field=name)
        for name in ("width_m", "height_m", "areal_density_kg_m2", "stretch_stiffness_n_m",
                     "gust_length_m", "gust_period_s", "max_stretch", "max_substep_s",
                     "ring_speed_m_s", "ring_spacing_m", "thickness_m", "sleep_hold_s"):
            _positive(name, getattr(self, name))
        for name in ("bend_stiffness_n_m", "damping_per_s", "drag_coefficient",
                     "air_density_kg_m3", "gravity_m_s2", "wind_speed_m_s", "gust_strength",
                     "wall_gap_m", "sleep_speed_m_s", "sleep_rms_speed_m_s",
                     "contact_damping_per_s"):
            _non_negative(name, getattr(self, name))
        if self.shear_stiffness_n_m is not None:
            _non_negative("shear_stiffness_n_m", self.shear_stiffness_n_m)
        if self.rod_height_m is not None:
            _positive("rod_height_m", self.rod_height_m)
        _fraction("opening", self.opening, low_exclusive=True)
        if self.max_stretch > 1.0:
            raise InputError(f"must be <= 1, found {self.max_stretch:g}", field="max_stretch")
        if isinstance(self.strain_passes, bool) or not isinstance(self.strain_passes, int) \
                or not 0 <= self.strain_passes <= 8:
            raise InputError(f"must be an integer in 0..8, found {self.strain_passes!r}",
                             field="strain_passes")
        if isinstance(self.final_strain_passes, bool) \
                or not isinstance(self.final_strain_passes, int) \
                or not 0 <= self.final_strain_passes <= 256:
            raise InputError(f"must be an integer in 0..256, found "
                             f"{self.final_strain_passes!r}", field="final_strain_passes")
        if _finite("wake_factor", self.wake_factor) < 1.0:
            raise InputError(f"must be >= 1 (wake above the sleep thresholds), found "
                             f"{self.wake_factor:g}", field="wake_factor")
        direction = self.wind_direction
        if not isinstance(direction, (tuple, list)) or len(direction) != 3:
            raise InputError(f"must be 3 numbers, found {direction!r}", field="wind_direction")
        direction = tuple(_finite("wind_direction", c) for c in direction)
        norm = math.sqrt(sum(c * c for c in direction))
        if norm == 0.0:
            raise InputError("must not be the zero vector", field="wind_direction")
        object.__setattr__(self, "wind_direction", tuple(c / norm for c in direction))
        if self.wall_gap_m <= self.thickness_m:
            raise InputError(f"must exceed thickness_m ({self.thickness_m:g}), found "
                             f"{self.wall_gap_m:g}", field="wall_gap_m")

    # ---- derived quantities -------------------------------------------------------
    @property
    def particle_count(self) -> int:
        return self.grid_w * self.grid_h

    @property
    def spacing_x_m(self) -> float:
        """Rest distance between neighbouring columns."""
        return self.width_m / (self.grid_w - 1)

    @property
    def spacing_y_m(self) -> float:
        """Rest distance between neighbouring rows."""
        return self.height_m / (self.grid_h - 1)

    @property
    def particle_mass_kg(self) -> float:
        """Mass of one particle: the areal density times its share of the fabric."""
        return self.areal_density_kg_m2 * self.spacing_x_m * self.spacing_y_m

    @property
    def ring_every(self) -> int:
        """Columns from one ring to the next (at least 1)."""
        return max(1, round(self.ring_spacing_m / self.spacing_x_m))

    @property
    def rod_y_m(self) -> float:
        return self.height_m + 0.05 if self.rod_height_m is None else float(self.rod_height_m)

    @property
    def shear_n_m(self) -> float:
        return (0.1 * self.stretch_stiffness_n_m if self.shear_stiffness_n_m is None
                else float(self.shear_stiffness_n_m))

    def spring_stiffness_n_m(self) -> dict[str, float]:
        """Per-spring stiffness of each family (N/m) from the membrane stiffnesses.

        Structural: k = K * (strip width) / (spring length); shear and bend springs take
        the shear and bend values as they are.
        """
        dx, dy = self.spacing_x_m, self.spacing_y_m
        k = self.stretch_stiffness_n_m
        return {"horizontal": k * dy / dx, "vertical": k * dx / dy,
                "shear": self.shear_n_m, "bend": self.bend_stiffness_n_m}

    def substeps_for(self, frame_dt_s: float) -> int:
        """Substeps of one frame: the frame cut into steps no longer than max_substep_s.

        The count depends on the frame time only, never on the stiffness: stiff springs
        are handled by the compliant constraint pass (XPBD), not by smaller steps.
        """
        frame_dt_s = _positive("dt", frame_dt_s)
        return max(1, math.ceil(frame_dt_s / self.max_substep_s - 1e-9))

    def with_changes(self, **changes: Any) -> "ClothParams":
        """A copy with some fields changed (validated again)."""
        return replace(self, **changes)

    @classmethod
    def field_names(cls) -> list[str]:
        return [f.name for f in fields(cls) if f.name != "extra"]

    @classmethod
    def for_weave(cls, weave: str, **overrides: Any) -> "ClothParams":
        """Defaults of a weave (``lace``, ``voile``, ``plain``, ``twill``, ``satin``)."""
        if weave not in WEAVE_DEFAULTS:
            raise InputError(f"unknown weave {weave!r}; known: {', '.join(WEAVE_DEFAULTS)}",
                             field="weave")
        density, stretch, bend = WEAVE_DEFAULTS[weave]
        values = {"areal_density_kg_m2": density, "stretch_stiffness_n_m": stretch,
                  "bend_stiffness_n_m": bend}
        values.update(overrides)
        return cls(**values)

    @classmethod
    def from_preset(cls, preset: Any, **overrides: Any) -> "ClothParams":
        """Parameters from a preset's ``[cloth]`` table, weave defaults for what it lacks.

        Keys read: ``weave``, ``areal_density_kg_m2``, ``stretch_stiffness_n_m``,
        ``bend_stiffness_n_m``; other keys of the table are kept in ``extra``.
        """
        table = dict(preset.table("cloth")) if hasattr(preset, "table") else dict(preset)
        path = getattr(preset, "path", None)
        weave = table.pop("weave", DEFAULT_WEAVE)
        if weave not in WEAVE_DEFAULTS:
            raise InputError(f"unknown weave {weave!r}; known: {', '.join(WEAVE_DEFAULTS)}",
                             path=path, field="cloth.weave")
        density, stretch, bend = WEAVE_DEFAULTS[weave]
        values: dict[str, Any] = {"areal_density_kg_m2": density,
                                  "stretch_stiffness_n_m": stretch,
                                  "bend_stiffness_n_m": bend}
        for key in list(values):
            if key in table:
                values[key] = table.pop(key)
        values.update(overrides)
        try:
            return cls(extra=table, **values)
        except InputError as exc:
            raise InputError(exc.problem, path=path, field=f"cloth.{exc.field}") from None
