#!/usr/bin/env python3
"""Each effect's fingerprint (issue 12, docs/model-notes.md "Effect fingerprints").

Simulates the paper's cases (+6 deg, full protocol) with each effect alone at
its realistic magnitude (ccsrm generate --list-effects) and compares the
joint angles with the nominal run: which joints and axes the residual
touches, how much of its time-varying part a per-joint linear fit on each
candidate regressor explains (joint rate, sign of the joint rate, angle,
time, input rate), and its RMS against the 0.03 deg mocap floor.

Usage: scripts/effect_fingerprints.py BUILD_DIR OUT_DIR [--cases 1 2 3 4] [--duration S]
"""
import argparse
import json
import os
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

import h5py
import numpy as np

FLOOR_DEG = 0.03


def run(ccsrm, config, case, duration, params, out):
    if os.path.exists(out):
        return out
    cmd = [ccsrm, "simulate", "--config", config, "--case", str(case), "--quiet", "--out", out]
    if duration:
        cmd += ["--duration", str(duration)]
    if params:
        cmd += ["--params", params]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return out


def load(path):
    with h5py.File(path, "r") as f:
        return {k: f[k][()] for k in ("time", "joint_angles", "joint_rates", "input_length_change")}


def explained(residual, regressor):
    """Share of the residual's variance (about each joint-axis mean) that a
    per-joint-axis fit r = a x + b explains, and the sign of the dominant a."""
    ss_tot = ss_res = 0.0
    signed = 0.0
    for j in range(residual.shape[1]):
        for a in range(residual.shape[2]):
            r = residual[:, j, a] - residual[:, j, a].mean()
            x = regressor[:, j, a] - regressor[:, j, a].mean()
            tot = float(r @ r)
            if tot == 0.0:
                continue
            xx = float(x @ x)
            slope = float(r @ x) / xx if xx > 0 else 0.0
            res = r - slope * x
            ss_tot += tot
            ss_res += float(res @ res)
            signed += slope * xx * abs(slope)
    if ss_tot == 0.0:
        return 0.0, 0
    return 1.0 - ss_res / ss_tot, int(np.sign(signed))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("build")
    ap.add_argument("out")
    ap.add_argument("--cases", type=int, nargs="+", default=[1, 2, 3, 4])
    ap.add_argument("--duration", type=float, default=0.0)
    ap.add_argument("--config", default=os.path.join(os.path.dirname(__file__), "..", "configs", "paper.yaml"))
    ap.add_argument("--threads", type=int, default=2)
    args = ap.parse_args()
    ccsrm = os.path.join(args.build, "app", "ccsrm")
    os.makedirs(args.out, exist_ok=True)
    listing = json.loads(subprocess.run([ccsrm, "generate", "--list-effects", "--json"], check=True,
                                        capture_output=True, text=True).stdout)["effects"]
    params = {}
    for e in listing:
        path = os.path.join(args.out, e["name"] + ".yaml")
        with open(path, "w") as f:
            f.write("effects:\n  %s:\n" % e["name"])
            for p in e["parameters"]:
                f.write("    %s: %r\n" % (p["name"].split(".", 1)[1], p["realistic"]))
        params[e["name"]] = (path, e["measurement"],
                             {p["name"].split(".", 1)[1]: p["realistic"] for p in e["parameters"]})
    jobs = []
    for case in args.cases:
        jobs.append((case, None, None))
        for name, (path, measurement, _) in params.items():
            if not measurement:
                jobs.append((case, name, path))
    with ThreadPoolExecutor(args.threads) as pool:
        futures = {(c, n): pool.submit(run, ccsrm, args.config, c, args.duration, p,
                                       os.path.join(args.out, "case%d_%s.h5" % (c, n or "nominal")))
                   for c, n, p in jobs}
        for f in futures.values():
            f.result()
    deg = 180.0 / np.pi
    rows = []
    for case in args.cases:
        nominal = load(os.path.join(args.out, "case%d_nominal.h5" % case))
        t = nominal["time"]
        theta = nominal["joint_angles"]
        rate = nominal["joint_rates"]
        # Input rate of the cable driving each joint's segment in +θx (cables 2 and 4 pull
        # segment 1 and 2 the same way as the plan), broadcast over joints and axes.
        dl = np.gradient(nominal["input_length_change"], t, axis=0)
        input_rate = np.zeros_like(theta)
        input_rate[:, :6, :] = dl[:, 1][:, None, None]
        input_rate[:, 6:, :] = dl[:, 3][:, None, None]
        regressors = {
            "rate": rate,
            "sign of rate": np.tanh(rate / 1e-3),
            "angle": theta,
            "time": np.broadcast_to(t[:, None, None], theta.shape),
            "input rate": input_rate,
        }
        for name, (path, measurement, values) in params.items():
            if measurement:
                offsets = np.zeros(theta.shape[1:])
                for j in range(theta.shape[1]):
                    for a, axis in enumerate("xy"):
                        offsets[j, a] = values.get("joint%d_%s_rad" % (j + 1, axis), 0.0)
                residual = np.broadcast_to(offsets, theta.shape).copy()
            else:
                other = load(os.path.join(args.out, "case%d_%s.h5" % (case, name)))
                residual = other["joint_angles"] - theta
            rms_ja = np.sqrt((residual ** 2).mean(axis=0)) * deg  # 12 x 2
            const = np.sqrt((residual.mean(axis=0) ** 2).mean()) * deg
            fits = {k: explained(residual, x) for k, x in regressors.items()}
            rows.append({
                "case": case, "effect": name,
                "rms_deg": float(np.sqrt((residual ** 2).mean()) * deg),
                "rms_x_deg": float(np.sqrt((residual[:, :, 0] ** 2).mean()) * deg),
                "rms_y_deg": float(np.sqrt((residual[:, :, 1] ** 2).mean()) * deg),
                "max_deg": float(np.abs(residual).max() * deg),
                "constant_rms_deg": float(const),
                "per_joint_x_deg": [round(float(v), 5) for v in rms_ja[:, 0]],
                "per_joint_y_deg": [round(float(v), 5) for v in rms_ja[:, 1]],
                "explained": {k: [round(v[0], 3), v[1]] for k, v in fits.items()},
            })
            print("case %d %-17s RMS %.4f deg (x %.4f, y %.4f, max %.4f, constant %.4f) %s" % (
                case, name, rows[-1]["rms_deg"], rows[-1]["rms_x_deg"], rows[-1]["rms_y_deg"],
                rows[-1]["max_deg"], const,
                " ".join("%s %.2f%+d" % (k, v[0], v[1]) for k, v in fits.items())))
    with open(os.path.join(args.out, "fingerprints.json"), "w") as f:
        json.dump(rows, f, indent=1)


if __name__ == "__main__":
    sys.exit(main())
