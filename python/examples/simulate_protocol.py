#!/usr/bin/env python3
"""Simulates the paper's arm through a custom motion (a ccsrm-protocol/1
file) and plots the tip joints' angles and the cable tensions.

    PYTHONPATH=build/python python3 python/examples/simulate_protocol.py \
        --protocol configs/protocols/two-axis.yaml --case 2 --duration 20 --out two-axis.png
"""
import argparse

import matplotlib

matplotlib.use("Agg")  # files only: runs headless (CI, ssh)
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import ccsrm  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--config", default=ccsrm.bundled_config("paper.yaml"))
    parser.add_argument("--protocol", default=ccsrm.bundled_config("protocols/two-axis.yaml"))
    parser.add_argument("--case", type=int, default=2, help="paper case 1..4 (default 2)")
    parser.add_argument("--duration", type=float, help="simulated time [s] (default: all)")
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    parser.add_argument("--out", default="protocol.png", help="figure (PNG)")
    args = parser.parse_args()

    model = ccsrm.load_config(args.config)
    values = {k: float(v) for k, v in (s.split("=", 1) for s in args.set)}
    run = ccsrm.simulate(model, values, case=args.case, protocol=args.protocol,
                         duration=args.duration)
    print(run.description, end="")
    print(run.summary.full_report(), end="")

    # The last joint of each segment: where the motion of a segment shows.
    segment_ends = np.cumsum(model.segment_links) - 1
    fig, (ax_angles, ax_tension) = plt.subplots(2, 1, sharex=True, figsize=(8, 6))
    for j in segment_ends:
        for axis, name, style in ((0, "θx", "-"), (1, "θy", "--")):
            ax_angles.plot(run.time, np.degrees(run.joint_angles[:, j, axis]), style,
                           label=f"joint {j + 1} {name}")
    ax_angles.set_ylabel("joint angle [deg]")
    ax_angles.legend(ncol=2, fontsize="small")
    ax_angles.set_title(f"{run.description.splitlines()[0]}", fontsize="small")
    for k in range(model.num_cables):
        ax_tension.plot(run.time, run.input_tension[:, k], label=f"cable {k + 1}")
    ax_tension.set_ylabel("input tension [N]")
    ax_tension.set_xlabel("time [s]")
    ax_tension.legend(ncol=3, fontsize="small")
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    print(f"figure: {args.out}")
    return 0 if run.summary.completed else 3


if __name__ == "__main__":
    raise SystemExit(main())
