#!/usr/bin/env bash
# ctest's ReportInBrowser: writes a report with the rtcost under test and checks it in headless
# Chromium (report_page.cjs). Exits 77 (ctest: skipped) with a message when Chromium, Node.js or
# the npm packages are absent; scripts/install-deps.sh installs all three.
# Usage: run_report_page.sh RTCOST SOURCE_DIR OUT_DIR
set -euo pipefail
rtcost="$1" src="$2" out="$3"
chromium="$(command -v "${RTCOST_CHROMIUM:-chromium}" || true)"
skip() { echo "SKIPPED: $1 (scripts/install-deps.sh installs it)"; exit 77; }
[ -n "$chromium" ] || skip "no chromium on PATH"
command -v node > /dev/null || skip "no node on PATH"
[ -d "$src/third_party/js/node_modules/playwright-core" ] || skip "no third_party/js/node_modules/playwright-core"
mkdir -p "$out"
SECONDS=0
"$rtcost" report builtin:balls:3 -H bvh-sah,kd-sah,grid,octree,rc5d --size 64x64 --heatmap-size 96x96 -q \
  -o "$out/report.html"
node "$src/tests/browser/report_page.cjs" "$out/report.html" "$out/report.png" "$chromium"
echo "ReportInBrowser: ${SECONDS} s in all"
