"""Bytes held deflated while a site is built: what data.js carries as zlib (site.pack_data)
is compressed once, when it is recorded, and held so (a fraction of its raw size, and of
its base64's 4/3 of it) until it is written as it is."""

from __future__ import annotations

import base64
import zlib
from dataclasses import dataclass

#: zlib's level for the bytes data.js carries (site.pack_data deflates the JSON at it too).
DEFLATE_LEVEL = 9


@dataclass(frozen=True)
class Deflated:
    """``data``: zlib.compress(raw, DEFLATE_LEVEL); ``size``: len(raw)."""

    data: bytes
    size: int

    @classmethod
    def of(cls, raw: bytes) -> Deflated:
        return cls(zlib.compress(raw, DEFLATE_LEVEL), len(raw))

    @classmethod
    def of_pieces(cls, pieces) -> Deflated:
        """:meth:`of` the concatenation of the byte strings ``pieces`` (an iterable), without
        making it: zlib gives the same bytes for its input fed in parts."""
        deflate = zlib.compressobj(DEFLATE_LEVEL)
        size, out = 0, []
        for piece in pieces:
            size += len(piece)
            out.append(deflate.compress(piece))
        out.append(deflate.flush())
        return cls(b"".join(out), size)

    def raw(self) -> bytes:
        return zlib.decompress(self.data)

    def b64(self) -> str:
        """The raw bytes' base64 (the plain data.js form)."""
        return base64.b64encode(self.raw()).decode("ascii")

    def b64_length(self) -> int:
        """len(self.b64()) without making it."""
        return 4 * ((self.size + 2) // 3)
