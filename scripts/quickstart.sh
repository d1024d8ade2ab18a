#!/usr/bin/env bash
# The main job on the bundled configuration: installs what is missing, builds,
# checks the paper configuration, simulates the paper's case 3 (+6 degrees,
# 48 s) and inspects the run file it wrote. Outputs go to ./out.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
mkdir -p out
./build/app/ccsrm config check configs/paper.yaml
./build/app/ccsrm simulate --config configs/paper.yaml --case 3 --out out/case3.h5
./build/app/ccsrm dataset inspect out/case3.h5
