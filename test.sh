#!/usr/bin/env bash
# Set-up if needed, build (Release), then the whole test suite with ctest.
#   ./test.sh                      # everything CI runs
#   ./test.sh -L validation        # the long physics validations (extra ctest arguments are
#                                  # passed through; without any, validations are left out)
#   ./test.sh --sanitize [ARGS]    # the same suite built with ASan + UBSan (RelWithDebInfo) in
#                                  # build-sanitize/ (DRAGLAB_BUILD_DIR overrides); any report
#                                  # fails the test. Tests that cannot run instrumented are
#                                  # disabled there, each with the reason (tests/*/CMakeLists.txt).
#   ./test.sh --sanitize-fast      # the same, for the input-handling tests only (ctest label
#                                  # `inputs`: parsers, database, bindings, bad-input matrix),
#                                  # building only what they need; CI runs it after the suite.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
if [ "${1:-}" = "--sanitize-fast" ]; then
  shift
  export DRAGLAB_BUILD_TARGET=input_tests
  if [ "$#" -eq 0 ]; then set -- -L inputs -LE validation; fi
  set -- --sanitize "$@"
fi
if [ "${1:-}" = "--sanitize" ]; then
  shift
  export DRAGLAB_SANITIZE=1
  export DRAGLAB_BUILD_DIR="${DRAGLAB_BUILD_DIR:-$here/build-sanitize}"
  # Every report stops the process with a stack trace (UB included); leaks are reports too.
  export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1}"
  export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
fi
"$here/scripts/setup.sh"
jobs="$(nproc 2>/dev/null || echo 2)"
if [ "$#" -eq 0 ]; then set -- -LE validation; fi
# ctest runs tests side by side, each with OpenMP threads: threads that spin at barriers while
# their core is taken by another test slow the DEM/DPM tests down by up to 10x (measured), so
# waiting threads sleep instead.
export OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-passive}"
ctest --test-dir "${DRAGLAB_BUILD_DIR:-$here/build}" --output-on-failure -j "$jobs" "$@"
