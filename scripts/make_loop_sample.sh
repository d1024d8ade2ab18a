#!/usr/bin/env bash
# Regenerates the bundled loop sample (datasets/samples/loop/README.md): two
# training experiments and one held-out experiment of the paper's arm on the
# sample's 9 s protocol, with backlash in the connecting cables (a 2 mrad
# dead band, the effect library's realistic magnitude) that the nominal
# configuration does not declare. The truth side files go to truth/, apart
# from the data the loop reads; the truth runs (*.truth.h5, 3 MB each) are
# not kept.
set -euo pipefail
cd "$(dirname "$0")/.."
dir=datasets/samples/loop
ccsrm=./build/app/ccsrm
mkdir -p "$dir/truth"
for spec in "train1 6 21" "train2 -4 22" "holdout 5 23"; do
  set -- $spec
  $ccsrm generate --config "$dir/arm.yaml" --amplitude "$2" --seed "$3" --resolution-mm 0.1 \
    --effect backlash --quiet --out "$dir/$1.h5"
  mv "$dir/$1.truth.yaml" "$dir/truth/$1.truth.yaml"
  rm -f "$dir/$1.truth.h5"
done
ls -la "$dir" "$dir/truth"
