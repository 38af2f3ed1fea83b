"""The interactive viewer (``catalog view``): a glfw window, an imgui-bundle panel, keys.

Modules: :mod:`.app` (window, loop, timing parts), :mod:`.panel` (the panel),
:mod:`.input` (keys, mouse orbit), :mod:`.catalog_state` (lazy, self-reloading presets),
:mod:`.settings` (what is shown), :mod:`.scene` (cloth -> renderer), :mod:`.screenshot`,
:mod:`.timing`, :mod:`.window`. Importing this package imports nothing heavy; the viewer
never imports scipy.
"""
