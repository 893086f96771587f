#!/usr/bin/env bash
# Set-up if needed, build (Release), then the main job on the default database
# ($DRAGLAB_DB, else ./draglab.db, created and seeded with the literature library on first use).
#   ./run.sh                       # the quick pipeline: LBM campaign -> dataset -> fit of Eq. 6
#                                  # -> published law -> report (a few minutes on 2 cores)
#   ./run.sh law eval bvk2007 --phi 0.3 --re 50     # any other draglab command
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
"$here/scripts/setup.sh" >&2
draglab="${DRAGLAB_BUILD_DIR:-$here/build}/cli/draglab"
if [ "$#" -eq 0 ]; then
  exec "$draglab" pipeline --preset quick
fi
exec "$draglab" "$@"
