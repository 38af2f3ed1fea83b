"""When the room's light is redrawn: a change of the scene, the cloth or the lamps, or the
cloth moving (at the settings' room_update_every)."""

from __future__ import annotations


class RoomLightSchedule:
    """Whether the room's light (the key's maps, the transport's update) is stale this frame."""

    def __init__(self, frame):
        self.frame = frame
        self._room_key = None
        self._room_frames = 0
        self._room_mesh_version = None

    def stale(self) -> bool:
        """Whether the room's light must be redrawn this frame (see room_update_every)."""
        frame = self.frame
        key = (frame.terms.inputs_key, frame.curtain_open, frame.room_lighting,
               frame.room_side_active(), frame.key_second_layer, frame.patterned,
               frame.fabric_pattern.key,
               tuple((light.name, position) for light, position in frame.room_lamps))
        self._room_frames += 1
        # a cloth on the GPU moves unseen: its owner calls frame.cloth_moved() after each step
        moved = frame.mesh.version != self._room_mesh_version
        due = moved and self._room_frames >= frame.room_update_every
        if key != self._room_key or due or frame.room_targets.objects is None:
            self._room_key = key
            self._room_mesh_version = frame.mesh.version
            self._room_frames = 0
            return True
        return False

    def invalidate(self) -> None:
        """Redraw the room's light at the next frame (e.g. after the cloth moved on the GPU)."""
        self._room_key = None
