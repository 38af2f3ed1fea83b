"""OpenGL plumbing shared by the cloth and the renderer: the one place a context is created
(:mod:`.context`) and shader files with includes and injected defines (:mod:`.shaderlib`).
Importing this package imports nothing heavy."""
