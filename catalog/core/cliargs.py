"""Option values shared by several commands (light: no numpy, no GL)."""

from __future__ import annotations

import argparse
import re

from catalog.core.errors import InputError

_WXH = re.compile(r"\s*(\d+)\s*[xX]\s*(\d+)\s*")


def parse_wxh(text: str, option: str, low: int, high: int | None = None,
              unit: str = "px", example: str = "1280x720") -> tuple[int, int]:
    """``WxH`` -> (width, height), both whole numbers in ``low..high`` (no upper bound when
    ``high`` is None); otherwise an InputError naming ``option``."""
    match = _WXH.fullmatch(str(text))
    if match is None:
        raise InputError(f"{text!r} is not WIDTHxHEIGHT in {unit} (e.g. {example})", field=option)
    width, height = int(match.group(1)), int(match.group(2))
    if not (low <= width and low <= height
            and (high is None or (width <= high and height <= high))):
        bound = f"{low}..{high}" if high is not None else f"at least {low}"
        raise InputError(f"{width}x{height} is impossible: each side must be {bound} {unit}",
                         field=option)
    return width, height


def wxh_type(option: str, low: int, high: int | None = None, unit: str = "px",
             example: str = "1280x720"):
    """An argparse ``type=`` for :func:`parse_wxh` (argparse prefixes the option itself)."""
    def parse(text: str) -> tuple[int, int]:
        try:
            return parse_wxh(text, option, low, high, unit, example)
        except InputError as exc:
            raise argparse.ArgumentTypeError(exc.problem) from None
    return parse
