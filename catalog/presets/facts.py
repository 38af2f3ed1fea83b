"""What the catalog states about a fabric, read from its preset file (nothing estimated): the
one source of the desktop panel's facts and the web page's (catalog/web/facts.py exports
these values, the page shows them as given).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

from catalog.presets import Preset

#: What a fabric's colour comes from (the panel's filter groups, in its order).
KINDS = ("optical brightener", "fluorescent dye", "dye", "undyed")


@dataclass(frozen=True)
class FabricFacts:
    """Openness, colour, weight and weave of a preset; the brightener's or fluorescent dye's
    quantum yield and peak absorptance where the file gives them."""

    openness_pct: float              # LD, the open-area see-through fraction, in per cent
    kind: str                        # one of KINDS
    weight_g_m2: float | None        # [cloth] areal_density_kg_m2 x 1000, where the file has it
    weave: str | None                # [cloth] weave, where the file has it
    quantum_yield: float | None = None       # [fluorescence] quantum_yield
    peak_absorptance: float | None = None    # [fluorescence] peak_absorptance

    def lines(self) -> list[str]:
        """The one-line summary (the panel's list, the page's cards)."""
        parts = [f"open {self.openness_pct:.0f} %", self.kind]
        if self.weight_g_m2 is not None:
            parts.append(f"{self.weight_g_m2:.0f} g/m2")
        if self.weave:
            parts.append(self.weave)
        return [", ".join(parts)]

    def rows(self) -> list[tuple[str, str]]:
        """(label, value) rows: the panel's tooltip, the page's facts list."""
        colour = self.kind
        if self.quantum_yield is not None:
            colour += f", quantum yield {self.quantum_yield:.2f}"
        if self.peak_absorptance is not None:
            colour += f", peak absorptance {self.peak_absorptance:.2f}"
        rows = [("Openness", f"{self.openness_pct:.0f} % see-through"), ("Colour", colour)]
        if self.weight_g_m2 is not None:
            rows.append(("Weight", f"{self.weight_g_m2:.0f} g/m2"))
        if self.weave:
            rows.append(("Weave", self.weave))
        return rows

    def as_json(self) -> dict:
        """The values, the summary line and the rows, as the web page receives them."""
        return {**asdict(self), "line": self.lines()[0], "rows": [list(r) for r in self.rows()]}


def fabric_facts(preset: Preset) -> FabricFacts:
    """Openness (btdf.direct), brightener or dye ([fluorescence] with or without [dye] or
    [btdf.rgb]), weight and weave ([cloth]) of a preset."""
    has_dye = bool(preset.table("dye")) or isinstance(preset.table("btdf").get("rgb"), dict)
    if preset.has_fluorescence:
        kind = "fluorescent dye" if has_dye else "optical brightener"
    else:
        kind = "dye" if has_dye else "undyed"
    cloth = preset.table("cloth")
    density = cloth.get("areal_density_kg_m2")
    weight = float(density) * 1000.0 if isinstance(density, (int, float)) and density > 0 else None
    weave = cloth.get("weave") if isinstance(cloth.get("weave"), str) else None
    extra = preset.fluorescence.extra if preset.fluorescence is not None else {}

    def number(key: str) -> float | None:
        value = extra.get(key)
        return float(value) if isinstance(value, (int, float)) else None

    return FabricFacts(openness_pct=100.0 * float(preset.btdf.direct), kind=kind,
                       weight_g_m2=weight, weave=weave, quantum_yield=number("quantum_yield"),
                       peak_absorptance=number("peak_absorptance"))
