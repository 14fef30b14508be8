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
  pybind11-dev python3-dev           # the Python module (Debian's /usr/bin/python3)
  python3-numpy python3-pandas python3-pytest
  python3-dask python3-distributed   # sweeps
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed"
  exit 0
fi

sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
echo "install-deps: installing ${missing[*]}"
$sudo apt-get update -q
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
