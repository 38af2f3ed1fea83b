"""Record what the desktop frame does with its GL context, to replay it in a browser.

:class:`RecordingContext` wraps a real moderngl context (EGL) and hands
:class:`catalog.render.frame.FrameRenderer` proxies of every object it creates. Each call the
frame makes is forwarded to the real object (so the desktop frame renders as usual and
``name in program`` answers as GL does) and noted: the programs (shader files and ``#define``s,
told by :func:`catalog.gl.shaderlib.create_program`), the buffers' bytes, the textures and
framebuffers, and the ordered commands of one frame (bind a framebuffer, clear, viewport, GL
state, a program's uniforms, a texture unit, a draw). The web page replays these commands
with WebGL2 and the ES variant of the same shader files, so whatever passes, programs and
uniforms the desktop frame uses for a scene, the page uses too; nothing of the frame is
written twice.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass, field

import numpy as np

from catalog.core.errors import CatalogError

#: moderngl enable flags -> names the page knows.
_FLAGS = {1: "BLEND", 2: "DEPTH_TEST", 4: "CULL_FACE"}


@dataclass
class Recording:
    """Everything noted: objects by id, and the commands since :meth:`start`."""

    programs: dict[int, dict] = field(default_factory=dict)     # id -> {vertex, fragment, defines}
    buffers: dict[int, bytes] = field(default_factory=dict)     # id -> current bytes
    textures: dict[int, dict] = field(default_factory=dict)     # id -> {size, components, dtype}
    texture_data: dict[int, bytes] = field(default_factory=dict)  # id -> texels given by the frame
    #: id -> {level: texels}: the mip levels the frame gave over its built chain (the pattern's
    #: prefiltered levels, catalog.presets.patterns.mip_chain)
    texture_levels: dict[int, dict[int, bytes]] = field(default_factory=dict)
    renderbuffers: dict[int, dict] = field(default_factory=dict)
    framebuffers: dict[int, dict] = field(default_factory=dict)  # id -> {colour: [ids], depth}
    vertex_arrays: dict[int, dict] = field(default_factory=dict)
    commands: list[dict] | None = None
    #: While recording: skip the GL work whose pixels nobody reads (draws, clears, mipmap
    #: builds); the commands and every object's state are noted all the same.
    dry: bool = False
    bound_framebuffer: object = None
    _next_id: int = 1
    _pending_recipe: dict | None = None

    def new_id(self) -> int:
        self._next_id += 1
        return self._next_id - 1

    def note(self, command: dict) -> None:
        if self.commands is not None:
            self.commands.append(command)

    def start(self, dry: bool = False) -> None:
        """Note the commands from now on; ``dry``: without doing the GL work that only makes
        pixels (a frame recorded for its commands alone, whose image is not read)."""
        self.commands = []
        self.dry = dry

    @property
    def skipping(self) -> bool:
        """Whether pixel work is skipped now (a dry recording in progress)."""
        return self.dry and self.commands is not None

    def stop(self) -> list[dict]:
        commands, self.commands = self.commands or [], None
        self.dry = False
        return commands


class _Proxy:
    """Forwards everything it does not override to the real moderngl object."""

    def __init__(self, real, recording: Recording, object_id: int):
        object.__setattr__(self, "_real", real)
        object.__setattr__(self, "_rec", recording)
        object.__setattr__(self, "rid", object_id)

    def __getattr__(self, name):
        return getattr(self._real, name)

    def __setattr__(self, name, value):
        if isinstance(getattr(type(self), name, None), property):
            object.__setattr__(self, name, value)  # a property of ours notes it first
        else:
            setattr(self._real, name, value)


class _Buffer(_Proxy):
    def write(self, data, offset: int = 0):
        data = bytes(data)
        old = self._rec.buffers[self.rid]
        self._rec.buffers[self.rid] = old[:offset] + data + old[offset + len(data):]
        # written within a frame (e.g. the room's triangles sorted toward the key light):
        # a command the page replays with the scene's bytes
        self._rec.note({"op": "buffer_write", "buffer": self.rid, "offset": int(offset),
                        "data": data})
        return self._real.write(data, offset=offset)


class _Texture(_Proxy):
    @property
    def filter(self):
        return self._real.filter

    @filter.setter
    def filter(self, value) -> None:
        self._rec.textures[self.rid]["filter"] = [int(v) for v in value]
        self._real.filter = value

    @property
    def anisotropy(self):
        return self._real.anisotropy

    @anisotropy.setter
    def anisotropy(self, value) -> None:
        # the page asks EXT_texture_filter_anisotropic for the same (the pattern's, at oblique
        # pleats the filter decides what a texel looks like)
        self._rec.textures[self.rid]["anisotropy"] = float(value)
        self._real.anisotropy = value

    @property
    def compare_func(self):
        return self._real.compare_func

    @compare_func.setter
    def compare_func(self, value) -> None:
        # a depth texture sampled by a shadow sampler (the room's depth map from the key)
        self._rec.textures[self.rid]["compare_func"] = str(value)
        self._real.compare_func = value

    def read(self, *args, **kw):
        if self._rec.skipping:
            raise CatalogError("the desktop frame reads a texture back in a dry recording: "
                               "record a frame with a host step wet (Recording.start(dry=False))")
        return self._real.read(*args, **kw)

    def write(self, data, **kw):
        if set(kw) == {"level"} and kw["level"] > 0 and self._rec.textures[self.rid].get("mipmaps"):
            # a prefiltered mip level (catalog.presets.patterns.mip_chain) over the built chain:
            # the page writes it over its generateMipmap chain at the same level
            if not self._rec.texture_data.get(self.rid):  # (empty: already encoded by the export)
                raise CatalogError("the web page replays mip levels only of textures the frame "
                                   "filled in the same frame")
            self._rec.texture_levels.setdefault(self.rid, {})[int(kw["level"])] = bytes(data)
            return self._real.write(data, **kw)
        if kw:
            raise CatalogError("the web page replays only whole-texture writes")
        if self._rec.commands is not None:
            # written within a frame (a host step's output, e.g. the room's light on the
            # cloth): a command the page replays with the scene's bytes, as a buffer write
            if self._rec.textures[self.rid].get("mipmaps"):
                raise CatalogError("the web page replays in-frame writes only of textures "
                                   "without mipmaps")
            self._rec.note({"op": "texture_write", "texture": self.rid, "data": bytes(data)})
            return self._real.write(data)
        self._rec.texture_data[self.rid] = bytes(data)
        self._rec.texture_levels.pop(self.rid, None)   # new texels: their levels come again
        return self._real.write(data)

    def build_mipmaps(self, base: int = 0, max_level: int = 1000):
        if base != 0:
            raise CatalogError("the web page replays only full mipmap chains")
        if max_level < 1000 and self._rec.commands is not None:
            raise CatalogError("the web page replays only full mipmap chains")
        # made with mipmaps: the page calls generateMipmap after filling it; built again
        # within a frame (a render target, e.g. the room's shadow map): a command the page
        # replays at the same place
        self._rec.textures[self.rid]["mipmaps"] = True
        if self.rid not in self._rec.texture_data:  # texels drawn by the frame, not given
            self._rec.note({"op": "mipmaps", "texture": self.rid})
            if self._rec.skipping:
                return None
        return self._real.build_mipmaps(base, max_level)

    @property
    def repeat_x(self):
        return self._real.repeat_x

    @repeat_x.setter
    def repeat_x(self, value) -> None:
        self._rec.textures[self.rid]["repeat_x"] = bool(value)
        self._real.repeat_x = value

    @property
    def repeat_y(self):
        return self._real.repeat_y

    @repeat_y.setter
    def repeat_y(self, value) -> None:
        self._rec.textures[self.rid]["repeat_y"] = bool(value)
        self._real.repeat_y = value

    def use(self, location: int = 0):
        self._rec.note({"op": "texture", "unit": int(location), "texture": self.rid})
        return self._real.use(location=location)


class _Framebuffer(_Proxy):
    @property
    def depth_mask(self):
        return self._real.depth_mask

    @depth_mask.setter
    def depth_mask(self, value) -> None:
        # moderngl applies it whenever the framebuffer is used or cleared (the OIT layers are
        # depth-tested against the room but write no depth, and their clear keeps the room's)
        self._rec.framebuffers[self.rid]["depth_mask"] = bool(value)
        self._real.depth_mask = value

    def __setattr__(self, name, value):
        # any other framebuffer state (colour mask, scissor, viewport) the page would not know
        if not isinstance(getattr(type(self), name, None), property):
            raise CatalogError(f"the desktop frame sets a framebuffer's {name}; the web page "
                               "replays only its depth mask")
        object.__setattr__(self, name, value)

    def use(self):
        self._rec.bound_framebuffer = self
        self._rec.note({"op": "framebuffer", "framebuffer": self.rid})
        result = self._real.use()
        # moderngl's use() also sets the viewport to the framebuffer's (GL's bind does not)
        self._rec.note({"op": "viewport", "viewport": [int(v) for v in self._real.viewport]})
        return result

    def clear(self, red=0.0, green=0.0, blue=0.0, alpha=0.0, depth=1.0, viewport=None, **kw):
        self._rec.note({"op": "clear", "framebuffer": self.rid,
                        "colour": [float(red), float(green), float(blue), float(alpha)],
                        "depth": float(depth),
                        "viewport": None if viewport is None else [int(v) for v in viewport]})
        if self._rec.skipping:
            return None
        return self._real.clear(red, green, blue, alpha, depth=depth, viewport=viewport, **kw)


class _Uniform:
    def __init__(self, program: "_Program", name: str):
        self._program, self._name, self._real = program, name, program._real[name]

    def _note(self, value) -> None:
        self._program._rec.note({"op": "uniform", "program": self._program.rid,
                                 "name": self._name, "value": value})

    @property
    def value(self):
        return self._real.value

    @value.setter
    def value(self, value) -> None:
        if isinstance(value, (tuple, list)):
            noted = [float(v) for v in value]
        elif isinstance(value, (int, np.integer)) and not isinstance(value, bool):
            noted = int(value)
        else:
            noted = float(value)
        self._note(noted)
        self._real.value = value

    def write(self, data) -> None:
        data = bytes(data)
        self._note([float(v) for v in np.frombuffer(data, dtype=np.float32)])
        self._real.write(data)


class _Program(_Proxy):
    def __contains__(self, name) -> bool:
        return name in self._real

    def __getitem__(self, name):
        return _Uniform(self, name)


class _VertexArray(_Proxy):
    def render(self, mode=None, vertices: int = -1, first: int = 0, **kw):
        if kw:
            raise CatalogError(f"the web page replays draws without {', '.join(kw)}")
        self._rec.note({"op": "draw", "vertex_array": self.rid, "mode": int(mode)
                        if mode is not None else 4, "vertices": int(vertices),
                        "first": int(first)})
        if self._rec.skipping:
            return None
        if mode is None:
            return self._real.render(vertices=vertices, first=first)
        return self._real.render(mode, vertices=vertices, first=first)


#: Context attributes passed through unrecorded: they read, wait or release, and change
#: nothing the page would have to replay. Any other (e.g. ``copy_framebuffer``, ``clear``,
#: ``blend_equation``) is refused: the page would silently differ from the desktop frame.
PASS_THROUGH = frozenset({"info", "version_code", "error", "finish", "screen",
                          "detect_framebuffer", "release", "extensions", "max_samples",
                          "max_texture_units", "default_texture_unit", "mglo", "gc_mode"})


class RecordingContext:
    """A moderngl context that notes what is done with it (see the module docstring)."""

    def __init__(self, ctx):
        object.__setattr__(self, "_ctx", ctx)
        object.__setattr__(self, "recording", Recording())

    def __getattr__(self, name):
        if name in PASS_THROUGH or name.startswith("__"):
            return getattr(self._ctx, name)
        raise CatalogError(f"the desktop frame uses ctx.{name}, which the web page does not "
                           "replay (teach catalog/web/record.py and assets/app.js)")

    def __setattr__(self, name, value):
        if isinstance(getattr(type(self), name, None), property):
            object.__setattr__(self, name, value)
        else:
            raise CatalogError(f"the desktop frame sets ctx.{name}, which the web page does "
                               "not replay (teach catalog/web/record.py and assets/app.js)")

    # -- told by shaderlib.create_program just before it calls program()
    def program_recipe_sink(self, vertex: str, fragment: str | None, defines: dict) -> None:
        self.recording._pending_recipe = {"vertex": vertex, "fragment": fragment,
                                          "defines": defines}

    # -- told by catalog.gl.host_step around a frame's host work
    @contextlib.contextmanager
    def host_step_sink(self, name: str, inputs: dict):
        """Notes ``host`` (the step's name, its inputs with GL objects as ids) and, after the
        step's own commands (its outputs), ``host_end``; the step reads pixels back, so a dry
        recording is refused."""
        rec = self.recording
        if rec.skipping:
            raise CatalogError(f"host step {name!r} reads pixels back: record its frame wet")
        rec.note({"op": "host", "name": str(name), "inputs": _plain(inputs)})
        yield
        rec.note({"op": "host_end", "name": str(name)})

    def program(self, **kw):
        recipe = self.recording._pending_recipe
        self.recording._pending_recipe = None
        if recipe is None:
            raise CatalogError("a program was made without catalog.gl.shaderlib: the web "
                               "page can only replay programs built from shader files")
        proxy = _Program(self._ctx.program(**kw), self.recording, self.recording.new_id())
        self.recording.programs[proxy.rid] = recipe
        return proxy

    def buffer(self, data=None, reserve: int = 0, dynamic: bool = False, **kw):
        real = self._ctx.buffer(data, reserve=reserve, dynamic=dynamic, **kw)
        proxy = _Buffer(real, self.recording, self.recording.new_id())
        self.recording.buffers[proxy.rid] = bytes(data) if data is not None else bytes(real.size)
        return proxy

    def texture(self, size, components, data=None, dtype="f1", **kw):
        real = self._ctx.texture(size, components, data, dtype=dtype, **kw)
        proxy = _Texture(real, self.recording, self.recording.new_id())
        self.recording.textures[proxy.rid] = {"size": [int(v) for v in size],
                                              "components": int(components), "dtype": dtype,
                                              "filter": [int(v) for v in real.filter]}
        if data is not None:
            self.recording.texture_data[proxy.rid] = bytes(data)
        return proxy

    def depth_texture(self, size, data=None, **kw):
        """A depth texture (the room's depth map from the key), drawn by the frame, sampled
        with its compare function (:attr:`_Texture.compare_func`)."""
        if data is not None:
            raise CatalogError("the web page replays only depth textures the frame draws")
        real = self._ctx.depth_texture(size, **kw)
        proxy = _Texture(real, self.recording, self.recording.new_id())
        self.recording.textures[proxy.rid] = {"size": [int(v) for v in size], "components": 1,
                                              "dtype": "depth", "filter": [int(v) for v in real.filter]}
        return proxy

    def depth_renderbuffer(self, size, **kw):
        proxy = _Proxy(self._ctx.depth_renderbuffer(size, **kw), self.recording,
                       self.recording.new_id())
        self.recording.renderbuffers[proxy.rid] = {"size": [int(v) for v in size]}
        return proxy

    def framebuffer(self, color_attachments=(), depth_attachment=None):
        colour = list(color_attachments) if isinstance(color_attachments, (list, tuple)) \
            else [color_attachments]
        real = self._ctx.framebuffer([c._real for c in colour],
                                     depth_attachment._real if depth_attachment is not None else None)
        proxy = _Framebuffer(real, self.recording, self.recording.new_id())
        self.recording.framebuffers[proxy.rid] = {
            "colour": [c.rid for c in colour],
            "depth": depth_attachment.rid if depth_attachment is not None else None}
        return proxy

    def vertex_array(self, program, content, index_buffer=None, index_element_size: int = 4, **kw):
        real_content = []
        noted = []
        for entry in content:
            buffer, layout, *names = entry
            real_content.append((buffer._real, layout, *names))
            noted.append({"buffer": buffer.rid, "layout": layout, "attributes": list(names)})
        real = self._ctx.vertex_array(program._real, real_content,
                                      index_buffer=index_buffer._real if index_buffer is not None else None,
                                      index_element_size=index_element_size, **kw)
        proxy = _VertexArray(real, self.recording, self.recording.new_id())
        self.recording.vertex_arrays[proxy.rid] = {
            "program": program.rid, "content": noted,
            "index_buffer": index_buffer.rid if index_buffer is not None else None,
            "index_element_size": int(index_element_size)}
        return proxy

    # -- state
    @property
    def fbo(self):
        """The bound framebuffer: our proxy when one of ours is bound (the frame compares it
        with its own before releasing them)."""
        real = self._ctx.fbo
        bound = self.recording.bound_framebuffer
        return bound if bound is not None and bound._real is real else real

    def enable(self, flags) -> None:
        self.recording.note({"op": "enable", "flags": _flag_names(flags)})
        self._ctx.enable(flags)

    def disable(self, flags) -> None:
        self.recording.note({"op": "disable", "flags": _flag_names(flags)})
        self._ctx.disable(flags)

    @property
    def viewport(self):
        return self._ctx.viewport

    @viewport.setter
    def viewport(self, value) -> None:
        self.recording.note({"op": "viewport", "viewport": [int(v) for v in value]})
        self._ctx.viewport = value

    def clear(self, red=0.0, green=0.0, blue=0.0, alpha=0.0, depth=1.0, viewport=None, **kw):
        """Clears the bound framebuffer (noted as a clear of it)."""
        bound = self.recording.bound_framebuffer
        if bound is None or bound._real is not self._ctx.fbo:
            raise CatalogError("the desktop frame clears a framebuffer the web page does not know")
        return bound.clear(red, green, blue, alpha, depth=depth, viewport=viewport, **kw)

    @property
    def blend_equation(self):
        return self._ctx.blend_equation

    @blend_equation.setter
    def blend_equation(self, value) -> None:
        values = value if isinstance(value, (tuple, list)) else (value,)
        self.recording.note({"op": "blend_equation", "modes": [int(v) for v in values]})
        self._ctx.blend_equation = value

    @property
    def blend_func(self):
        return self._ctx.blend_func

    @blend_func.setter
    def blend_func(self, value) -> None:
        self.recording.note({"op": "blend_func", "factors": [int(v) for v in value]})
        self._ctx.blend_func = value

    @property
    def depth_func(self):
        return self._ctx.depth_func

    @depth_func.setter
    def depth_func(self, value) -> None:
        self.recording.note({"op": "depth_func", "func": str(value)})
        self._ctx.depth_func = value


def _flag_names(flags: int) -> list[str]:
    names = [name for bit, name in _FLAGS.items() if int(flags) & bit]
    if int(flags) & ~sum(_FLAGS):
        raise CatalogError(f"GL state flags {int(flags)} include some the web page cannot set")
    return names


def _plain(value):
    """A host step's inputs as JSON: GL objects by their recorded id ({"object": id}), numpy
    arrays and tuples as lists."""
    if isinstance(value, _Proxy):
        return {"object": value.rid}
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return _plain(value.tolist())
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value)
    if value is None or isinstance(value, str):
        return value
    raise CatalogError(f"a host step's input of type {type(value).__name__} cannot be recorded")
