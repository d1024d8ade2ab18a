#!/usr/bin/env bash
# Installs what is missing, builds, and runs the default test suite (every
# test not labelled `slow`). The long validations: scripts/test.sh --slow.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
if [ "${1:-}" = "--slow" ]; then
  ctest --test-dir build -L slow --output-on-failure
else
  ctest --test-dir build -LE slow --output-on-failure -j"$(nproc)"
fi
