"""What the viewer shows: fabric, light, fluorescence mode, bands, wind, curtain, pause.

Plain data and the small rules the keys and the panel share (the order the L key walks
the lights in, the F key's cycle of modes). No GL, no window: tested directly.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from catalog.viewer.catalog_state import FabricFilter

from catalog.core.constants import FLUORESCENCE_MODES

#: Band counts the renderer compiles (3 = RGB).
BAND_COUNTS = (3, 6, 9, 16)
#: The lights the L key steps through: the sun (hour slider), CIE daylight and tungsten,
#: two fluorescent tubes, the LEDs (a violet-pumped white and a 405 nm violet one among
#: them) and the UV lamps. The panel offers every CIE table too.
SUN = "sun"
LIGHT_CYCLE = (SUN, "D65", "A", "FL2", "FL11", "LED-B4", "LED-warm", "LED-violet-white",
               "LED-405", "UV-385", "UV-A")
#: The LED lights of the panel's LED group.
LED_LIGHTS = ("LED-B4", "LED-warm", "LED-violet-white", "LED-405")
UVA_LIGHT = "UV-A"
#: The UV lamps of the panel's UV group (365 nm blacklight first).
UV_LIGHTS = (UVA_LIGHT, "UV-385")

#: Hour-of-day slider range (local solar time, h) and its default: noon, the paper's scene.
SUN_HOUR_RANGE = (6.0, 18.0)
DEFAULT_SUN_HOUR = 12.0
#: White balance choices (catalog/render/display.py) and the exposure slider's range (EV100).
WHITE_BALANCES = ("room", "camera")
EV_SLIDER_RANGE = (-2.0, 18.0)

#: Wind slider range (m/s at the open window).
WIND_RANGE_M_S = (0.0, 8.0)
#: A light breeze through the open window: it sways a sheer, it does not throw it (at 1.5 m/s
#: the drag on a 0.05 kg/m2 voile, 1/2 rho C_d v^2 = 1.6 N/m2, is three times its weight and
#: lifts it into the room; docs/pattern.md, "The breeze", has the hem's displacement).
#: Stronger wind: the slider.
DEFAULT_WIND_M_S = 0.5


def next_fluorescence(mode: str) -> str:
    """The mode after ``mode`` in off -> paper -> physical -> off."""
    if mode not in FLUORESCENCE_MODES:
        return FLUORESCENCE_MODES[0]
    return FLUORESCENCE_MODES[(FLUORESCENCE_MODES.index(mode) + 1) % len(FLUORESCENCE_MODES)]


def next_light(light: str) -> str:
    """The light after ``light`` in :data:`LIGHT_CYCLE` (any other light goes to the first)."""
    if light not in LIGHT_CYCLE:
        return LIGHT_CYCLE[0]
    return LIGHT_CYCLE[(LIGHT_CYCLE.index(light) + 1) % len(LIGHT_CYCLE)]


@dataclass
class ViewerSettings:
    """The viewer's state as the user set it (the panel and the keys both write here)."""

    fabric_index: int = 0
    compare_index: int | None = None  # split screen: the right half's fabric
    light: str = SUN  # SUN (path from ``sun_hour``) or a light name of catalog.optics.lights
    sun_hour: float = DEFAULT_SUN_HOUR
    fluorescence: str = "physical"
    bands: int = 3
    wind_m_s: float = DEFAULT_WIND_M_S
    curtain_open: bool = False
    paused: bool = False
    show_help: bool = False
    show_panel: bool = True
    ev100: float | None = None  # fixed exposure (EV100); None: automatic, adapting over time
    white_balance: str = "room"
    compare_fluorescence: str | None = None  # the right half's mode (None: the left's)
    show_timing: bool = False  # the developer frame-time graphs
    fabric_filter: FabricFilter = field(default_factory=FabricFilter)

    @property
    def right_fluorescence(self) -> str:
        return self.compare_fluorescence or self.fluorescence

    @property
    def light_label(self) -> str:
        return f"sun at {self.sun_hour:04.1f} h" if self.light == SUN else self.light
