"""Rooms as data: a glTF room loaded and checked (:mod:`catalog.room.load`), its value
(:mod:`catalog.room.model`), and its light transport precomputed once per room
(:mod:`catalog.room.transport`, cached by :mod:`catalog.room.cache`)."""
