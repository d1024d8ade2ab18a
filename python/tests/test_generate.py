"""ccsrm.generate against `ccsrm generate`: one library call
(mocap::GenerateExperiment), so the same files to the bit; the output policy
and the protocol grammar are the command's."""
import h5py
import numpy as np
import pytest

import ccsrm
from conftest import SOURCE_DIR, run_ccsrm

# The paper's protocol as a file, whose parameters a spec can set.
PAPER = str(SOURCE_DIR / "configs" / "protocols" / "paper.yaml")


def datasets_of(path):
    """Every dataset of an HDF5 file by name, and its root attributes but the
    creation time and the name (the file's stem)."""
    arrays = {}
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, o: arrays.__setitem__(name, o[()])
                     if isinstance(o, h5py.Dataset) else None)
        attrs = {k: f.attrs[k] for k in f.attrs if k not in ("created", "name")}
    return arrays, attrs


def assert_same_files(a, b):
    (xa, aa), (xb, ab) = datasets_of(a), datasets_of(b)
    assert sorted(xa) == sorted(xb)
    for name in xa:
        a, b = np.asarray(xa[name]), np.asarray(xb[name])
        if a.dtype.kind == "O":  # names
            assert a.tolist() == b.tolist(), name
        else:  # the same doubles (NaN where a marker was hidden), not close ones
            assert a.tobytes() == b.tobytes(), name
    assert sorted(aa) == sorted(ab)
    for key in aa:
        assert np.array_equal(aa[key], ab[key]), key


def test_generate_writes_the_files_the_command_writes(exe, paper_config, tmp_path):
    spec = PAPER + "@amplitude_deg=4"
    run_ccsrm(exe, "generate", "--config", paper_config, "--case", 2, "--protocol", spec,
              "--duration", 0.5, "--set", "T_p=55", "--effect", "joint_friction",
              "--seed", 3, "--quiet", "--out", tmp_path / "cli.h5")
    out = ccsrm.generate(tmp_path / "py.h5", paper_config, case=2, protocol=spec, duration=0.5,
                         params={"T_p": 55.0}, effects=["joint_friction"], seed=3)
    assert out["experiment"] == str(tmp_path / "py.h5")
    assert out["truth_yaml"] == str(tmp_path / "py.truth.yaml")
    assert out["effects"] == ["joint_friction"]
    assert out["frames"] == 51 and out["markers"] > 0
    assert_same_files(tmp_path / "cli.h5", tmp_path / "py.h5")
    assert_same_files(tmp_path / "cli.truth.h5", tmp_path / "py.truth.h5")
    # The truth file names its experiment; all else is the same text.
    cli = (tmp_path / "cli.truth.yaml").read_text().replace("cli.h5", "X.h5")
    py = (tmp_path / "py.truth.yaml").read_text().replace("py.h5", "X.h5")
    assert cli == py
    assert "T_p: 55" in py and "joint_friction:" in py
    # The experiment states the nominal model: the truth's value is not in it.
    assert ccsrm.read_dataset(tmp_path / "py.h5").source == "generated"


def test_generate_of_settled_poses_says_so_and_is_the_commands(exe, paper_config, tmp_path):
    # A quasi-static replay's frames are settled poses: the experiment says
    # so (identify, predict and loop replay it the same way).
    run_ccsrm(exe, "generate", "--config", paper_config, "--case", 2, "--duration", 0.3,
              "--quasi-static", "--seed", 4, "--quiet", "--out", tmp_path / "cli.h5")
    out = ccsrm.generate(tmp_path / "py.h5", paper_config, case=2, duration=0.3, seed=4,
                         quasi_static=True)
    assert out["frames"] == 31
    assert_same_files(tmp_path / "cli.h5", tmp_path / "py.h5")
    assert ccsrm.read_dataset(tmp_path / "py.h5").motion == "settled_poses"
    ccsrm.generate(tmp_path / "dynamic.h5", paper_config, case=2, duration=0.3, seed=4)
    assert ccsrm.read_dataset(tmp_path / "dynamic.h5").motion == "continuous"


def test_generate_refuses_a_file_that_is_not_an_earlier_experiment(paper_config, tmp_path):
    notes = tmp_path / "notes.h5"
    notes.write_text("my notes")
    with pytest.raises(ccsrm.InputError, match="notes.h5"):
        ccsrm.generate(notes, paper_config, duration=0.1)
    assert notes.read_text() == "my notes"
    with pytest.raises(ccsrm.InputError, match="must end in .h5"):
        ccsrm.generate(tmp_path / "exp.hdf", paper_config, duration=0.1)
    with pytest.raises(ccsrm.InputError, match="expected name=value after '@'"):
        ccsrm.generate(tmp_path / "exp.h5", paper_config, protocol=PAPER + "@amplitude_deg",
                       duration=0.1)
    assert not (tmp_path / "exp.h5").exists()


def test_simulate_takes_a_protocol_with_parameter_values(paper_model):
    run = ccsrm.simulate(paper_model, case=1, protocol=PAPER + "@amplitude_deg=4",
                         duration=0.2)
    assert run.summary.completed
    assert "amplitude_deg" in run.protocol_yaml
