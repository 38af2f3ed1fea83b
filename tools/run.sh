#!/usr/bin/env bash
# Run the fabric catalog (after tools/setup.sh).
#
# With a display that glfw can open: the interactive viewer, `catalog view` (any
# arguments are passed on to it). Without one (a server, a container, CI): the catalog
# rendered headless through EGL, every fabric under four lights, with
# `catalog sheet --lights D65,sun:22,LED-B4,UV-A --out renders/`, and where the images are.
#
# CATALOG_RUN_OUT=DIR changes the output folder; CATALOG_RUN_DRY=1 prints the command
# instead of running it.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
PY="$ROOT/.venv/bin/python"
if [ ! -x "$PY" ]; then
  echo "run.sh: no virtual environment in $ROOT/.venv: run tools/setup.sh first" >&2
  exit 2
fi
OUT="${CATALOG_RUN_OUT:-renders}"
LIGHTS="D65,sun:22,LED-B4,UV-A"

run() {
  if [ -n "${CATALOG_RUN_DRY:-}" ]; then
    echo "$*"
  else
    "$@"
  fi
}

display_opens() {
  # a display is named, and glfw can actually open it (a stale DISPLAY cannot)
  [ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ] || return 1
  "$PY" -c 'import glfw, sys; glfw.set_error_callback(lambda *a: None); sys.exit(0 if glfw.init() else 1)' \
    >/dev/null 2>&1
}

if display_opens; then
  run "$PY" -m catalog view "$@"
  exit $?
fi

echo "run.sh: no display to open a window on: rendering the catalog headless (EGL) instead"
run "$PY" -m catalog sheet --lights "$LIGHTS" --out "$OUT"
if [ -z "${CATALOG_RUN_DRY:-}" ]; then
  echo "run.sh: images in $(cd "$OUT" && pwd)/ (one per fabric and light, and the grid);"
  echo "        on a machine with a display, tools/run.sh opens the viewer (catalog view)"
fi
