"""Lace as lace is made: a net ground, cord-outlined motifs of cloth-stitch and open fillings.

What the structure follows (Leavers and Raschel machine laces, embroidered tulle):

- the **ground** is a hexagonal net (tulle / bobbinet): threads along the edges of hexagonal
  holes about 0.8-1.5 mm across;
- a **motif** (flower, leaf, bud, spot) is worked in *cloth-stitch* (toile: threads laid
  side by side as in a fine plain weave, nearly opaque, the densest part of the lace), and
  parts of it in an *open filling* (a coarser honeycomb of larger holes, lighter than the
  cloth-stitch yet denser than the ground), so dense and open areas lie side by side;
- a raised **cord** (the gimp of a Leavers lace, the couched cord of a re-embroidered or
  Raschel lace) outlines every motif and runs along its veins and stems: the thickest thread,
  standing proud of the net (the height map's 1);
- motifs come at **several scales** (a large flower, smaller flowers and buds, leaves,
  scattered spots) on a **half-drop** repeat (the second column of motifs shifted half a repeat
  down), so the layout never reads as a square grid of identical spots;
- the **border** along the hem (:func:`scalloped_border`): the lace ends in scallops, arcs
  cut along a heavy cord (the gimp that a Leavers edging carries round each scallop) with
  picots (small corded loops) outside it, a band of cloth-stitch rays inside each scallop
  between the edge cord and an inner cord that follows it, and the all-over lace above.

Everything is a field on the repeat's pixel grid, periodic in both directions (the minimum
image of each displacement), so the repeat tiles without a seam. Lengths in metres.
"""

from __future__ import annotations

import math

import numpy as np

SQRT3 = math.sqrt(3.0)


def wrapped(d: np.ndarray, period: float) -> np.ndarray:
    """The minimum-image displacement of ``d`` on a circle of ``period``."""
    return d - period * np.round(d / period)


def hex_edge_distance(x, y, cell):
    """Distance to the nearest edge of the hexagonal (Voronoi) cells around a triangular
    lattice of hole centres ``cell`` apart (basis (cell, 0), (cell/2, cell sqrt3/2))."""
    t = y / (cell * SQRT3 / 2)
    s = x / cell - 0.5 * t
    s0, t0 = np.floor(s), np.floor(t)
    best = np.full(x.shape, np.inf)
    second = np.full(x.shape, np.inf)
    for ds in (-1, 0, 1, 2):
        for dt in (-1, 0, 1, 2):
            pt = t0 + dt
            px = (s0 + ds + 0.5 * pt) * cell
            py = pt * cell * SQRT3 / 2
            d = (x - px) ** 2 + (y - py) ** 2
            second = np.where(d < best, best, np.minimum(second, d))
            best = np.minimum(best, d)
    return (second - best) / (2 * cell)   # distance to the two nearest centres' bisector


def ellipse_sdf(dx, dy, a, b, angle):
    """Approximate signed distance (m, < 0 inside) to an ellipse of semi-axes a (along
    ``angle``) and b, centred at displacement 0."""
    c, s = math.cos(angle), math.sin(angle)
    u = c * dx + s * dy
    v = -s * dx + c * dy
    k = np.hypot(u / a, v / b)
    return (k - 1.0) * min(a, b)


def leaf_sdf(dx, dy, length, width, angle):
    """A pointed leaf (vesica: two circle arcs meeting at both tips), signed distance < 0
    inside, its axis along ``angle`` with the centre at displacement 0."""
    c, s = math.cos(angle), math.sin(angle)
    u = c * dx + s * dy
    v = np.abs(-s * dx + c * dy)
    half, w = 0.5 * length, 0.5 * width
    radius = (half * half + w * w) / (2 * w)          # the arc through both tips and the bulge
    return np.hypot(u, v + radius - w) - radius


class Lace:
    """Accumulates a lace's regions on one repeat: the cloth-stitch, the open filling, the
    cords (as distances to their centre lines) and the motif outline."""

    def __init__(self, size_u: int, size_v: int, repeat_u: float, repeat_v: float,
                 rows: int | None = None):
        """A repeat of size_u x size_v px; ``rows``: only its first rows (the hem's band, on
        the repeat's own pixel grid), the motifs still wrapping by the whole repeat."""
        self.ru, self.rv = repeat_u, repeat_v
        self.px = repeat_u / size_u
        xs = (np.arange(size_u) + 0.5) * (repeat_u / size_u)
        ys = (np.arange(size_v if rows is None else rows) + 0.5) * (repeat_v / size_v)
        self.x, self.y = np.meshgrid(xs, ys)
        self.solid = np.full(self.x.shape, np.inf)     # signed distance of the motifs' union
        self.opening = np.full(self.x.shape, np.inf)   # the open fillings inside motifs
        self.cord = np.full(self.x.shape, np.inf)      # distance to a cord's centre line

    def displacement(self, centre):
        return wrapped(self.x - centre[0], self.ru), wrapped(self.y - centre[1], self.rv)

    def _add(self, sdf, outline=True):
        self.solid = np.minimum(self.solid, sdf)
        if outline:
            self.cord = np.minimum(self.cord, np.abs(sdf))

    def flower(self, centre, radius, petals, rotation=0.0, open_petals=True):
        """Petals (ellipses) round an open-filled eye; each petal outlined by the cord and,
        when ``open_petals``, with an open filling along its middle (a vein of honeycomb)."""
        dx, dy = self.displacement(centre)
        for k in range(petals):
            angle = rotation + 2 * math.pi * k / petals
            cx, cy = 0.55 * radius * math.cos(angle), 0.55 * radius * math.sin(angle)
            a, b = 0.45 * radius, 0.45 * radius * math.sin(math.pi / petals) * 1.6
            petal = ellipse_sdf(dx - cx, dy - cy, a, b, angle)
            self._add(petal)
            if open_petals:
                inner = ellipse_sdf(dx - 1.15 * cx, dy - 1.15 * cy, 0.5 * a, 0.35 * b, angle)
                self.opening = np.minimum(self.opening, inner)
                self.cord = np.minimum(self.cord, np.abs(inner))
        eye = np.hypot(dx, dy) - 0.2 * radius
        self._add(eye)
        self.opening = np.minimum(self.opening, eye + 0.06 * radius)

    def leaf(self, centre, length, width, angle, vein=True):
        """A cloth-stitch leaf with a corded outline and a corded midrib."""
        dx, dy = self.displacement(centre)
        self._add(leaf_sdf(dx, dy, length, width, angle))
        if vein:
            c, s = math.cos(angle), math.sin(angle)
            u = c * dx + s * dy
            v = -s * dx + c * dy
            along = np.clip(u, -0.4 * length, 0.4 * length)
            self.cord = np.minimum(self.cord, np.hypot(u - along, v))

    def spot(self, centre, radius):
        """A small solid spot (point d'esprit, a bud), outlined."""
        dx, dy = self.displacement(centre)
        self._add(np.hypot(dx, dy) - radius)

    def stem(self, points, closed=False):
        """A cord along a polyline of points (m), each segment by the minimum image."""
        pts = list(points) + ([points[0]] if closed else [])
        for (x0, y0), (x1, y1) in zip(pts[:-1], pts[1:]):
            ex, ey = x1 - x0, y1 - y0
            length2 = ex * ex + ey * ey
            dx, dy = self.displacement((x0, y0))
            t = np.clip((dx * ex + dy * ey) / length2, 0.0, 1.0)
            self.cord = np.minimum(self.cord, np.hypot(dx - t * ex, dy - t * ey))

    def scroll(self, start, end, bulge, steps=24):
        """A stem from ``start`` to ``end`` curving ``bulge`` (m) to its left: a quadratic arc."""
        (x0, y0), (x1, y1) = start, end
        mx, my = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
        nx, ny = -(y1 - y0), x1 - x0
        norm = math.hypot(nx, ny)
        cx, cy = mx + 2 * bulge * nx / norm, my + 2 * bulge * ny / norm
        t = np.linspace(0.0, 1.0, steps + 1)
        xs = (1 - t) ** 2 * x0 + 2 * (1 - t) * t * cx + t ** 2 * x1
        ys = (1 - t) ** 2 * y0 + 2 * (1 - t) * t * cy + t ** 2 * y1
        self.stem(list(zip(xs, ys)))


def ramp(distance, half_width, px):
    """Coverage of a thread ``distance`` from its centre line: 1 within half_width, 0 beyond,
    linear over one pixel across the edge."""
    return np.clip(0.5 - (distance - half_width) / px, 0.0, 1.0)


def lace_fields(lace: Lace, cell: float, cord: float, filling_cell: float,
                cloth_density: float = 0.92):
    """Coverage and height functions of the net's thread half-width: returns
    (coverage(half), height(half)). The cloth-stitch is ``cloth_density`` covered with a fine
    woven texture (threads at cell / 4), the fillings a honeycomb of ``filling_cell`` holes."""
    px = lace.px
    x, y = lace.x, lace.y
    net_edge = hex_edge_distance(x, y, cell)
    fill_edge = hex_edge_distance(x + 0.37 * filling_cell, y, filling_cell)
    in_motif = ramp(lace.solid, 0.0, px)              # 1 inside a motif
    in_opening = ramp(lace.opening, 0.0, px) * in_motif
    pitch = cell / 4
    weave = 0.5 + 0.25 * (np.cos(2 * math.pi * x / pitch) + np.cos(2 * math.pi * y / pitch))
    cloth = cloth_density * (0.9 + 0.1 * weave)
    filling = ramp(fill_edge, 0.18 * filling_cell, px)
    cords = ramp(lace.cord, 0.5 * cord, px)
    cord_h = np.sqrt(np.clip(1.0 - (lace.cord / (0.5 * cord)) ** 2, 0.0, 1.0))

    def coverage(half):
        net = ramp(net_edge, half, px)
        body = (1 - in_opening) * cloth + in_opening * np.maximum(filling, net)
        c = (1 - in_motif) * net + in_motif * body
        return np.maximum(c, cords)

    def height(half):
        net = ramp(net_edge, half, px)
        net_h = 0.3 * np.sqrt(np.clip(1.0 - (net_edge / max(half, 1e-12)) ** 2, 0.0, 1.0)) * net
        body_h = (1 - in_opening) * (0.45 + 0.15 * weave) + in_opening * 0.35 * filling
        h = (1 - in_motif) * net_h + in_motif * body_h
        return np.clip(np.maximum(h, cord_h), 0.0, 1.0)

    return coverage, height


def scallop_distances(x, y, pitch: float, rise: float, bottom: float):
    """The hem's scallops: arcs of circles ``pitch`` wide (m) whose lowest points lie
    ``bottom`` above the hem line (y = 0, y up the cloth) and whose cusps lie ``rise`` higher.
    Returns (signed distance to the edge arc, > 0 on the lace side; the scallop's circle
    centre (cx, cy) per point; its radius)."""
    radius = ((0.5 * pitch) ** 2 + rise ** 2) / (2.0 * rise)
    cx = (np.floor(x / pitch) + 0.5) * pitch
    cy = bottom + radius
    return lower_arc(x - cx, y - cy, radius), (cx, cy), radius


def lower_arc(dx, dy, radius):
    """Signed distance to the lower half of a circle of ``radius`` about displacement 0,
    > 0 above the arc (inside the circle below its centre, anywhere above the centre)."""
    return np.where(dy < 0.0, radius - np.hypot(dx, dy), radius - np.abs(dx) + dy)


def scalloped_border(p: dict, lace_of_rows, half: float, cell: float, cord: float):
    """The band along the hem (rows from the hem up, on the all-over's pixel grid):
    ``lace_of_rows(rows)`` gives the all-over's Lace on the band's rows (its motifs, the
    same pixels as the repeat's first rows), ``half`` the net thread's half-width of the
    all-over. Returns (coverage, height) of the band, rows = p["border_rows"]; the top rows
    equal the all-over's, so the band joins it without a seam.

    p: ``scallops`` per repeat across, ``scallop_rise`` (the cusp's height over the arc's
    lowest point) and ``band`` (the ornament's width between the edge cord and the inner cord),
    both as fractions of the scallop's pitch."""
    rows = p["border_rows"]
    lace = lace_of_rows(rows)
    x, y = lace.x, lace.y
    px = lace.px
    pitch = lace.ru / p["scallops"]
    rise, band = p["scallop_rise"] * pitch, p["band"] * pitch
    bottom = 3.0 * cord
    edge, (cx, cy), radius = scallop_distances(x, y, pitch, rise, bottom)
    inner = lower_arc(x - cx, y - cy - band, radius)    # > 0 above the inner cord (the arc raised by band)
    if bottom + rise + band + 2 * cord >= rows * px:
        raise ValueError("the scallops and their band do not fit in the border's rows")
    # the ornament between the cords: cloth-stitch rays (leaves) fanning out from the
    # scallop's centre, outlined and veined by the cord, a spot between neighbours
    ornament = Lace(x.shape[1], round(lace.rv / px), lace.ru, lace.rv, rows=rows)
    rays = p.get("rays", 7)
    half_angle = math.asin(min(1.0, 0.5 * pitch / radius))
    mid_y = bottom + radius + 0.5 * band                 # the centre of the arc midway between the cords
    for k in range(p["scallops"]):
        centre_x = (k + 0.5) * pitch
        for j in range(rays):
            a = -half_angle + (j + 0.5) * 2 * half_angle / rays
            at = (centre_x + radius * math.sin(a), mid_y - radius * math.cos(a))
            ornament.leaf(at, 0.75 * band, 0.3 * band, 0.5 * math.pi + a)
            if j:
                b = a - half_angle / rays
                ornament.spot((centre_x + radius * math.sin(b), mid_y - radius * math.cos(b)),
                              0.07 * band)
    coverage_all, height_all = lace_fields(lace, cell, cord, 2 * cell)
    coverage_orn, height_orn = lace_fields(ornament, cell, cord, 2 * cell)
    above = ramp(-inner, 0.0, px)                       # 1 above the inner cord
    on_lace = ramp(-edge, 0.0, px)                      # 1 on the lace side of the edge
    picot_pitch = pitch / p.get("picots", 12)
    picot_r = 0.9 * cord
    # picots: small loops standing outside the edge cord, along the arc
    along = radius * np.arctan2(x - cx, cy - y)          # arc length from the scallop's bottom
    nearest = np.round(along / picot_pitch) * picot_pitch
    px_, py_ = cx + (radius + picot_r) * np.sin(nearest / radius), cy - (radius + picot_r) * np.cos(nearest / radius)
    picot = np.abs(np.hypot(x - px_, y - py_) - picot_r)
    heavy = 1.6 * cord                                   # the gimp round the scallop
    edge_cord = np.abs(edge)
    inner_cord = np.abs(inner)
    cords = np.maximum.reduce([ramp(edge_cord, 0.5 * heavy, px), ramp(inner_cord, 0.5 * cord, px),
                               ramp(picot, 0.25 * cord, px) * (edge < 0)])
    cord_h = np.maximum.reduce([
        np.sqrt(np.clip(1.0 - (edge_cord / (0.5 * heavy)) ** 2, 0.0, 1.0)),
        np.sqrt(np.clip(1.0 - (inner_cord / (0.5 * cord)) ** 2, 0.0, 1.0)),
        0.6 * np.sqrt(np.clip(1.0 - (picot / (0.25 * cord)) ** 2, 0.0, 1.0)) * (edge < 0)])
    body_c = above * coverage_all(half) + (1 - above) * coverage_orn(half)
    body_h = above * height_all(half) + (1 - above) * height_orn(half)
    coverage = np.maximum(on_lace * body_c, cords)
    height = np.clip(np.maximum(on_lace * body_h, cord_h), 0.0, 1.0)
    return coverage, height
