#!/usr/bin/env bash
# Installs rtcost's build and test dependencies from Debian's packages. Idempotent: packages that
# are already installed are left alone, and apt is only asked when something is missing.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libassimp-dev assimp-testmodels    # mesh formats, and real test meshes
  libembree-dev                      # Embree 3: reference and peer
  libtbb-dev                         # threads
  libcli11-dev nlohmann-json3-dev libfmt-dev
  libpng-dev libstb-dev              # images
  libgtest-dev libgmock-dev libbenchmark-dev
  libcairo2-dev fonts-dejavu-core    # heat maps: legends drawn with a real font
  chromium                           # the report's test in a headless browser
  clang libclang-rt-14-dev llvm      # sanitizer builds, libFuzzer, symbolised reports
  pybind11-dev python3-dev           # the Python module (Debian's /usr/bin/python3)
  python3-numpy python3-pandas python3-pytest
  python3-dask python3-distributed   # sweeps
)
# npm installs the report's plotting library (Vega-Lite) and the browser test's driver; a machine
# with Node.js from elsewhere (e.g. NodeSource) keeps it.
command -v npm > /dev/null || packages+=(nodejs npm)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed"
else
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  echo "install-deps: installing ${missing[*]}"
  $sudo apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# Vega, Vega-Lite, vega-embed (inlined into `rtcost report` pages by the build) and
# playwright-core, at the versions third_party/js/package-lock.json pins, into
# third_party/js/node_modules (ignored by git); skipped when that install is of the current lock.
js="$(cd "$(dirname "$0")/.." && pwd)/third_party/js"
lock_sum="$(sha256sum "$js/package-lock.json" | cut -d' ' -f1)"
if [ "$(cat "$js/node_modules/.rtcost-lock" 2>/dev/null)" != "$lock_sum" ]; then
  echo "install-deps: npm ci in third_party/js"
  (cd "$js" && npm ci --no-audit --no-fund --loglevel=error)
  echo "$lock_sum" > "$js/node_modules/.rtcost-lock"
else
  echo "install-deps: third_party/js/node_modules is current"
fi
