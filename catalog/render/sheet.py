"""Contact sheets: every fabric under every light, one PNG per pair and a labelled grid.

Rows are fabrics, columns lights. Everything is checked (fabrics, lights, size, the output
folder and its free room) before the first render; the images and the grid are staged in a
temporary folder beside ``out_dir`` and moved in only when all are written, so an
interrupted or failed sheet leaves ``out_dir`` as it was.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from catalog.core.errors import CatalogError, InputError


def _fabric_list(fabrics):
    from catalog.presets import find_preset, list_presets, load_preset  # noqa: PLC0415

    paths = list_presets() if fabrics is None else [find_preset(f) for f in fabrics]
    if not paths:
        raise InputError("no fabric presets found (fabrics/*.toml); run `catalog fit` first",
                         field="--fabric")
    return [load_preset(p) for p in paths]


#: The grid's inset swatch: the close-up view (catalog.render.views "close") of the same
#: fabric and light, this fraction of the cell's side, in the cell's lower right corner, so
#: that the weave or the lace's motif reads at catalog size (the whole curtain alone shows
#: the white fabrics nearly alike). Cells smaller than INSET_MIN_CELL_PX get none.
INSET_FRACTION = 0.45
INSET_MIN_CELL_PX = 64

#: Label strips of the grid (px): the fabric names' column and the lights' header row.
LABEL_COLUMN_PX = 200
LABEL_ROW_PX = 22
LABEL_FONT_PX = 13


def labelled_grid(grid: np.ndarray, rows: list[str], columns: list[str], cell: tuple[int, int]) -> np.ndarray:
    """``grid`` with a header row naming each column and a left column naming each row
    (OpenImageIO's text renderer and its built-in font)."""
    import OpenImageIO as oiio  # noqa: PLC0415

    width, height = cell
    out = np.full((grid.shape[0] + LABEL_ROW_PX, grid.shape[1] + LABEL_COLUMN_PX, 3), 24, np.uint8)
    out[LABEL_ROW_PX:, LABEL_COLUMN_PX:] = grid
    buf = oiio.ImageBuf(oiio.ImageSpec(out.shape[1], out.shape[0], 3, oiio.UINT8))
    buf.set_pixels(oiio.ROI(), out)
    baseline = (LABEL_ROW_PX + LABEL_FONT_PX) // 2 - 1
    for j, name in enumerate(columns):
        oiio.ImageBufAlgo.render_text(buf, LABEL_COLUMN_PX + j * width + 4, baseline, name,
                                      LABEL_FONT_PX, "", (0.92, 0.92, 0.92))
    for i, name in enumerate(rows):
        y = LABEL_ROW_PX + i * height + height // 2 + LABEL_FONT_PX // 2
        for k, line in enumerate(_wrap(name, LABEL_COLUMN_PX - 8, LABEL_FONT_PX)):
            oiio.ImageBufAlgo.render_text(buf, 4, int(y + (k - 1) * (LABEL_FONT_PX + 2)), line,
                                          LABEL_FONT_PX, "", (0.92, 0.92, 0.92))
    return buf.get_pixels(oiio.UINT8).reshape(out.shape)


def _wrap(text: str, width_px: int, font_px: int) -> list[str]:
    """At most three lines of about width_px (average glyph ~0.55 font sizes)."""
    per_line = max(4, int(width_px / (0.55 * font_px)))
    words, lines, line = text.split(), [], ""
    for word in words:
        if line and len(line) + 1 + len(word) > per_line:
            lines.append(line)
            line = word
        else:
            line = f"{line} {word}".strip()
    lines.append(line)
    return lines if len(lines) <= 3 else [*lines[:2], " ".join(lines[2:])[:per_line]]


def close_up(renderer) -> np.ndarray:
    """The renderer's fabric and light seen from the close-up view (sRGB8), the camera put
    back as it was."""
    from catalog.render.settings import orbit  # noqa: PLC0415

    camera = renderer.camera
    placement = renderer.placement        # the close-up of the room's own curtain
    view = placement.view("close")
    renderer.update(camera=orbit(view.yaw_deg, view.pitch_deg, view.distance_m, target=view.target,
                                 fov_y_deg=view.fov_y_deg, inside=True, placement=placement))
    try:
        renderer.render()
        return renderer.read_srgb8()
    finally:
        renderer.update(camera=camera)


def put_inset(cell: np.ndarray, swatch: np.ndarray, fraction: float = INSET_FRACTION) -> None:
    """``swatch`` (the cell's size) reduced by area averaging to ``fraction`` of the cell and
    framed by a 1 px dark line, into the cell's lower right corner (in place)."""
    h, w = cell.shape[:2]
    k = max(1, int(round(1.0 / fraction)))
    sh, sw = h // k, w // k
    small = swatch[:sh * k, :sw * k].reshape(sh, k, sw, k, 3).astype(np.float64)
    # average in linear light (sRGB decode, mean, encode) so the reduction keeps the brightness
    lin = np.where(small / 255.0 <= 0.04045, small / 255.0 / 12.92,
                   ((small / 255.0 + 0.055) / 1.055) ** 2.4).mean(axis=(1, 3))
    enc = np.where(lin <= 0.0031308, 12.92 * lin, 1.055 * lin ** (1 / 2.4) - 0.055)
    y0, x0 = h - sh - 2, w - sw - 2
    cell[y0 - 1:y0 + sh + 1, x0 - 1:x0 + sw + 1] = 16
    cell[y0:y0 + sh, x0:x0 + sw] = np.round(np.clip(enc, 0, 1) * 255).astype(np.uint8)


def render_sheet(lights: list[str], out_dir: Path, size: tuple[int, int], *, fabrics=None,
                 fluorescence: str = "physical", bands: int = 3, progress: bool = True,
                 ctx=None, ev: float | None = None, white_balance: str = "room",
                 labels: bool = True, room: str | None = "living") -> dict:
    """``room``: a built-in name or a .glb, lit by its transport (None: the box)."""
    from catalog.optics.lights import get_light  # noqa: PLC0415
    from catalog.render import bands as band_lib  # noqa: PLC0415
    from catalog.render import scene as scene_lib  # noqa: PLC0415
    from catalog.core.atomic import staged_folder  # noqa: PLC0415

    if not lights:
        raise InputError("give at least one light", field="--lights")
    light_objects = [get_light(name) for name in lights]
    presets = _fabric_list(fabrics)
    for preset in presets:
        scene_lib.dye_transmittance(preset)
        scene_lib.fluorescent_material(preset)
    band_lib.check_band_count(bands)
    from catalog.render.snapshot import check_display_choices  # noqa: PLC0415

    check_display_choices(ev, white_balance)
    if room is not None:
        from catalog.room.load import room_path  # noqa: PLC0415

        room_path(room)
    if out_dir.exists() and not out_dir.is_dir():
        raise InputError(f"{str(out_dir)!r} exists and is not a folder", field="--out")
    width, height = size
    # an upper bound of what is written: every image and the grid, uncompressed
    estimate_bytes = 2 * len(presets) * len(light_objects) * width * height * 3
    from catalog.gl.context import headless_context  # noqa: PLC0415

    # without ctx, a context of its own, released after (the caller's current one current again)
    with staged_folder(out_dir, estimate_bytes=estimate_bytes) as stage, \
            headless_context(ctx) as ctx:
        report = _render_into(stage, out_dir, presets, light_objects, size, fluorescence,
                              bands, progress, ctx, ev, white_balance, labels, room)
    return report


def _render_into(stage: Path, out_dir: Path, presets, light_objects, size, fluorescence,
                 bands, progress, ctx, ev, white_balance, labels, room=None) -> dict:
    from catalog.render.imagefile import write_image  # noqa: PLC0415

    from catalog.render.snapshot import new_renderer  # noqa: PLC0415

    renderer = new_renderer(ctx, size)  # the size checked against the context first
    renderer.update(fluorescence=fluorescence, bands=bands, ev=ev, white_balance=white_balance,
                    room=room)
    from catalog.render.settings import orbit  # noqa: PLC0415

    placement = renderer.placement   # the room's curtain, its rod and the camera on it
    base = renderer.camera           # the cells' camera: straight at the room's own curtain
    renderer.update(camera=orbit(base.yaw_deg, base.pitch_deg, base.distance_m,
                                 fov_y_deg=base.fov_y_deg, placement=placement))
    width, height = size
    grid = np.zeros((height * len(presets), width * len(light_objects), 3), dtype=np.uint8)
    images = []
    pairs = [(i, preset, j, light) for i, preset in enumerate(presets)
             for j, light in enumerate(light_objects)]

    def work(advance):
        from catalog.render.snapshot import ring_xs_m, simulated_curtain  # noqa: PLC0415

        shown = None
        for i, preset, j, light in pairs:
            if shown is not preset:   # the drape catalog snapshot shows (its fullness, rings)
                *mesh, fabric_size = simulated_curtain(preset, 0, placement)
                renderer.set_mesh(*mesh, fabric_size_m=fabric_size)
                renderer.set_rings(ring_xs_m(preset, placement))
                shown = preset
            renderer.update(fabric=preset, light=light)
            renderer.render()
            pixels = renderer.read_srgb8()
            safe_light = "".join(c if c.isalnum() or c in "-._" else "_" for c in light.name)
            name = f"{preset.name}__{safe_light}.png"
            path = out_dir / name
            info = renderer.info()
            write_image(stage / name, pixels, {"catalog:fabric": preset.name, "catalog:light": light.name,
                                       "catalog:mode": info["mode"],
                                       "catalog:fluorescence_variant": info["fluorescence_variant"],
                                       "catalog:ev100": f"{info['ev100']:.4f}",
                                       "catalog:white_balance": info["white_balance"]})
            cell = pixels.copy()
            if min(width, height) >= INSET_MIN_CELL_PX:
                put_inset(cell, close_up(renderer))
            grid[i * height:(i + 1) * height, j * width:(j + 1) * width] = cell
            images.append({"fabric": preset.name, "light": light.name, "path": str(path),
                           "fluorescence_variant": info["fluorescence_variant"],
                           "ev100": info["ev100"]})
            advance()

    from catalog.core.progress import progress as progress_bar  # noqa: PLC0415

    try:
        with progress_bar("catalog sheet", total=len(pairs), unit="images",
                          enabled=progress) as bar:
            work(bar.advance)
    finally:
        renderer.release()
    grid_path = out_dir / "grid.png"
    if labels:
        grid = labelled_grid(grid, [f"{p.display_name} ({p.name})" for p in presets],
                             [l.name for l in light_objects], (width, height))
    write_image(stage / grid_path.name, grid, {
        "ImageDescription": "rows: " + ", ".join(p.name for p in presets)
                            + "; columns: " + ", ".join(l.name for l in light_objects),
        "catalog:fabrics": ",".join(p.name for p in presets),
        "catalog:lights": ",".join(l.name for l in light_objects)})
    if not images:
        raise CatalogError("nothing rendered")
    return {"images": images, "grid": str(grid_path), "rows": [p.name for p in presets],
            "columns": [l.name for l in light_objects], "size": list(size), "labels": labels,
            "label_offset_px": [LABEL_COLUMN_PX, LABEL_ROW_PX] if labels else [0, 0]}
