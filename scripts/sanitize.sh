#!/usr/bin/env bash
# Sanitizer builds of the test suite (called by .ci/run):
#  1. build-asan/: clang with AddressSanitizer + UndefinedBehaviorSanitizer (and the fuzzers'
#     coverage instrumentation, so that scripts/fuzz.sh reuses this build). The whole suite runs
#     except the SPD-wide suites (every SPD scene through every hierarchy: those run in the
#     Release suite; the built-in, adversarial and reliability scenes exercise the same code).
#  2. build-tsan/: clang with ThreadSanitizer: multi-threaded tracing through every hierarchy,
#     the lazily grown rc5d included, and the rc5d suites.
# Any sanitizer report fails the script. JOBS=N sets the build jobs (default 2).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="${JOBS:-2}"
launcher=$(command -v ccache >/dev/null && echo -DCMAKE_CXX_COMPILER_LAUNCHER=ccache || true)
export CCACHE_NOHASHDIR=1
t() { echo $(( $(date +%s) - $1 )); }

# Configures a clang build in $1 with sanitizer flags $2 and extra CMake options after.
configure() {
  local dir="$1" flags="$2"; shift 2
  [ -f "$dir/build.ninja" ] || CC=clang CXX=clang++ cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS="$flags" -DRTCOST_BUILD_BENCH=OFF $launcher "$@" > /dev/null
}

asan="-fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=all -fsanitize=fuzzer-no-link"
configure build-asan "$asan" -DRTCOST_FUZZ=ON
start=$(date +%s)
cmake --build build-asan -j "$jobs" --target rtcost_tests rtcost_cli
echo "sanitize: asan build $(t "$start") s"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
slow="*Spd*:SceneCheck*:ModelExactness.*:AdversarialBounds.SpdScenesAreNotLimited"
start=$(date +%s)
build-asan/tests/rtcost_tests --gtest_filter="-$slow" --gtest_brief=1
echo "sanitize: asan tests $(t "$start") s"

# ThreadSanitizer needs a build of its own (about six minutes on two cores): CI skips it to stay
# within its time (RTCOST_TSAN=0 in .ci/run); run it with RTCOST_TSAN=1 (the default here).
if [ "${RTCOST_TSAN:-1}" = 0 ]; then
  echo "sanitize: ThreadSanitizer skipped (RTCOST_TSAN=0)"
  exit 0
fi
tsan="-fsanitize=thread"
configure build-tsan "$tsan"
start=$(date +%s)
cmake --build build-tsan -j "$jobs" --target rtcost_tests rtcost_cli
echo "sanitize: tsan build $(t "$start") s"
export TSAN_OPTIONS="halt_on_error=1:suppressions=$PWD/scripts/tsan.supp"
start=$(date +%s)
build-tsan/tests/rtcost_tests --gtest_filter="Reliability.Threaded*:Rc5dBuild.*:Rc5dHits.*" --gtest_brief=1
echo "sanitize: tsan tests $(t "$start") s"
