"""Option values shared by several commands (light: no numpy, no GL)."""

from __future__ import annotations

import argparse
import re

from catalog.core.errors import InputError

_WXH = re.compile(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", re.ASCII)


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


def number_type(low: float, high: float, *, unit: str = "", low_open: bool = False,
                high_open: bool = False, whole: bool = False):
    """An argparse ``type=`` for a finite number in ``low..high`` (``low_open``/``high_open``
    exclude the bound; ``whole`` asks for an integer). argparse names the option in its
    message: ``argument --wind: must be a finite number in [0, 50] m/s, found 'nan'``."""
    import math  # noqa: PLC0415

    lo, hi = ("(" if low_open else "["), (")" if high_open else "]")
    kind = "whole number" if whole else "finite number"
    def show(bound: float) -> str:
        return str(int(bound)) if whole else f"{bound:g}"

    wanted = f"must be a {kind} in {lo}{show(low)}, {show(high)}{hi}" + (f" {unit}" if unit else "")

    from catalog.core.validate import _DECIMAL, _WHOLE  # noqa: PLC0415

    def parse(text: str):
        raw = str(text).strip()
        # plain digits only: Python's int()/float() also take '1_000' and 'nan'
        if not (_WHOLE if whole else _DECIMAL).fullmatch(raw) or len(raw) > 40:
            raise argparse.ArgumentTypeError(f"{wanted}, found {text[:20]!r}")
        value = int(raw) if whole else float(raw)
        ok = math.isfinite(value) and (value > low if low_open else value >= low) \
            and (value < high if high_open else value <= high)
        if not ok:
            raise argparse.ArgumentTypeError(f"{wanted}, found {text[:20]!r}")
        return value
    return parse

