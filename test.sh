#!/usr/bin/env bash
# Set-up if needed, build (Release), then the whole test suite with ctest.
#   ./test.sh                      # everything CI runs
#   ./test.sh -L validation        # the long physics validations (extra ctest arguments are
#                                  # passed through; without any, validations are left out)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
"$here/scripts/setup.sh"
jobs="$(nproc 2>/dev/null || echo 2)"
if [ "$#" -eq 0 ]; then set -- -LE validation; fi
# ctest runs tests side by side, each with OpenMP threads: threads that spin at barriers while
# their core is taken by another test slow the DEM/DPM tests down by up to 10x (measured), so
# waiting threads sleep instead.
export OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-passive}"
ctest --test-dir "${DRAGLAB_BUILD_DIR:-$here/build}" --output-on-failure -j "$jobs" "$@"
