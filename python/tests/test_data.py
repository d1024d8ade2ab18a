"""Experiment and marker files, and the mocap pipeline, from Python."""
import h5py
import numpy as np
import pytest

import ccsrm
from conftest import run_ccsrm


def test_dataset_arrays(experiment):
    d = ccsrm.read_dataset(experiment)
    assert d.source == "generated"
    n, c = d.input_length_change.shape
    assert n == d.input_time.size and c == 6
    f, m, three = d.mocap_markers.shape
    assert f == d.mocap_time.size and m == len(d.marker_names) and three == 3
    assert d.measured_joint_angles is None  # a generated file has markers only
    assert not d.input_time.flags.writeable
    # A motion sampled in time, markers in W, no pattern labels.
    assert d.motion == "continuous" and d.marker_frame == "world" and d.input_labels == []


def test_pose_log_import(exe, tmp_path):
    """A pose log through an actuator map: settled poses of a tracked tip."""
    from conftest import SOURCE_DIR
    columns = [f"servo_{k}_mm" for k in range(1, 10)]
    rows = ["timestamp,pattern_label," + ",".join(columns) + ",tip_x,tip_y,tip_z"]
    for i in range(6):
        label = "seg1_dir0" if i < 4 else "seg1_dir0_hold"
        readings = [0.5 * i if k == 0 else -0.2 for k in range(9)]
        tip = [-3.0 * i, 0.5, 188.0 - 0.1 * i]
        rows.append(f"{100 + 0.57 * i:.2f},{label}," + ",".join(map(str, readings + tip)))
    (tmp_path / "poses.csv").write_text("\n".join(rows) + "\n")
    cables = "".join(f'  - {{column: "{c}", signal: length_change, unit: mm, zero: -0.5}}\n'
                     for c in columns)
    (tmp_path / "actuators.yaml").write_text(
        'schema: ccsrm-actuators/1\ntime: {column: "timestamp", unit: s}\ncables:\n' + cables)
    out = tmp_path / "poses.h5"
    run_ccsrm(exe, "dataset", "import-pose-log", "--log", str(tmp_path / "poses.csv"),
              "--actuator-map", str(tmp_path / "actuators.yaml"),
              "--config", str(SOURCE_DIR / "configs" / "ftdcr_v4.yaml"), "--out", str(out))
    d = ccsrm.read_dataset(str(out))
    assert d.motion == "settled_poses" and d.marker_frame == "capture"
    assert d.input_labels == ["seg1_dir0"] * 4 + ["seg1_dir0_hold"] * 2
    # Pulled in = reading - zero, in m; the tip in m.
    np.testing.assert_allclose(d.input_length_change[:, 0], (0.5 * np.arange(6) + 0.5) * 1e-3)
    np.testing.assert_allclose(d.input_length_change[:, 1], 0.3e-3)
    np.testing.assert_allclose(d.mocap_markers[:, 0, 2], (188.0 - 0.1 * np.arange(6)) * 1e-3)
    np.testing.assert_allclose(d.input_time, 0.57 * np.arange(6), atol=1e-9)


def test_c3d_round_trip(experiment, tmp_path):
    markers = ccsrm.read_markers(experiment)
    path = tmp_path / "markers.c3d"
    ccsrm.write_c3d(path, markers.positions, markers.labels, markers.rate_hz, units="mm")
    back = ccsrm.read_markers(path)
    assert back.format == "c3d" and back.labels == markers.labels
    assert back.rate_hz == pytest.approx(markers.rate_hz, rel=1e-6)
    # C3D stores float32 millimetres: 1e-7 relative of a metre-sized value.
    seen = np.isfinite(markers.positions)
    assert (np.isfinite(back.positions) == seen).all()
    np.testing.assert_allclose(back.positions[seen], markers.positions[seen], atol=1e-6)


def test_bad_marker_input(tmp_path):
    bad = tmp_path / "broken.c3d"
    bad.write_bytes(b"\x02\x50" + b"\x00" * 20)
    with pytest.raises(ccsrm.InputError) as e:
        ccsrm.read_markers(bad)
    assert str(bad) in str(e.value)
    with pytest.raises(ccsrm.InputError) as e:
        ccsrm.write_c3d(tmp_path / "x.c3d", np.zeros((4, 2, 3)), ["a"], 100.0)
    assert "positions" in str(e.value)


def test_write_c3d_replaces_only_a_c3d_unless_asked(experiment, paper_config, tmp_path):
    # Issue 47, 2: a user's configuration is not an earlier C3D file.
    markers = ccsrm.read_markers(experiment)
    mine = tmp_path / "mycfg.yaml"
    mine.write_bytes(open(paper_config, "rb").read())
    with pytest.raises(ccsrm.InputError) as e:
        ccsrm.write_c3d(mine, markers)
    assert str(mine) in str(e.value) and "not a C3D file" in str(e.value)
    assert mine.read_bytes() == open(paper_config, "rb").read()
    # An earlier C3D is replaced; overwrite=True replaces anything.
    c3d = tmp_path / "m.c3d"
    ccsrm.write_c3d(c3d, markers)
    ccsrm.write_c3d(c3d, markers, units="m")
    ccsrm.write_c3d(mine, markers, overwrite=True)
    assert ccsrm.read_markers(mine.rename(tmp_path / "now.c3d")).labels == markers.labels


def test_mocap_pipeline_equals_command_line(exe, experiment, paper_config, tmp_path):
    # The real-file route: markers as a C3D file, the arm and the inputs
    # given apart, as `ccsrm mocap process` takes them.
    markers = ccsrm.read_markers(experiment)
    c3d = tmp_path / "trial.c3d"
    ccsrm.write_c3d(c3d, markers, units="mm")
    out = tmp_path / "cli.h5"
    run_ccsrm(exe, "mocap", "process", "--quiet", "--in", c3d, "--config", paper_config,
              "--inputs", experiment, "--out", out)
    processed = ccsrm.process_markers(c3d, config=paper_config, inputs=experiment)
    ours = processed.dataset
    assert "frames" in processed.full_report()
    with h5py.File(out, "r") as f:
        for name, array in (("measured/joint_angles", ours.measured_joint_angles),
                            ("measured/link_pose", ours.measured_link_pose),
                            ("input/length_change", ours.input_length_change)):
            assert array.tobytes() == f[name][()].astype(np.float64).tobytes(), name
    written = tmp_path / "py.h5"
    processed.write(written)
    again = ccsrm.read_dataset(written)
    assert again.measured_joint_angles.tobytes() == ours.measured_joint_angles.tobytes()
