#!/usr/bin/env bash
# Make the wheel folder tools/gpu_check.sh installs from on a GPU machine without network:
# binary wheels, no dependencies pulled, for one CPython version.
#   tools/gpu_wheels.sh [PYTHON_VERSION] [DIR]   # default 3.12 ./wheelhouse (git-ignored)
# Default packages: what the lent H200's image lacks (device KINDS list, 2026-11: it has
# numpy, numba, llvmlite, rich): moderngl, glcontext, tomli-w, OpenImageIO, about 9 MB.
# EXTRA="numba llvmlite rich pygments markdown-it-py mdurl" adds the rest (about 65 MB:
# llvmlite alone is 60), e.g. for a dry run on a bare Python.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
VERSION="${1:-3.12}"
DIR="${2:-$ROOT/wheelhouse}"
PY="$ROOT/.venv/bin/python"; [ -x "$PY" ] || PY="${PYTHON:-python3}"
mkdir -p "$DIR"
# shellcheck disable=SC2086
"$PY" -m pip download -q --only-binary=:all: --no-deps --python-version "$VERSION" \
  --implementation cp --platform manylinux_2_28_x86_64 --platform manylinux_2_27_x86_64 \
  --platform manylinux_2_17_x86_64 --platform manylinux2014_x86_64 \
  --platform manylinux1_x86_64 -d "$DIR" \
  "moderngl>=5.10" glcontext "tomli-w>=1.0" "openimageio>=3.0" ${EXTRA:-}
du -sh "$DIR"
