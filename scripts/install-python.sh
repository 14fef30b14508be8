#!/usr/bin/env bash
# Makes the Python module `rtcost` built in build/python importable by Debian's /usr/bin/python3:
# a rtcost.pth in its site directory (/usr/local/lib/python3.X/dist-packages) naming build/python,
# so a rebuild needs no reinstall. Other interpreters (pyenv, venvs) do not read that directory;
# run /usr/bin/python3, or set PYTHONPATH=build/python (see README).
set -euo pipefail
cd "$(dirname "$0")/.."
python=/usr/bin/python3
if [ ! -f build/python/rtcost/__init__.py ]; then
  echo "install-python: build/python/rtcost is not built (RTCOST_BUILD_PYTHON off?); skipped" >&2
  exit 0
fi
site=$("$python" -c "import site; print(site.getsitepackages()[0])")
sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
$sudo mkdir -p "$site"
echo "$(pwd)/build/python" | $sudo tee "$site/rtcost.pth" > /dev/null
"$python" -c "import rtcost" && echo "install-python: $python imports rtcost from $(pwd)/build/python ($site/rtcost.pth)"
