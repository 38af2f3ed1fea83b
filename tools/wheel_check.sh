#!/usr/bin/env bash
# CI: build the wheel, install it into a fresh virtual environment, and run the main
# commands from a folder outside the checkout: what a user gets from `pip install`.
# Usage: tools/wheel_check.sh [WORK_DIR]   (default: a temporary folder, removed after)
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
WORK="${1:-$(mktemp -d)}"
[ -n "${1:-}" ] || trap 'rm -rf "$WORK"' EXIT
mkdir -p "$WORK/wheel" "$WORK/run"
PY=${PYTHON:-python3}

echo "wheel_check: building the wheel"
"$ROOT/.venv/bin/python" -m pip wheel -q --no-deps -w "$WORK/wheel" "$ROOT"
"$PY" -m venv "$WORK/venv"
WHEEL=$(ls "$WORK"/wheel/*.whl)
# a plain install, no extras: every main command must run from it
"$WORK/venv/bin/python" -m pip install -q "$WHEEL"
CATALOG="$WORK/venv/bin/catalog"

cd "$WORK/run"  # outside the checkout: only what the wheel carries is found
unset CATALOG_FABRICS
echo "wheel_check: snapshot"
"$CATALOG" snapshot --fabric lace-fwa --light D65 --size 64x48 --out snap.png --json > snap.json
echo "wheel_check: fit"
# a measurement the user brings (here the checkout's own, copied out)
cp "$ROOT/fabrics/measurements/voile-white/gonio.csv" gonio.csv
"$CATALOG" fit --gonio gonio.csv --name my-voile --out my-voile.toml --json > fit.json
echo "wheel_check: sheet (the built-in catalog and the user's folder)"
mkdir -p mine && cp -r my-voile.toml my-voile mine/   # a preset travels with its folder (its pattern)
"$CATALOG" sheet --lights D65 --fabric lace-fwa,my-voile --fabrics mine --size 48x36 --out sheet --json > sheet.json
echo "wheel_check: view --frames under Xvfb"
xvfb-run -a "$CATALOG" view --frames 2 --size 160x120 --grid 12x16 --cloth-backend numpy \
  --fabric voile-white --screenshot view.png
echo "wheel_check: an optional extra that is not installed is one line naming it (exit 3)"
set +e
"$CATALOG" reference --fabric lace-fwa --size 16x12 --spp 1 --out ref.exr 2> ref.err
status=$?
set -e
if [ "$status" -ne 3 ] || [ "$(wc -l < ref.err)" -ne 1 ] || [ -e ref.exr ]; then
  echo "wheel_check: catalog reference without the pathtrace extra: exit $status" >&2
  cat ref.err >&2; exit 1
fi
grep -q "fabric-catalog\[pathtrace\]\|libllvm19" ref.err || { cat ref.err >&2; exit 1; }
for f in snap.png sheet.json view.png my-voile.toml; do
  [ -s "$f" ] || { echo "wheel_check: $f missing" >&2; exit 1; }
done
"$WORK/venv/bin/python" - <<'PY'
import json
snap = json.load(open("snap.json")); fit = json.load(open("fit.json")); sheet = json.load(open("sheet.json"))
assert len(sheet["images"]) == 2, sheet
print("wheel_check: ok:", snap.get("out", "snap.png"), "fit rmse", fit.get("rmse"), len(sheet["images"]), "sheet images")
PY
