#!/usr/bin/env python3
"""Scan one parameter finely over a motion and say whether the joint angles
jump or are smooth but steep in it (issue 43, docs/model-notes.md "Fast
reversals at static above kinetic friction").

    PYTHONPATH=build/python python3 scripts/scan_parameter.py \\
        --protocol configs/protocols/fast-reversals.yaml --case 2 \\
        --set mu_s=0.25 --set mu_c_s=0.25 --parameter mu_c --points 41 --span 0.02 \\
        --out scan_mu_c

Runs the arm at `points` values over +-span (relative) on two threads, fits a
least-squares cubic in the parameter to every sampled angle (every frame,
joint and axis), and prints: the residual against the angles' variation; the
change between neighbouring values (a jump shows as one step far above the
others); where in time and at which joints the residual sits; the angle the
cubic fits worst, across the scan; and how the stuck hole nodes move with
the parameter. Writes OUT_frames.dat (t, RMS residual, RMS theta_x) and
OUT_worst.dat (offset %, the worst angle, its cubic) for
scripts/scan_parameter.gp.
"""
import argparse
import threading

import numpy as np

import ccsrm


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--config", default=ccsrm.bundled_config("paper.yaml"))
    ap.add_argument("--protocol", required=True)
    ap.add_argument("--case", type=int, default=None)
    ap.add_argument("--set", action="append", default=[], help="name=value (repeatable)")
    ap.add_argument("--parameter", required=True)
    ap.add_argument("--points", type=int, default=41)
    ap.add_argument("--span", type=float, default=0.02)
    ap.add_argument("--out", required=True, help="prefix of the .dat files")
    a = ap.parse_args()
    model = ccsrm.load_config(a.config)
    base = {}
    for text in a.set:
        name, value = text.split("=", 1)
        base[name] = float(value)
    centre = base.get(a.parameter, model.parameters[a.parameter])
    offsets = np.linspace(-a.span, a.span, a.points)
    values = centre * (1.0 + offsets)
    angles, stuck, time, failures = [None] * a.points, [None] * a.points, [], []

    def work(indices):
        try:
            run_all(indices)
        except Exception as e:  # reported by the main thread, once
            failures.append(e)

    def run_all(indices):
        for i in indices:
            params = dict(base, **{a.parameter: float(values[i])})
            run = ccsrm.simulate(model, params, case=a.case, protocol=a.protocol)
            if run.status != "completed":
                raise RuntimeError(f"the run at {a.parameter} = {values[i]:g} {run.status}")
            angles[i] = np.degrees(run.joint_angles.copy())
            stuck[i] = run.stuck_nodes.copy()
            if i == 0:
                time.append(run.time.copy())

    threads = [threading.Thread(target=work, args=(range(k, a.points, 2),)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    if failures:
        raise SystemExit(f"scan_parameter: {failures[0]}")
    A = np.array(angles)  # points x frames x joints x 2 [deg]
    P, T, J, _ = A.shape
    t = time[0]
    X = A.reshape(P, -1)
    V = np.vander(offsets, 4)
    coef, *_ = np.linalg.lstsq(V, X, rcond=None)
    R = X - V @ coef
    variation = X.max(0) - X.min(0)
    print(f"{a.parameter} over {centre:g} +-{100 * a.span:g} % in {P} runs; {T} frames x {J} "
          f"joints x 2 axes")
    print(f"residual to the cubics: {np.sqrt((R ** 2).mean()):.3g} deg RMS, "
          f"{np.abs(R).max():.3g} max; variation {np.sqrt((variation ** 2).mean()):.3g} RMS, "
          f"{variation.max():.3g} max")
    steps = np.sqrt((np.diff(X, axis=0) ** 2).mean(1))
    print(f"change between neighbouring values, RMS over the angles: min {steps.min():.3g}, "
          f"median {np.median(steps):.3g}, max {steps.max():.3g} deg (a jump: one far above)")
    per_frame = np.sqrt((R.reshape(P, T, J, 2) ** 2).mean(axis=(0, 2, 3)))
    top = sorted(np.argsort(per_frame)[::-1][:8])
    print("frames of the largest residual: " +
          ", ".join(f"{t[i]:.2f} s ({per_frame[i]:.2g} deg)" for i in top))
    per_joint = np.sqrt((R.reshape(P, T, J, 2) ** 2).mean(axis=(0, 1)))
    print("RMS residual per joint, theta_x / theta_y [deg]:")
    for j in range(J):
        print(f"  joint {j + 1:2d}: {per_joint[j, 0]:.2e} / {per_joint[j, 1]:.2e}")
    k = int(np.abs(R).max(0).argmax())
    f, rest = divmod(k, J * 2)
    j, axis = divmod(rest, 2)
    d = np.diff(X[:, k])
    print(f"worst angle: joint {j + 1} theta_{'xy'[axis]} at t = {t[f]:.2f} s; across the scan "
          f"{X[:, k].min():.5f} to {X[:, k].max():.5f} deg; neighbouring steps median "
          f"{np.median(np.abs(d)):.2g}, largest {np.abs(d).max():.2g} deg")
    S = np.array(stuck).reshape(P, -1)
    moved = np.abs(S - S[P // 2]).sum(1).astype(int)
    print("stuck-node samples that differ from the middle run, per value: " +
          " ".join(str(m) for m in moved))
    middle_motion = np.sqrt((A[P // 2][:, :, 0] ** 2).mean(1))
    np.savetxt(a.out + "_frames.dat", np.c_[t, per_frame, middle_motion],
               header="t_s residual_rms_deg rms_theta_x_deg")
    np.savetxt(a.out + "_worst.dat", np.c_[100 * offsets, X[:, k], (V @ coef)[:, k]],
               header="offset_percent angle_deg cubic_deg")


if __name__ == "__main__":
    main()
