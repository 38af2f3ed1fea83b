"""``python -m benchmarks [options]``: the same as ``catalog bench [options]`` in a checkout."""

from __future__ import annotations

import sys

from catalog.commands.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", *sys.argv[1:]]))
