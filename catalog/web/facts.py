"""What the web page's cards and facts show of a fabric, from the desktop's sources: the
panel's facts (catalog.presets.facts), exported as JSON so that both state the same values in
the same words, and the card's picture with the close-up inset of the contact sheet and the
viewer's thumbnails (catalog.render.sheet)."""

from __future__ import annotations

from catalog.presets.facts import fabric_facts


def page_facts(preset) -> dict:
    """The preset's facts for data.js: values, the summary line, the rows."""
    return fabric_facts(preset).as_json()


def catalog_card(renderer, pixels):
    """``pixels`` (the renderer's frame, sRGB8) with the renderer's close-up of the same
    fabric and light in its lower right corner (catalog.render.sheet.put_inset)."""
    import numpy as np  # noqa: PLC0415

    from catalog.render.sheet import close_up, put_inset  # noqa: PLC0415

    card = np.array(pixels, dtype=np.uint8, copy=True)
    put_inset(card, close_up(renderer))
    return card
