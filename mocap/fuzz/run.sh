#!/bin/sh
# Runs the three fuzzers (C3D, marker text files, actuator map and log) for a bounded time with the vendor files of
# ../shared/data/mocap (and seeds/) as the seed corpus, copied to a fresh
# temporary directory so the shared files are never modified.
#
#   mocap/fuzz/run.sh BUILD_DIR [SECONDS]      (default 60 s per fuzzer)
#
# BUILD_DIR is a build configured with -DCCSRM_BUILD_FUZZERS=ON and clang
# (see README.md). Crash inputs are kept in the printed work directory.
set -eu
build=${1:?usage: run.sh BUILD_DIR [SECONDS]}
seconds=${2:-60}
here=$(cd "$(dirname "$0")" && pwd)
shared=${CCSRM_SHARED_DIR:-$here/../../../shared}
work=$(mktemp -d "${TMPDIR:-/tmp}/ccsrm_fuzz.XXXXXX")
mkdir -p "$work/c3d" "$work/text" "$work/actuators" "$work/crashes"
cp "$shared"/data/mocap/c3d/*.c3d "$work/c3d/"
# The first 20 kB of each text file hold its header and first rows.
for f in "$shared"/data/mocap/text/*; do
  head -c 20000 "$f" > "$work/text/$(basename "$f")"
done
cp "$here"/seeds/* "$work/text/"
cp "$here"/actuator_seeds/* "$work/actuators/"
chmod -R u+w "$work"
echo "work directory: $work"

status=0
"$build/mocap/fuzz/ccsrm_c3d_fuzzer" "$work/c3d" -max_total_time="$seconds" -max_len=65536 \
  -rss_limit_mb=4096 -artifact_prefix="$work/crashes/c3d-" -print_final_stats=1 || status=1
"$build/mocap/fuzz/ccsrm_text_fuzzer" "$work/text" -max_total_time="$seconds" -max_len=20000 \
  -rss_limit_mb=4096 -artifact_prefix="$work/crashes/text-" -print_final_stats=1 || status=1
"$build/mocap/fuzz/ccsrm_actuator_fuzzer" "$work/actuators" -max_total_time="$seconds" \
  -max_len=4096 -rss_limit_mb=4096 -artifact_prefix="$work/crashes/actuator-" \
  -print_final_stats=1 || status=1
ls -l "$work/crashes"
exit $status
