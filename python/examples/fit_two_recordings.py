#!/usr/bin/env python3
"""Fits friction, damping and pre-tension to two recordings at once and
prints the table of estimates.

    PYTHONPATH=build/python python3 python/examples/fit_two_recordings.py \
        exp1.h5 exp2.h5 --free T_p,mu_c --set mu=0 --set mu_s=0
"""
import argparse
import math

import ccsrm


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("recordings", nargs=2, help="two ccsrm-dataset/1 files")
    parser.add_argument("--free", default="T_p", help="parameters to fit, comma-separated")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    parser.add_argument("--max-iterations", type=int, default=30)
    parser.add_argument("--threads", type=int, default=ccsrm.default_threads())
    parser.add_argument("--out", help="also write the fit folder here")
    args = parser.parse_args()

    def progress(p):
        values = ", ".join(f"{name}={value:.6g}" for name, value in p["values"].items())
        print(f"  iteration {p['iteration']}: RMS {p['rms_deg']:.4f} deg, {values}", flush=True)

    fit = ccsrm.identify(args.recordings, free=args.free, set=args.set,
                         max_iterations=args.max_iterations, threads=args.threads, out=args.out,
                         progress=progress)
    print(f"{fit.termination} after {fit.iterations} iterations, {fit.simulations} simulations, "
          f"RMS {fit.rms_deg:.4f} deg")
    print(f"{'parameter':<12}{'start':>12}{'estimate':>14}{'std error':>12}  units")
    for p in fit.parameters:
        if not p.free:
            continue
        error = "-" if math.isnan(p.std_error) else f"{p.std_error:.4g}"
        print(f"{p.name:<12}{p.start:>12.6g}{p.value:>14.6g}{error:>12}  {p.units}"
              f"{'  (at bound)' if p.at_bound else ''}")
    return 0 if fit.converged else 4


if __name__ == "__main__":
    raise SystemExit(main())
