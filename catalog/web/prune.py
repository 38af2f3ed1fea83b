"""Drop the recorded GL work whose pixels the page never reads.

A recorded frame draws views that only a host step reads back (catalog.gl.host_step: the
room's transport draws its window captures, the room's depth from the key and the outside,
reads them back and uploads the light map). The page replays the step's outputs as the
desktop computed them (the recorded buffer and texture writes), so unless it runs the step
itself (assets/host_steps.js) nothing on the page reads those views: drawing them costs the
page its frame time (18 views into a float32 target, a float32 mip chain, a 1024² depth map
under SwiftShader) for nothing.

:func:`prune_unread` finds, over the structure taken as one frame of a loop (what the page
draws each frame: state left at the end holds at the start), the commands that make pixels
(``draw``, ``clear``, ``mipmaps``) whose outputs nothing reads, and leaves them out. Every
other command (uniforms, bindings, GL state, writes) is kept: a uniform set in a dropped pass
may be read by a later one, and keeping state commands keeps the page's GL state as the
desktop's. A pixel command is live when one of its outputs is read by a live command, or is
the screen (the last framebuffer the structure binds, the page's canvas). What a command reads,
conservatively: a draw, every texture bound to any unit and its framebuffer's attachments
(blending, the depth test); a mipmap build, its texture; a host step the page runs, its input
objects. Outputs: a draw's or a clear's framebuffer's attachments (colour textures, depth
texture or renderbuffer), a mipmap build's texture.
"""

from __future__ import annotations

#: Pixel work: dropped when its outputs are not read.
PIXEL_OPS = ("draw", "clear", "mipmaps")


def _objects(value) -> set[int]:
    """The recorded object ids in a host step's inputs ({"object": id}, nested)."""
    if isinstance(value, dict):
        if set(value) == {"object"}:
            return {int(value["object"])}
        return set().union(*(_objects(v) for v in value.values())) if value else set()
    if isinstance(value, list):
        return set().union(*(_objects(v) for v in value)) if value else set()
    return set()


def _effects(structure: list[dict], framebuffers: dict, page_steps) -> list[tuple[set, set]]:
    """(reads, outputs) of each command (empty sets for those that make no pixels), with the
    bound units as the page has them in a loop of frames (a first pass over the structure
    leaves the state its second pass starts from)."""
    def attachments(fb) -> set[int]:
        entry = framebuffers[fb]
        return set(entry["colour"]) | ({entry["depth"]} if entry.get("depth") is not None else set())

    units: dict[int, int] = {}
    bound = None
    effects = []
    for lap in (0, 1):
        for c in structure:
            op = c["op"]
            if op == "texture":
                units[c["unit"]] = c["texture"]
            elif op == "framebuffer":
                bound = c["framebuffer"]
            if lap == 0:
                continue
            reads, outputs = set(), set()
            if op == "draw" and bound is not None:
                reads = set(units.values()) | attachments(bound)
                outputs = attachments(bound)
            elif op == "draw":
                reads = set(units.values())
            elif op == "clear":
                outputs = attachments(c["framebuffer"])
            elif op == "mipmaps":
                reads = outputs = {c["texture"]}
            elif op == "host" and c["name"] in page_steps:
                reads = _objects(c.get("inputs", {}))
            effects.append((reads, outputs))
    return effects


def prune_unread(structure: list[dict], framebuffers: dict, page_steps=()) -> list[dict]:
    """``structure`` without its pixel commands (:data:`PIXEL_OPS`) whose outputs nothing the
    page draws reads (the module doc). ``framebuffers``: the recording's (id -> {colour: [ids],
    depth: id}); ``page_steps``: the host steps the page runs itself (their inputs are read)."""
    screen = next((c["framebuffer"] for c in reversed(structure) if c["op"] == "framebuffer"),
                  None)
    effects = _effects(structure, framebuffers, set(page_steps))
    live_objects: set[int] = set()
    if screen is not None:
        entry = framebuffers[screen]
        live_objects |= set(entry["colour"]) | ({entry["depth"]} - {None})
    live = [False] * len(structure)
    changed = True
    while changed:
        changed = False
        for i, (c, (reads, outputs)) in enumerate(zip(structure, effects)):
            is_live = c["op"] not in PIXEL_OPS or bool(outputs & live_objects) \
                or (c["op"] == "draw" and not outputs)   # a draw with no framebuffer noted
            if is_live and not live[i]:
                live[i] = True
                if not reads <= live_objects:
                    live_objects |= reads
                    changed = True
    return [c for c, keep in zip(structure, live) if keep]
