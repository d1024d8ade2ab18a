"""The examples run headless, as a user would run them."""
import os
import subprocess
import sys

import pytest

from conftest import SOURCE_DIR, run_ccsrm

EXAMPLES = SOURCE_DIR / "python" / "examples"


def run_example(name, *args):
    env = dict(os.environ, MPLBACKEND="Agg")
    done = subprocess.run([sys.executable, str(EXAMPLES / name), *map(str, args)],
                          capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stdout + done.stderr
    return done.stdout


def test_simulate_protocol_example_draws_its_figure(tmp_path):
    figure = tmp_path / "two-axis.png"
    out = run_example("simulate_protocol.py", "--case", 2, "--duration", 1.0, "--out", figure)
    assert "completed" in out
    # A PNG with something drawn in it (an empty 880x660 figure is ~10 kB).
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert figure.stat().st_size > 20_000


def test_fit_example_prints_the_table(exe, experiment, tmp_path):
    second = tmp_path / "exp2.h5"
    run_ccsrm(exe, "generate", "--config", SOURCE_DIR / "configs" / "paper.yaml", "--case", 4,
              "--duration", 2, "--amplitude", 20, "--set", "T_p=60", "--seed", 3, "--quiet",
              "--out", second)
    out = run_example("fit_two_recordings.py", experiment, second, "--free", "T_p",
                      "--set", "mu=0", "--set", "mu_s=0", "--max-iterations", 2, "--threads", 2)
    lines = [line for line in out.splitlines() if not line.startswith("  iteration ")]
    assert out.startswith("  iteration 0: RMS ")
    assert lines[1].split()[:2] == ["parameter", "start"]
    assert lines[2].split()[0] == "T_p"
