#!/usr/bin/env bash
# The main job on the bundled configuration: installs what is missing, builds,
# checks the paper configuration, simulates the paper's case 2 (+6 degrees,
# 48 s, friction on every cable), prints its summary, inspects the run file
# it wrote and makes its report (out/case2-report/index.html). Outputs go to
# ./out.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
mkdir -p out
./build/app/ccsrm config check configs/paper.yaml
./build/app/ccsrm simulate --config configs/paper.yaml --case 2 --out out/case2.h5
./build/app/ccsrm dataset inspect out/case2.h5
./build/app/ccsrm report --in out/case2.h5 --out out/case2-report
