#!/usr/bin/env python3
"""Friction's part in a pose log (issue 46): the same servo state reached at
different times, and so from different directions, at different tip
positions, against what each model gives there.

A frictionless arm at rest has one pose per input state, so its tip is the
same wherever the state recurs; friction in the holes keeps part of the
earlier motion (hysteresis), and the measured tip differs. For every pair of
frames whose tendon inputs agree to --tolerance-mm (largest difference over
the tendons) while the inputs travelled at least --travel-mm in between
(not two frames of one hold), the script compares the measured difference of
the tip between the two frames with each model's (fit or prediction folders
of `ccsrm identify` / `ccsrm predict`, their <name>.points.csv):

  measured |dp|   the tip's displacement between the two visits [mm]
  model |dp|      the same for the model's tip
  miss            RMS of (model dp - measured dp) over the pairs [mm]: what the
                  model leaves of the hysteresis (a model without any leaves
                  the measured |dp| itself)

Usage:
  scripts/tdcr_hysteresis.py --data val.h5 --model frictionless=predF0 \\
      --model friction=predF1 [--tolerance-mm 0.05] [--travel-mm 2]
"""
import argparse
import csv
import pathlib
import sys

import h5py
import numpy as np


def read_points(folder, stem):
    """time [s] and the first tracked point's measured and model positions
    [mm] from a fit or prediction folder's points CSV."""
    path = pathlib.Path(folder) / f"{stem}.points.csv"
    if not path.exists():
        sys.exit(f"{path}: no points file (a fit or prediction folder of tracked points?)")
    with open(path, newline="") as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith("#"))]
    header, rows = rows[0], rows[1:]
    model_kind = "fitted" if any(h.startswith("fitted_") for h in header) else "predicted"
    measured = [i for i, h in enumerate(header) if h.startswith("measured_")][:3]
    model = [i for i, h in enumerate(header) if h.startswith(model_kind + "_")][:3]
    if len(measured) != 3 or len(model) != 3:
        sys.exit(f"{path}: expected measured_ and {model_kind}_ columns of a point")

    def column(indices):
        return np.array([[float(r[i]) if r[i] else np.nan for i in indices] for r in rows])

    time = np.array([float(r[0]) for r in rows])
    return time, column(measured), column(model)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", required=True, help="the recording (ccsrm-dataset/1)")
    parser.add_argument("--model", action="append", required=True,
                        help="NAME=FOLDER, a fit or prediction folder of the recording")
    parser.add_argument("--tolerance-mm", type=float, default=0.05,
                        help="inputs that agree to this are one servo state (default 0.05)")
    parser.add_argument("--travel-mm", type=float, default=2.0,
                        help="least input path between the two visits (default 2)")
    args = parser.parse_args()

    with h5py.File(args.data, "r") as f:
        stem = f.attrs.get("name", pathlib.Path(args.data).stem)
        stem = stem.decode() if isinstance(stem, bytes) else str(stem)
        input_time = f["input/time"][:]
        inputs_mm = f["input/length_change"][:] * 1e3
    models = {}
    for spec in args.model:
        name, _, folder = spec.partition("=")
        if not folder:
            sys.exit(f"--model {spec}: expected NAME=FOLDER")
        models[name] = read_points(folder, stem)
    time = next(iter(models.values()))[0]
    # The CSV's times are rounded to the microsecond.
    rows = np.abs(input_time[None, :] - time[:, None]).argmin(axis=1)
    if np.any(np.abs(input_time[rows] - time) > 1e-5):
        sys.exit(f"{args.data}: the frames are not at input samples (a pose log's are)")
    u = inputs_mm[rows]
    # Input path travelled up to each frame.
    path = np.concatenate([[0.0], np.cumsum(np.abs(np.diff(u, axis=0)).max(axis=1))])

    pairs = []
    for i in range(len(u)):
        close = np.abs(u[i + 1:] - u[i]).max(axis=1) <= args.tolerance_mm
        far = path[i + 1:] - path[i] >= args.travel_mm
        pairs += [(i, i + 1 + j) for j in np.flatnonzero(close & far)]
    if not pairs:
        print(f"no servo state recurs within {args.tolerance_mm} mm after {args.travel_mm} mm "
              "of travel")
        return
    i, j = np.array(pairs).T
    measured = next(iter(models.values()))[1]
    d_measured = measured[j] - measured[i]
    ok = np.isfinite(d_measured).all(axis=1)
    print(f"{args.data}: {ok.sum()} pairs of frames at one servo state (inputs within "
          f"{args.tolerance_mm} mm, {args.travel_mm} mm or more of travel between them), "
          f"{len(set(i[ok]) | set(j[ok]))} frames")
    size = np.linalg.norm(d_measured[ok], axis=1)
    print(f"  measured |dp|: median {np.median(size):.2f} mm, RMS "
          f"{np.sqrt(np.mean(size ** 2)):.2f} mm, largest {size.max():.2f} mm")
    for name, (_, _, model) in models.items():
        d_model = model[j] - model[i]
        valid = ok & np.isfinite(d_model).all(axis=1)
        model_size = np.linalg.norm(d_model[valid], axis=1)
        miss = np.sqrt(np.mean(np.sum((d_model[valid] - d_measured[valid]) ** 2, axis=1)))
        unexplained = np.sqrt(np.mean(np.sum(d_measured[valid] ** 2, axis=1)))
        print(f"  {name}: model |dp| median {np.median(model_size):.2f} mm; miss {miss:.2f} mm "
              f"RMS against {unexplained:.2f} mm with no hysteresis ({valid.sum()} pairs)")


if __name__ == "__main__":
    main()
