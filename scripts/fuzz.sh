#!/usr/bin/env bash
# Builds the libFuzzer harnesses (clang, ASan + UBSan) in build-asan/ (the build that
# scripts/sanitize.sh makes for the tests) and runs each for SECONDS (default 60) on one core,
# starting from fuzz/corpus/<name>/. Findings go to build-asan/findings/ and fail the script.
# Long run: scripts/fuzz.sh 3600 (an hour each), or one harness: FUZZERS=trace scripts/fuzz.sh
# 36000. New corpus entries stay in build-asan/corpus/ (copy small interesting ones into
# fuzz/corpus/ by hand). FUZZ_SEED=N fixes libFuzzer's seed: the same inputs in the same order
# on every machine (CI uses it, so that its result does not depend on the draw; long runs draw
# a new seed each time to explore further).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
fuzzers="${FUZZERS:-nff mesh rays params trace}"
b=build-asan
export CCACHE_NOHASHDIR=1
flags="-fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=all -fsanitize=fuzzer-no-link"
if [ ! -f $b/build.ninja ]; then  # the same configuration as scripts/sanitize.sh
  CC=clang CXX=clang++ cmake -S . -B $b -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only -DNDEBUG" \
    -DCMAKE_CXX_FLAGS="$flags" -DRTCOST_FUZZ=ON -DRTCOST_BUILD_BENCH=OFF -DRTCOST_BUILD_PYTHON=OFF \
    $(command -v ccache >/dev/null && echo -DCMAKE_CXX_COMPILER_LAUNCHER=ccache) > /dev/null
fi
targets=""
for f in $fuzzers; do targets="$targets fuzz_$f"; done
cmake --build $b -j "${JOBS:-2}" --target $targets
mkdir -p $b/findings
status=0
export ASAN_OPTIONS="detect_leaks=0:allocator_may_return_null=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
for f in $fuzzers; do
  mkdir -p "$b/corpus/$f"
  echo "fuzz: $f for ${seconds}s"
  if ! $b/fuzz/fuzz_$f ${FUZZ_SEED:+-seed=$FUZZ_SEED} -max_total_time="$seconds" -timeout=120 -rss_limit_mb=3072 -max_len=4096 \
      -artifact_prefix="$b/findings/$f-" -print_final_stats=1 \
      "$b/corpus/$f" "fuzz/corpus/$f" 2> "$b/fuzz-$f.log"; then
    echo "fuzz: $f FOUND a problem ($b/fuzz-$f.log, $b/findings/)"; tail -40 "$b/fuzz-$f.log"
    status=1
  fi
  grep -E "stat::number_of_executed_units|Done [0-9]+ runs" "$b/fuzz-$f.log" | tail -1 || true
done
exit $status
