"""``--json`` output: exactly one JSON object on stdout and nothing else there."""

from __future__ import annotations

import json
import math
import sys
from typing import Any


def _plain(value: Any) -> Any:
    """numpy scalars and arrays -> Python numbers and lists; non-finite floats -> None."""
    if hasattr(value, "tolist"):
        value = value.tolist()
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


def print_json(obj: dict[str, Any]) -> None:
    """Print ``obj`` as one line of strict JSON (NaN is not JSON: it becomes null)."""
    from catalog.core.atomic import write_stdout  # noqa: PLC0415

    write_stdout(json.dumps(_plain(obj), allow_nan=False) + "\n")
