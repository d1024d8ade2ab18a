"""Shared fixtures: the command-line program and the source tree, which CTest
passes in the environment (python/tests/CMakeLists.txt)."""
import os
import pathlib
import subprocess

import pytest

import ccsrm

SOURCE_DIR = pathlib.Path(
    os.environ.get("CCSRM_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))


@pytest.fixture(scope="session")
def exe():
    path = os.environ.get("CCSRM_EXE")
    if not path:
        pytest.skip("CCSRM_EXE (the ccsrm program) not set: run through ctest")
    return path


@pytest.fixture(scope="session")
def paper_config():
    return str(SOURCE_DIR / "configs" / "paper.yaml")


@pytest.fixture(scope="session")
def paper_model(paper_config):
    return ccsrm.load_config(paper_config)


def run_ccsrm(exe, *args, check=True):
    """Runs the command line; returns the CompletedProcess."""
    done = subprocess.run([exe, *map(str, args)], capture_output=True, text=True)
    if check and done.returncode != 0:
        raise AssertionError(f"ccsrm {' '.join(map(str, args))} exited {done.returncode}:\n"
                             f"{done.stdout}\n{done.stderr}")
    return done


@pytest.fixture(scope="session")
def experiment(exe, tmp_path_factory):
    """A short generated experiment (no measured angles: identification runs
    the mocap pipeline on its markers), as tests/identify/cli_test.cc makes."""
    path = tmp_path_factory.mktemp("experiment") / "exp.h5"
    run_ccsrm(exe, "generate", "--config", SOURCE_DIR / "configs" / "paper.yaml", "--case", 4,
              "--duration", 2, "--set", "T_p=60", "--quiet", "--out", path)
    return path
