"""Rooms as data: a glTF room loaded and checked (:mod:`catalog.room.load`), its value
(:mod:`catalog.room.model`), and its light transport precomputed once per room
(:mod:`catalog.room.transport`, cached by :mod:`catalog.room.cache`)."""

#: The rooms that ship with the package (catalog/room/data/NAME.glb), by name.
BUILTIN_ROOMS = ("box", "living", "bedroom")
