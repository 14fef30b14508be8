#!/usr/bin/env bash
# One command from a fresh Debian machine to a result: installs the dependencies, builds rtcost,
# makes the Python module importable by /usr/bin/python3, and runs the main job on a built-in
# scene (no files needed).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
bash scripts/install-python.sh
./build/rtcost info builtin:balls
./build/rtcost eval builtin:balls --rays camera --size 256x256
