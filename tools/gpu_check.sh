#!/usr/bin/env bash
# The GPU check (docs/gpu.md, "The GPU check"): on a machine with an NVIDIA GPU and no
# network, install the few packages it lacks from wheels carried with the checkout, then run
# the frame bench (benchmarks.gpu_check: 720p, 1080p, 4K; gpu and cpu cloth 128x128;
# moving and static) in under 5 minutes, writing one JSON.
#
#   tools/gpu_check.sh [OUT_JSON]                    # default benchmarks/gpu_check.json
#   GPU_CHECK_ARGS=--tiny tools/gpu_check.sh F.json  # the dry run (llvmpipe, tiny sizes)
#
# Python: $PYTHON, else the checkout's .venv, else python3. Wheels: $CATALOG_WHEELS (default
# ./wheelhouse, made where there is network by tools/gpu_wheels.sh). Only the modules that
# Python cannot import already are installed, with --target into $GPU_CHECK_SITE (default
# /tmp/catalog-gpu-site), put on PYTHONPATH; nothing is installed into the system.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
OUT="${1:-$ROOT/benchmarks/gpu_check.json}"
WHEELS="${CATALOG_WHEELS:-$ROOT/wheelhouse}"
SITE="${GPU_CHECK_SITE:-/tmp/catalog-gpu-site}"
START=$(date +%s)
if [ -n "${PYTHON:-}" ]; then RUN_PY="$PYTHON"
elif [ -x "$ROOT/.venv/bin/python" ]; then RUN_PY="$ROOT/.venv/bin/python"
else RUN_PY=python3; fi
export PYTHONPATH="$ROOT:$SITE${PYTHONPATH:+:$PYTHONPATH}"

# module:distribution of what the headless frame imports (numba: the cpu cloth and the drape)
missing=()
for pair in numpy:numpy moderngl:moderngl glcontext:glcontext OpenImageIO:openimageio \
            numba:numba llvmlite:llvmlite tomli_w:tomli-w rich:rich pygments:pygments \
            markdown_it:markdown-it-py mdurl:mdurl; do
  module=${pair%%:*}; dist=${pair#*:}
  "$RUN_PY" -c "import $module" 2>/dev/null || missing+=("$dist")
done
if ((${#missing[@]})); then
  wheels=()
  for dist in "${missing[@]}"; do
    found=$(ls "$WHEELS"/$(echo "$dist" | tr - _)-*.whl "$WHEELS"/"$dist"-*.whl 2>/dev/null | head -1 || true)
    if [ -n "$found" ]; then wheels+=("$found")
    else echo "gpu_check: $dist: not importable and no wheel in $WHEELS (tools/gpu_wheels.sh)" >&2; fi
  done
  if ((${#wheels[@]})); then
    echo "gpu_check: installing into $SITE: ${wheels[*]##*/}"
    "$RUN_PY" -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade \
      --target "$SITE" "${wheels[@]}" \
      || echo "gpu_check: the wheels did not install (another Python version?); cases that" \
              "need them are reported as skipped" >&2
  fi
fi
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader 2>/dev/null \
  | sed 's/^/gpu_check: /' || echo "gpu_check: nvidia-smi not found (no NVIDIA GPU?)"
cd "$ROOT"
# 240 s for starting cases, 290 s at most for the run: the 5 minutes include the set-up
timeout 290 "$RUN_PY" -m benchmarks.gpu_check --budget-s 240 --json-out "$OUT" \
  ${GPU_CHECK_ARGS:-}
echo "gpu_check: done in $(( $(date +%s) - START )) s: $OUT"
