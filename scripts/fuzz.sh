#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ (clang-14, -DDRAGLAB_FUZZ=ON) into their own build
# directory and runs one of them for SECONDS on a seed corpus made from data/ (and fuzz/seeds/).
#
#   scripts/fuzz.sh TARGET SECONDS [libFuzzer options...]
#   scripts/fuzz.sh --list
#
# TARGET: campaign_spec, scene, dataset_csv, packing_hdf5, law_reference (fuzz/README.md).
# Findings (crash-*, leak-*, timeout-*, oom-* files: the input that triggers them) go to
# build-fuzz/crashes/TARGET/; reproduce one with build-fuzz/fuzz/fuzz_TARGET FILE. The corpus the
# fuzzer grows stays in build-fuzz/corpus/TARGET/ (kept between runs); the seeds are copied anew
# into build-fuzz/seeds/TARGET/ each run. Logs: build-fuzz/logs/TARGET.log.
#
# By default the run goes on after a finding (libFuzzer -fork=1 with -ignore_crashes,
# -ignore_timeouts, -ignore_ooms), so that one run collects every finding; set
# DRAGLAB_FUZZ_STOP=1 to stop at the first one instead. Other settings: DRAGLAB_FUZZ_BUILD_DIR
# (default build-fuzz), DRAGLAB_FUZZ_JOBS (build jobs, default min(nproc, 2)).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
targets=(campaign_spec scene dataset_csv packing_hdf5 law_reference)

usage() {
  echo "usage: scripts/fuzz.sh TARGET SECONDS [libFuzzer options...]  (TARGET: ${targets[*]})" >&2
  exit 2
}
if [ "${1:-}" = "--list" ]; then
  printf '%s\n' "${targets[@]}"
  exit 0
fi
[ "$#" -ge 2 ] || usage
target="$1"
seconds="$2"
shift 2
[[ " ${targets[*]} " == *" $target "* ]] || usage
[[ "$seconds" =~ ^[0-9]+$ ]] || usage

build="${DRAGLAB_FUZZ_BUILD_DIR:-$here/build-fuzz}"
jobs="${DRAGLAB_FUZZ_JOBS:-$(nproc 2>/dev/null || echo 2)}"
if [ -z "${DRAGLAB_FUZZ_JOBS:-}" ] && ((jobs > 2)); then jobs=2; fi

# ---- packages: the project's (scripts/setup.sh) and clang's fuzzing toolchain --------------------
# clang-14 and libFuzzer; the sanitizer and fuzzer runtimes (libclang-rt-14-dev) and clang's
# OpenMP (libomp-14-dev; consumers/ needs OpenMP) are only recommended/suggested by clang-14.
DRAGLAB_EXTRA_PACKAGES="clang-14 libfuzzer-14-dev libclang-rt-14-dev libomp-14-dev" \
  "$here/scripts/setup.sh" --no-build

# ---- build: only the fuzz targets and what they link ---------------------------------------------
if [ ! -f "$build/CMakeCache.txt" ]; then
  CC=clang-14 CXX=clang++-14 cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DDRAGLAB_FUZZ=ON -DDRAGLAB_BUILD_TESTS=OFF -DDRAGLAB_BUILD_BENCH=OFF \
    -DDRAGLAB_BUILD_FORTRAN=OFF >/dev/null
fi
build_targets=("fuzz_$target")
[ "$target" = packing_hdf5 ] && build_targets+=(fuzz_packing_seeds)
cmake --build "$build" -j "$jobs" --target "${build_targets[@]}"

# ---- seed corpus and dictionary ---------------------------------------------------------------
seeds="$build/seeds/$target"
corpus="$build/corpus/$target"
crashes="$build/crashes/$target"
dict="$build/seeds/$target.dict"
rm -rf "$seeds"
mkdir -p "$seeds" "$corpus" "$crashes" "$build/logs"
: >"$dict"
# TOML: the section headers and keys of the seeds, as dictionary entries.
toml_dict() {
  grep -ohE '^\[[a-z_0-9]+\]|^[a-z_0-9]+ *=' "$@" | sed -E 's/ *=$//' | sort -u |
    sed -E 's/.*/"&"/' >>"$dict"
  printf '%s\n' '"="' '"["' '"]"' '"\""' '"true"' '"false"' '"1e308"' '"nan"' '"inf"' \
    '"-0.0"' '"\"\"\""' >>"$dict"
}
case "$target" in
  campaign_spec)
    cp "$here"/data/campaigns/*.toml "$seeds/"
    toml_dict "$seeds"/*.toml
    ;;
  scene)
    cp "$here"/data/scenes/*.toml "$here"/tests/cli/data/*.toml "$seeds/"
    toml_dict "$seeds"/*.toml
    ;;
  dataset_csv)
    cp "$here"/data/datasets/*/*.csv "$here"/fuzz/seeds/dataset_csv/*.csv "$seeds/"
    # The column names of the format (dataset.h), as dictionary entries.
    head -n 2 "$here/fuzz/seeds/dataset_csv/all_columns.csv" | tail -n 1 | tr ',' '\n' |
      sed -E 's/.*/"&"/' >>"$dict"
    printf '%s\n' '","' '";"' '"#"' '"\x0D\x0A"' '"1e308"' '"nan"' '"inf"' '"-0"' '"0x1p-1074"' \
      >>"$dict"
    ;;
  packing_hdf5)
    "$build/fuzz/fuzz_packing_seeds" "$seeds"
    printf '%s\n' '"packing"' '"centers"' '"radii"' '"box_length"' '"generator"' '"settings"' \
      '"seed"' >>"$dict"
    ;;
  law_reference)
    # One reference per file: the hand-made list and the laws of the shipped scenes.
    {
      grep -vE '^(#|$)' "$here/fuzz/seeds/law_reference/references.txt"
      grep -ohE '"[a-z_0-9]+@[a-z0-9]+"' "$here"/data/scenes/*.toml | tr -d '"'
    } | sort -u | {
      i=0
      while IFS= read -r ref; do
        printf '%s' "$ref" >"$seeds/ref_$i"
        i=$((i + 1))
      done
    }
    printf '%s\n' '"@"' '"latest"' '"fuzzlaw"' '"gidaspow"' '"bvk2007"' >>"$dict"
    ;;
esac
# Inputs of earlier findings (fuzz/regressions/TARGET_*) are seeds too: they must stay clean.
for f in "$here/fuzz/regressions/${target}"_*; do
  [ -f "$f" ] && cp "$f" "$seeds/"
done
echo "fuzz: $(find "$seeds" -type f | wc -l) seed files, corpus $corpus" >&2

# ---- run ------------------------------------------------------------------------------------------
options=(-max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1
         -artifact_prefix="$crashes/" -dict="$dict")
if [ "${DRAGLAB_FUZZ_STOP:-0}" != 1 ]; then
  options+=(-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1)
fi
# UB stops the program (a finding, not a warning); stack traces for every report.
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1}"
export OMP_NUM_THREADS="${OMP_NUM_THREADS:-1}"
log="$build/logs/$target.log"
echo "fuzz: running fuzz_$target for $seconds s, log $log, findings in $crashes/" >&2
cd "$build"  # fork mode writes its temporary files next to the working directory
set +e
"$build/fuzz/fuzz_$target" "${options[@]}" "$@" "$corpus" "$seeds" 2>&1 | tee "$log" |
  grep -E '^#[0-9]+.*(DONE|pulse)|INFO: fuzzed for|==ERROR|SUMMARY|finding|Test unit written|^stat::'
status=${PIPESTATUS[0]}
set -e
found=$(find "$crashes" -type f | wc -l)
echo "fuzz: fuzz_$target exited with $status; $found finding file(s) in $crashes/" >&2
exit "$status"
