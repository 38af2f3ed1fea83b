"""Build the built-in rooms (catalog/room/data/box.glb, living.glb, bedroom.glb) from primitives.

    python tools/make_rooms.py [--out catalog/room/data]

Both follow the room format (docs/formats.md, "Rooms"): metres, +Y up, Lambertian
materials (baseColorFactor x baseColorTexture), the aperture as the node ``window`` (one
quad, normal into the room), a ``camera`` node. ``box`` is today's room: the shell of
catalog/render/scene.py (ROOM_BOX with the WINDOW_RECT opening through a WALL_THICKNESS_M
wall, ROOM_ALBEDO grey); its window quad lies in the wall's room-side plane z = WINDOW_Z,
where the curtain is placed today. ``living`` keeps that window (so the curtain hangs as
in the box) in a furnished room: a textured wood floor, painted walls, a window frame in a
wider opening and a sill, a sofa, a low table, a rug and a shelf. ``bedroom`` is another room: smaller and lower, its window
wider, lower and off-centre in the same wall plane, a pale plank floor, a bed, a desk
with a chair, a bedside table, a striped rug and wall shelves. The output is deterministic
(the textures from seeded generators).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from catalog.render import scene as scene_lib  # noqa: E402
from catalog.room.glb import with_camera  # noqa: E402

#: The default view (catalog.render.camera.OrbitCamera's defaults).
CAMERA_TARGET = (0.0, 0.15, -0.08)
CAMERA_POSITION = (0.0, 0.15, -0.08 + 2.6)
CAMERA_FOV_Y_DEG = 50.0


def box_part(x0, x1, y0, y1, z0, z1, uv_per_m: float | None = None):
    """A closed axis-aligned box as a trimesh (flat faces, non-indexed); with ``uv_per_m``
    each face gets planar uvs (its two in-plane world axes times uv_per_m)."""
    import trimesh  # noqa: PLC0415

    tris = scene_lib.box_triangles(x0, x1, y0, y1, z0, z1)
    mesh = trimesh.Trimesh(vertices=tris.reshape(-1, 3), faces=np.arange(tris.shape[0] * 3).reshape(-1, 3),
                           process=False)
    if uv_per_m is not None:
        normal = np.abs(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]))
        axis = np.argmax(normal, axis=1)
        keep = np.array([[1, 2], [0, 2], [0, 1]])[axis]          # drop the normal's axis
        uv = np.take_along_axis(tris, np.repeat(keep[:, None, :], 3, axis=1), axis=2)
        mesh.visual = trimesh.visual.TextureVisuals(uv=uv.reshape(-1, 2) * uv_per_m)
    return mesh


def material(rgb, texture=None):
    import trimesh  # noqa: PLC0415

    return trimesh.visual.material.PBRMaterial(
        baseColorFactor=[float(c) for c in rgb] + [1.0], baseColorTexture=texture,
        metallicFactor=0.0, roughnessFactor=1.0)


def painted(mesh, rgb):
    import trimesh  # noqa: PLC0415

    uv = getattr(mesh.visual, "uv", None)
    mesh.visual = trimesh.visual.TextureVisuals(uv=uv, material=material(rgb))
    return mesh


def wood_texture(size: int = 512, planks: int = 8, seed: int = 7):
    """An sRGB wood-plank image (PIL): ``planks`` boards across, staggered joints, grain."""
    from PIL import Image  # noqa: PLC0415

    rng = np.random.default_rng(seed)
    v, u = np.mgrid[0:size, 0:size] / size
    board = np.floor(u * planks).astype(int)
    shift = rng.random(planks)[board]
    along = (v + shift) % 1.0
    tone = 0.85 + 0.3 * rng.random((planks, 4))[board, np.floor(along * 4).astype(int) % 4]
    grain = 1.0 + 0.08 * np.sin(2 * np.pi * (u * planks * 9 + 3 * np.sin(2 * np.pi * along * 2)))
    joint = np.minimum(np.abs(u * planks - np.round(u * planks)), np.abs(along * 4 - np.round(along * 4)) / 8)
    dark = np.where(joint < 0.012, 0.45, 1.0)
    base = np.array([0.55, 0.36, 0.20])          # linear reflectance of a mid oak
    linear = np.clip(base[None, None, :] * (tone * grain * dark)[..., None], 0.0, 1.0)
    srgb = np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * linear ** (1 / 2.4) - 0.055)
    return Image.fromarray(np.round(srgb * 255).astype(np.uint8), "RGB")


def window_quad(z: float, rect=scene_lib.WINDOW_RECT):
    """The aperture: the ``rect`` (x0, x1, y0, y1) quad at z, wound so its normal is +z
    (into the room)."""
    import trimesh  # noqa: PLC0415

    x0, x1, y0, y1 = rect
    v = np.array([[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]])
    return trimesh.Trimesh(vertices=v, faces=[[0, 1, 2], [0, 2, 3]], process=False)


def shell_parts(hole, wall_rgb, floor, ceiling_rgb, box=scene_lib.ROOM_BOX):
    """Floor, ceiling, four walls and the window wall around ``hole`` (x0, x1, y0, y1) of
    the room ``box`` ((x0, x1), (y0, y1), (z0, z1), its inside; the window wall at z0)."""
    (x0, x1), (y0, y1), (z0, z1) = box
    wx0, wx1, wy0, wy1 = hole
    t = scene_lib.WALL_THICKNESS_M
    floor_mesh, floor_material = floor
    return {
        "floor": floor_mesh(x0 - t, x1 + t, y0 - t, y0, z0 - t, z1 + t),
        "ceiling": painted(box_part(x0 - t, x1 + t, y1, y1 + t, z0 - t, z1 + t), ceiling_rgb),
        "wall_left": painted(box_part(x0 - t, x0, y0, y1, z0 - t, z1 + t), wall_rgb),
        "wall_right": painted(box_part(x1, x1 + t, y0, y1, z0 - t, z1 + t), wall_rgb),
        "wall_back": painted(box_part(x0, x1, y0, y1, z1, z1 + t), wall_rgb),
        "window_wall_left": painted(box_part(x0, wx0, y0, y1, z0 - t, z0), wall_rgb),
        "window_wall_right": painted(box_part(wx1, x1, y0, y1, z0 - t, z0), wall_rgb),
        "window_wall_below": painted(box_part(wx0, wx1, y0, wy0, z0 - t, z0), wall_rgb),
        "window_wall_above": painted(box_part(wx0, wx1, wy1, y1, z0 - t, z0), wall_rgb),
    }, floor_material


def scene_bytes(parts: dict, window, camera=(CAMERA_POSITION, CAMERA_TARGET)) -> bytes:
    import trimesh  # noqa: PLC0415

    scene = trimesh.Scene()
    for name, mesh in parts.items():
        scene.add_geometry(mesh, node_name=name, geom_name=name)
    scene.add_geometry(window, node_name="window", geom_name="window")
    data = scene.export(file_type="glb")
    return with_camera(data, camera[0], camera[1], CAMERA_FOV_Y_DEG)


def build_box() -> bytes:
    grey = [scene_lib.ROOM_ALBEDO] * 3

    def floor(*extent):
        return painted(box_part(*extent), grey)

    parts, _ = shell_parts(scene_lib.WINDOW_RECT, grey, (floor, None), grey)
    return scene_bytes(parts, window_quad(scene_lib.WINDOW_Z))


#: living: colours (linear reflectance) and furniture, metres.
WALL_PAINT = (0.72, 0.68, 0.60)
CEILING_PAINT = (0.80, 0.80, 0.78)
FRAME_PAINT = (0.78, 0.78, 0.76)
FRAME_WIDTH_M = 0.06
PLANK_REPEAT_M = 1.2


def build_living() -> bytes:
    import trimesh  # noqa: PLC0415

    texture = wood_texture()

    def floor(*extent):
        mesh = box_part(*extent, uv_per_m=1.0 / PLANK_REPEAT_M)
        mesh.visual = trimesh.visual.TextureVisuals(uv=mesh.visual.uv, material=material((1, 1, 1), texture))
        return mesh

    wx0, wx1, wy0, wy1 = scene_lib.WINDOW_RECT
    f = FRAME_WIDTH_M
    (x0, x1), (y0, y1), (z0, z1) = scene_lib.ROOM_BOX
    t = scene_lib.WALL_THICKNESS_M
    parts, _ = shell_parts((wx0 - f, wx1 + f, wy0 - f, wy1 + f), WALL_PAINT, (floor, None), CEILING_PAINT)
    # the frame fills the opening's margin around the aperture, through the wall's depth
    parts["window_frame_left"] = painted(box_part(wx0 - f, wx0, wy0 - f, wy1 + f, z0 - t, z0), FRAME_PAINT)
    parts["window_frame_right"] = painted(box_part(wx1, wx1 + f, wy0 - f, wy1 + f, z0 - t, z0), FRAME_PAINT)
    parts["window_frame_bottom"] = painted(box_part(wx0, wx1, wy0 - f, wy0, z0 - t, z0), FRAME_PAINT)
    parts["window_frame_top"] = painted(box_part(wx0, wx1, wy1, wy1 + f, z0 - t, z0), FRAME_PAINT)
    parts["window_sill"] = painted(box_part(wx0 - 0.15, wx1 + 0.15, wy0 - f - 0.04, wy0 - f, z0, z0 + 0.03),
                                   FRAME_PAINT)
    floor_y = y0
    # a sofa against the right wall, facing the room (-x)
    sofa = (0.30, 0.33, 0.40)
    sx1 = x1
    parts["sofa_seat"] = painted(box_part(sx1 - 0.9, sx1 - 0.15, floor_y, floor_y + 0.42, 1.2, 3.2), sofa)
    parts["sofa_back"] = painted(box_part(sx1 - 0.15, sx1, floor_y, floor_y + 0.85, 1.2, 3.2), sofa)
    parts["sofa_arm_near"] = painted(box_part(sx1 - 0.9, sx1 - 0.15, floor_y, floor_y + 0.6, 1.0, 1.2), sofa)
    parts["sofa_arm_far"] = painted(box_part(sx1 - 0.9, sx1 - 0.15, floor_y, floor_y + 0.6, 3.2, 3.4), sofa)
    # a rug in front of the sofa and a low table on it
    parts["rug"] = painted(box_part(-0.4, 1.2, floor_y, floor_y + 0.01, 1.3, 3.1), (0.55, 0.18, 0.14))
    table = (0.42, 0.27, 0.16)
    top = floor_y + 0.40
    parts["table_top"] = painted(box_part(0.0, 1.0, top - 0.04, top, 1.7, 2.7), table)
    for i, (lx, lz) in enumerate(((0.05, 1.75), (0.9, 1.75), (0.05, 2.6), (0.9, 2.6))):
        leg = trimesh.creation.cylinder(radius=0.025, height=top - 0.04 - floor_y - 0.01, sections=12)
        leg.apply_translation((lx + 0.025, floor_y + 0.01 + (top - 0.04 - floor_y - 0.01) / 2, lz + 0.025))
        # trimesh's cylinder runs along z: turn it upright about its own centre
        centre = leg.bounds.mean(axis=0)
        leg.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, (1, 0, 0), centre))
        parts[f"table_leg_{i}"] = painted(leg, table)
    # a shelf against the left wall: two sides, four boards, a back
    shelf = (0.62, 0.58, 0.50)
    sx0, depth, sz0, sz1, height = x0, 0.32, 0.9, 1.9, 1.8
    parts["shelf_side_near"] = painted(box_part(sx0, sx0 + depth, floor_y, floor_y + height, sz0, sz0 + 0.02), shelf)
    parts["shelf_side_far"] = painted(box_part(sx0, sx0 + depth, floor_y, floor_y + height, sz1 - 0.02, sz1), shelf)
    parts["shelf_back"] = painted(box_part(sx0, sx0 + 0.01, floor_y, floor_y + height, sz0 + 0.02, sz1 - 0.02), shelf)
    for i, level in enumerate(np.linspace(0.02, height - 0.02, 4)):
        parts[f"shelf_board_{i}"] = painted(box_part(sx0 + 0.01, sx0 + depth, floor_y + level - 0.02,
                                                     floor_y + level, sz0 + 0.02, sz1 - 0.02), shelf)
    return scene_bytes(parts, window_quad(scene_lib.WINDOW_Z))


#: bedroom: its inside (m), the window wall at z = WINDOW_Z as in the others.
BEDROOM_BOX = ((-1.8, 2.3), (-1.3, 1.25), (scene_lib.WINDOW_Z, 3.6))
#: Its window: wider, lower and left of the wall's centre (x0, x1, y0, y1).
BEDROOM_WINDOW = (-1.25, 0.85, -0.45, 1.0)
BEDROOM_WALL = (0.55, 0.62, 0.66)
BEDROOM_CAMERA = ((-0.2, 0.3, 2.9), (-0.2, 0.25, -0.2))


def stripe_texture(size: int = 256, stripes: int = 9, seed: int = 3):
    """An sRGB woven-stripe rug image (PIL): bands of three colours with a fine weave."""
    from PIL import Image  # noqa: PLC0415

    rng = np.random.default_rng(seed)
    v, u = np.mgrid[0:size, 0:size] / size
    palette = np.array([[0.60, 0.52, 0.38], [0.20, 0.28, 0.42], [0.70, 0.66, 0.58]])
    band = palette[np.floor(u * stripes).astype(int) % 3]
    weave = 1.0 + 0.06 * np.sign(np.sin(2 * np.pi * u * 64) * np.sin(2 * np.pi * v * 64))
    noise = 1.0 + 0.05 * rng.standard_normal((size, size))
    linear = np.clip(band * (weave * noise)[..., None], 0.0, 1.0)
    srgb = np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * linear ** (1 / 2.4) - 0.055)
    return Image.fromarray(np.round(srgb * 255).astype(np.uint8), "RGB")


def textured(mesh, texture):
    import trimesh  # noqa: PLC0415

    mesh.visual = trimesh.visual.TextureVisuals(uv=mesh.visual.uv, material=material((1, 1, 1), texture))
    return mesh


def build_bedroom() -> bytes:
    """A bedroom (see the module doc): the window off-centre, a bed against the right wall,
    a desk and chair under the window's right side, a bedside table, a rug, two wall shelves."""
    import trimesh  # noqa: PLC0415

    planks = wood_texture(size=512, planks=6, seed=11)
    (x0, x1), (y0, y1), (z0, z1) = BEDROOM_BOX
    wx0, wx1, wy0, wy1 = BEDROOM_WINDOW
    f, t = FRAME_WIDTH_M, scene_lib.WALL_THICKNESS_M

    def floor(*extent):
        return textured(box_part(*extent, uv_per_m=1.0 / 1.5), planks)

    parts, _ = shell_parts((wx0 - f, wx1 + f, wy0 - f, wy1 + f), BEDROOM_WALL, (floor, None),
                           CEILING_PAINT, box=BEDROOM_BOX)
    parts["window_frame_left"] = painted(box_part(wx0 - f, wx0, wy0 - f, wy1 + f, z0 - t, z0), FRAME_PAINT)
    parts["window_frame_right"] = painted(box_part(wx1, wx1 + f, wy0 - f, wy1 + f, z0 - t, z0), FRAME_PAINT)
    parts["window_frame_bottom"] = painted(box_part(wx0, wx1, wy0 - f, wy0, z0 - t, z0), FRAME_PAINT)
    parts["window_frame_top"] = painted(box_part(wx0, wx1, wy1, wy1 + f, z0 - t, z0), FRAME_PAINT)
    parts["window_sill"] = painted(box_part(wx0 - 0.1, wx1 + 0.1, wy0 - f - 0.03, wy0 - f, z0, z0 + 0.05),
                                   FRAME_PAINT)
    fy = y0
    # the bed, its head against the right wall: a frame, a mattress, a headboard, a cover
    bed_wood, linen = (0.36, 0.24, 0.15), (0.78, 0.76, 0.72)
    bz0, bz1 = 1.5, 3.1
    parts["bed_frame"] = painted(box_part(x1 - 2.05, x1, fy, fy + 0.30, bz0, bz1), bed_wood)
    parts["bed_mattress"] = painted(box_part(x1 - 2.0, x1 - 0.05, fy + 0.30, fy + 0.52, bz0 + 0.05, bz1 - 0.05),
                                    linen)
    parts["bed_cover"] = painted(box_part(x1 - 1.45, x1 - 0.05, fy + 0.52, fy + 0.55, bz0 + 0.02, bz1 - 0.02),
                                 (0.45, 0.20, 0.22))
    parts["bed_headboard"] = painted(box_part(x1 - 0.06, x1, fy + 0.30, fy + 1.05, bz0, bz1), bed_wood)
    parts["bedside_table"] = painted(box_part(x1 - 0.45, x1, fy, fy + 0.50, bz1 + 0.05, bz1 + 0.45), bed_wood)
    # a desk under the window's right side, its back 0.05 m from the window wall
    desk = (0.66, 0.55, 0.40)
    dx0, dx1, dz0, dz1, top = 0.35, 1.55, z0 + 0.05, z0 + 0.65, fy + 0.74
    parts["desk_top"] = painted(box_part(dx0, dx1, top - 0.03, top, dz0, dz1), desk)
    for i, (lx, lz) in enumerate(((dx0, dz0), (dx1 - 0.04, dz0), (dx0, dz1 - 0.04), (dx1 - 0.04, dz1 - 0.04))):
        parts[f"desk_leg_{i}"] = painted(box_part(lx, lx + 0.04, fy, top - 0.03, lz, lz + 0.04), desk)
    # a chair pulled back from the desk: a seat on a cylinder, a back
    chair = (0.25, 0.25, 0.27)
    cx, cz = 0.95, z0 + 0.95
    parts["chair_seat"] = painted(box_part(cx - 0.22, cx + 0.22, fy + 0.44, fy + 0.48, cz - 0.22, cz + 0.22), chair)
    parts["chair_back"] = painted(box_part(cx - 0.22, cx + 0.22, fy + 0.48, fy + 0.90, cz + 0.18, cz + 0.22), chair)
    post = trimesh.creation.cylinder(radius=0.03, height=0.44, sections=12)
    post.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, (1, 0, 0)))
    post.apply_translation((cx, fy + 0.22, cz))
    parts["chair_post"] = painted(post, chair)
    # a striped rug beside the bed
    rug = box_part(-0.9, 0.2, fy, fy + 0.012, 1.4, 3.0, uv_per_m=1.0 / 1.1)
    parts["rug"] = textured(rug, stripe_texture())
    # two shelves on the left wall, over a low chest
    shelf = (0.70, 0.68, 0.62)
    for i, level in enumerate((1.05, 1.45)):
        parts[f"wall_shelf_{i}"] = painted(box_part(x0, x0 + 0.25, fy + level, fy + level + 0.025, 1.0, 2.2), shelf)
    parts["chest"] = painted(box_part(x0, x0 + 0.45, fy, fy + 0.70, 1.1, 2.1), (0.52, 0.44, 0.34))
    return scene_bytes(parts, window_quad(scene_lib.WINDOW_Z, BEDROOM_WINDOW), camera=BEDROOM_CAMERA)


BUILDERS = {"box": build_box, "living": build_living, "bedroom": build_bedroom}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(Path(__file__).resolve().parents[1] / "catalog" / "room" / "data"))
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for name, build in BUILDERS.items():
        data = build()
        (out / f"{name}.glb").write_bytes(data)
        print(f"{out / (name + '.glb')}: {len(data)} bytes")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
