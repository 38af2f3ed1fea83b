#!/usr/bin/env bash
# Set up a fresh machine: Debian packages the renderer and the window tests need (only
# those missing), a virtual environment in .venv, and the project installed editable with
# its optional extras (the path tracer, Dask) and the test tools.
# Idempotent: a second run installs nothing new.
set -euo pipefail
cd "$(dirname "$0")/.."

need_apt=()
have_pkg() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"; }
# Mesa's EGL + llvmpipe (headless GL 4.5), GLX for windows, Xvfb and xdotool for window tests,
# glslang-tools (glslangValidator) to check the display shader compiles as GLSL ES 3.00;
# Chromium and its WebDriver for the web catalog's browser tests (WebGL2 through SwiftShader);
# LLVM 19 for Mitsuba's JIT (the path-traced reference; Mesa's LLVM 14/15 cannot run it).
for pkg in libegl1 libegl-mesa0 libgl1-mesa-dri libglx-mesa0 libgl1 xvfb xauth xdotool glslang-tools \
           chromium chromium-driver libllvm19; do
  have_pkg "$pkg" || need_apt+=("$pkg")
done
if ((${#need_apt[@]})); then
  echo "setup: installing Debian packages: ${need_apt[*]}"
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get -o DPkg::Lock::Timeout=600 update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends -o DPkg::Lock::Timeout=600 "${need_apt[@]}" >/dev/null
fi

PY=${PYTHON:-python3}
[ -x .venv/bin/python ] || "$PY" -m venv .venv
.venv/bin/python -m pip install -q --upgrade pip
.venv/bin/python -m pip install -q -e ".[test,pathtrace,batch${EXTRAS:+,$EXTRAS}]"
# Node tools the tests use (tools/node/package.json: the Khronos glTF-Validator, three.js)
if command -v npm >/dev/null 2>&1 && [ ! -d tools/node/node_modules/gltf-validator ]; then
  echo "setup: installing tools/node (npm)"
  (cd tools/node && npm install --no-audit --no-fund --silent)
fi
echo "setup: ready (.venv)"
