"""An orbit camera: yaw, pitch and distance around a target; perspective projection.

Matrices are float64 numpy in the usual column-vector convention (clip = P V p);
:func:`gl_bytes` hands them to GLSL (column-major float32).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from catalog.core.errors import CatalogError

#: Pitch is kept inside +-89 deg (the up vector degenerates at the poles).
PITCH_LIMIT_DEG = 89.0


@dataclass(frozen=True)
class OrbitCamera:
    """yaw 0 looks from +z towards -z (from the room at the window); pitch > 0 from above."""

    target: tuple[float, float, float] = (0.0, 0.15, -0.08)
    yaw_deg: float = 0.0
    pitch_deg: float = 0.0
    distance_m: float = 2.6
    fov_y_deg: float = 50.0
    near_m: float = 0.05
    far_m: float = 50.0

    def __post_init__(self) -> None:
        for name in ("yaw_deg", "pitch_deg", "distance_m", "fov_y_deg"):
            if not math.isfinite(getattr(self, name)):
                raise CatalogError(f"camera {name} must be finite")
        if not self.distance_m > self.near_m:
            raise CatalogError(f"camera distance {self.distance_m:g} m must exceed the near "
                               f"plane ({self.near_m:g} m)")
        if not 1.0 <= self.fov_y_deg <= 170.0:
            raise CatalogError(f"camera field of view {self.fov_y_deg:g} deg is outside 1..170")
        object.__setattr__(self, "pitch_deg",
                           max(-PITCH_LIMIT_DEG, min(PITCH_LIMIT_DEG, self.pitch_deg)))

    @property
    def position(self) -> np.ndarray:
        yaw, pitch = math.radians(self.yaw_deg), math.radians(self.pitch_deg)
        offset = np.array([math.sin(yaw) * math.cos(pitch), math.sin(pitch),
                           math.cos(yaw) * math.cos(pitch)])
        return np.asarray(self.target, dtype=np.float64) + self.distance_m * offset

    def view(self) -> np.ndarray:
        eye = self.position
        forward = np.asarray(self.target, dtype=np.float64) - eye
        forward /= np.linalg.norm(forward)
        right = np.cross(forward, [0.0, 1.0, 0.0])
        right /= np.linalg.norm(right)
        up = np.cross(right, forward)
        m = np.eye(4)
        m[0, :3], m[1, :3], m[2, :3] = right, up, -forward
        m[:3, 3] = -m[:3, :3] @ eye
        return m

    def projection(self, aspect: float) -> np.ndarray:
        f = 1.0 / math.tan(math.radians(self.fov_y_deg) / 2)
        n, fa = self.near_m, self.far_m
        m = np.zeros((4, 4))
        m[0, 0] = f / aspect
        m[1, 1] = f
        m[2, 2] = (fa + n) / (n - fa)
        m[2, 3] = 2 * fa * n / (n - fa)
        m[3, 2] = -1.0
        return m

    def view_projection(self, aspect: float) -> np.ndarray:
        return self.projection(aspect) @ self.view()


def gl_bytes(matrix: np.ndarray) -> bytes:
    """A 4x4 matrix as GLSL expects it: column-major float32."""
    return np.ascontiguousarray(np.asarray(matrix, dtype=np.float32).T).tobytes()
