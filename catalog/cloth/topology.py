"""Which particles are joined by springs: Provot's structural, shear and bend springs.

Particles sit on a ``grid_h`` x ``grid_w`` grid, row 0 on the rod, index = row * W + col.
A spring joins a = (r, c) to b = (r + di, c + dj). Six families:

======== ======== ==============================
family   (di, dj) what it resists
======== ======== ==============================
horizontal (0, 1) stretch across (weft)
vertical   (1, 0) stretch down (warp)
diagonal   (1, 1) shear
antidiagonal (1, -1) shear
bend_h     (0, 2) bending across
bend_v     (2, 0) bending down
======== ======== ==============================

So each inner particle has 12 springs: the layout of the benchmark (:data:`GATHER_OFFSETS`).

The constraint solver visits the springs in *colours*: sets in which no two springs share
a particle, so a colour can be solved in parallel (numba threads, one GPU dispatch) and
the result is the same as solving its springs one after another, in any order. The same
table (:data:`SELECTORS`) drives the numpy, numba and GLSL backends, so all three visit
the springs in the same order.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: (name, di, dj, stiffness key of ClothParams.spring_stiffness_n_m, strain limited)
FAMILIES: tuple[tuple[str, int, int, str, bool], ...] = (
    ("horizontal", 0, 1, "horizontal", True),
    ("vertical", 1, 0, "vertical", True),
    ("diagonal", 1, 1, "shear", True),
    ("antidiagonal", 1, -1, "shear", True),
    ("bend_h", 0, 2, "bend", False),
    ("bend_v", 2, 0, "bend", False),
)

#: The 12 springs of a particle, as neighbour offsets (dr, dc), for the gather kernels.
GATHER_OFFSETS: tuple[tuple[int, int], ...] = (
    (0, 1), (0, -1), (1, 0), (-1, 0),          # structural
    (1, 1), (-1, -1), (1, -1), (-1, 1),        # shear
    (0, 2), (0, -2), (2, 0), (-2, 0),          # bend
)


@dataclass(frozen=True)
class Selector:
    """Springs of one family whose first particle has r % row_step == row0 and
    c % col_step == col0. Springs of one selector never share a particle."""

    family: int
    row0: int
    row_step: int
    col0: int
    col_step: int
    colour: int  # selectors of one colour are disjoint from each other as well

    @property
    def di(self) -> int:
        return FAMILIES[self.family][1]

    @property
    def dj(self) -> int:
        return FAMILIES[self.family][2]

    def ranges(self, grid_w: int, grid_h: int) -> tuple[range, range]:
        """Rows and columns of the first particle a of each spring of this selector."""
        di, dj = self.di, self.dj
        col_low = max(0, -dj)
        col0 = self.col0
        if col0 < col_low:  # first column >= col_low with the right remainder
            col0 += self.col_step * math.ceil((col_low - col0) / self.col_step)
        return (range(self.row0, grid_h - di, self.row_step),
                range(col0, grid_w - max(dj, 0), self.col_step))

    def slices(self, grid_w: int, grid_h: int) -> tuple[tuple[slice, slice], tuple[slice, slice]]:
        """numpy slices of the a and b particles of this selector's springs."""
        rows, cols = self.ranges(grid_w, grid_h)
        a = (slice(rows.start, rows.stop, rows.step), slice(cols.start, cols.stop, cols.step))
        b = (slice(rows.start + self.di, rows.stop + self.di, rows.step),
             slice(cols.start + self.dj, cols.stop + self.dj, cols.step))
        return a, b


def _build_selectors() -> tuple[Selector, ...]:
    out: list[Selector] = []
    colour = 0
    # horizontal: colour by column parity; vertical, shear: by row parity
    for family, by_row in ((0, False), (1, True), (2, True), (3, True)):
        for parity in (0, 1):
            if by_row:
                out.append(Selector(family, parity, 2, 0, 1, colour))
            else:
                out.append(Selector(family, 0, 1, parity, 2, colour))
            colour += 1
    # bend springs span two links: remainders {0, 1} then {2, 3} modulo 4
    for family, by_row in ((4, False), (5, True)):
        for pair in ((0, 1), (2, 3)):
            for rem in pair:
                if by_row:
                    out.append(Selector(family, rem, 4, 0, 1, colour))
                else:
                    out.append(Selector(family, 0, 1, rem, 4, colour))
            colour += 1
    return tuple(out)


#: The solver's visiting order: 16 selectors in 12 colours.
SELECTORS: tuple[Selector, ...] = _build_selectors()
COLOUR_COUNT = 1 + max(s.colour for s in SELECTORS)


def selector_table() -> np.ndarray:
    """SELECTORS as an int32 array (S, 7): family, di, dj, row0, row_step, col0, col_step."""
    return np.array([[s.family, s.di, s.dj, s.row0, s.row_step, s.col0, s.col_step]
                     for s in SELECTORS], dtype=np.int32)


def rest_lengths_m(spacing_x_m: float, spacing_y_m: float) -> np.ndarray:
    """Rest length of each family (m), in FAMILIES order."""
    dx, dy = spacing_x_m, spacing_y_m
    diag = math.hypot(dx, dy)
    return np.array([dx, dy, diag, diag, 2 * dx, 2 * dy])


def spring_pairs(grid_w: int, grid_h: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every spring once: flat indices a, b and the family of each (for checks, exports)."""
    index = np.arange(grid_w * grid_h).reshape(grid_h, grid_w)
    a_all, b_all, fam_all = [], [], []
    for family, (_, di, dj, _, _) in enumerate(FAMILIES):
        r0, c0 = 0, max(0, -dj)
        a = index[r0:grid_h - di, c0:grid_w - max(dj, 0)]
        b = index[r0 + di:grid_h, c0 + dj:grid_w - max(dj, 0) + dj]
        a_all.append(a.ravel())
        b_all.append(b.ravel())
        fam_all.append(np.full(a.size, family))
    return np.concatenate(a_all), np.concatenate(b_all), np.concatenate(fam_all)


def triangle_indices(grid_w: int, grid_h: int) -> np.ndarray:
    """Two triangles per grid cell, (T, 3) uint32, counter-clockwise seen from +z at rest."""
    index = np.arange(grid_w * grid_h, dtype=np.uint32).reshape(grid_h, grid_w)
    top_left = index[:-1, :-1].ravel()
    top_right = index[:-1, 1:].ravel()
    bottom_left = index[1:, :-1].ravel()
    bottom_right = index[1:, 1:].ravel()
    # rows run down (-y), columns along +x: (tl, bl, br) is counter-clockwise from +z
    first = np.stack([top_left, bottom_left, bottom_right], axis=1)
    second = np.stack([top_left, bottom_right, top_right], axis=1)
    return np.concatenate([first, second]).astype(np.uint32)
