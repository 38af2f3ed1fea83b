"""The frame as passes (docs/architecture.md, "The frame"). One frame of the curtain scene,
in the order :class:`catalog.render.frame.FrameRenderer` runs them:

0. the room's light, when stale (:meth:`catalog.render.passes.room_schedule.RoomLightSchedule.stale`): ``shadow``
   (the key light's maps, :mod:`.shadow`), then the room's precomputed transport
   (:mod:`.room_transport_light`: its views of the window, the light map, the curtain's two sides);
1. the room (:mod:`.room_transport`): the room file's surfaces and the rod and rings, depth-tested;
2. ``background`` (:mod:`.background`): the outside on the far plane;
3. ``curtain`` (:mod:`.curtain`): the cloth, its layers resolved over 1-2 (OIT);
4. ``glare`` (:mod:`.glare`), when on;
5. ``display`` (:mod:`.display`): exposure, white balance, tone curve, FXAA.

Each pass owns its programs' choice, its vertex arrays and its private GL objects, and reads
what it needs from the frame: the settings, the derived terms (:mod:`.scene_terms`), the mesh
(:mod:`.curtain_mesh`), the pattern (:mod:`.pattern`). The frame owns the targets
(:mod:`.targets`: the HDR, display, OIT and MSAA targets and the curtain's maps for the room's light) and the
program cache (:mod:`.gl_common`).
"""
