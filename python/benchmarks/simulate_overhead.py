#!/usr/bin/env python3
"""The cost of calling the simulator from Python: ccsrm.simulate for the
paper's case 2 against the C++ call that `ccsrm bench` times (sim::Simulate
on the same prepared run), interleaved so that both see the same load.

    PYTHONPATH=build/python python3 python/benchmarks/simulate_overhead.py \
        --exe build/app/ccsrm --repeat 5
"""
import argparse
import os
import re
import resource
import statistics
import subprocess
import time

import ccsrm


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--exe", default="build/app/ccsrm", help="the ccsrm program")
    parser.add_argument("--config", default=ccsrm.bundled_config("paper.yaml"))
    parser.add_argument("--case", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()

    def child_cpu(*options):
        """CPU seconds of one `ccsrm bench` process, and its output."""
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        out = subprocess.run([args.exe, "bench", "--config", args.config, "--case",
                              str(args.case), "--repeat", "1", *options],
                             capture_output=True, text=True, check=True).stdout
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        return after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime, out

    # What a bench process spends besides planning and running the protocol:
    # start, libraries, configuration (a 10 ms run plans and runs ~nothing).
    fixed = statistics.median(child_cpu("--duration", "0.01")[0] for _ in range(5))
    model = ccsrm.load_config(args.config)
    ccsrm.simulate(model, case=args.case, duration=1.0)  # warm up
    cpp, py_total, py_simulate, cpp_cpu, py_cpu = [], [], [], [], []
    for k in range(args.repeat):
        # The whole process: start, configuration, planning and the run.
        cpu, out = child_cpu()
        cpp_cpu.append(cpu)
        cpp.append(float(re.search(r"median wall time:\s+([\d.]+) s", out).group(1)))
        start, cpu = time.perf_counter(), time.thread_time()
        run = ccsrm.simulate(model, case=args.case)
        # The run goes on in this thread (the GIL released, not handed over).
        py_cpu.append(time.thread_time() - cpu)
        py_total.append(time.perf_counter() - start)
        py_simulate.append(run.summary.wall_time_s)
        print(f"run {k + 1}: C++ Simulate {cpp[-1]:.3f} s; Python simulate() {py_total[-1]:.3f} s "
              f"(its Simulate {py_simulate[-1]:.3f} s)")
    c, t, s = (statistics.median(v) for v in (cpp, py_total, py_simulate))
    cc, pc = statistics.median(cpp_cpu), statistics.median(py_cpu)
    print(f"fastest: C++ {min(cpp):.3f} s, Python whole {min(py_total):.3f} s "
          f"({100 * (min(py_total) / min(cpp) - 1):+.1f} %), its Simulate {min(py_simulate):.3f} s "
          f"({100 * (min(py_simulate) / min(cpp) - 1):+.1f} %)")
    print(f"median C++ Simulate (ccsrm bench):        {c:.3f} s")
    print(f"median Python ccsrm.simulate(), whole:     {t:.3f} s  ({100 * (t / c - 1):+.1f} %)")
    print(f"median Simulate inside ccsrm.simulate():   {s:.3f} s  ({100 * (s / c - 1):+.1f} %)")
    print(f"planning and arrays around it (median):    {t - s:.3f} s")
    print(f"CPU time, ccsrm bench process (median):    {cc:.3f} s  (start, config, plan, run)")
    print(f"CPU time, ccsrm.simulate() (median):       {pc:.3f} s  ({100 * (pc / cc - 1):+.1f} %; "
          f"plan, run, arrays)")
    print(f"CPU time, plan and run in C++ (median):    {cc - fixed:.3f} s  (bench process less its "
          f"{fixed:.3f} s of start and configuration)")
    print(f"CPU overhead of ccsrm.simulate():          {100 * (pc / (cc - fixed) - 1):+.1f} % "
          f"(plan, run and arrays against plan and run)")
    print(f"load average: {os.getloadavg()[0]:.2f} on {len(os.sched_getaffinity(0))} cores")


if __name__ == "__main__":
    main()
