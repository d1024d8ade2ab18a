"""ccsrm.simulate against `ccsrm simulate`: the same library calls, so the
same numbers to the bit; and the Python side of a run (arrays, summary,
errors, threads, Ctrl-C)."""
import _thread
import threading
import time

import h5py
import numpy as np
import pytest

import ccsrm
from conftest import SOURCE_DIR, run_ccsrm

TWO_AXIS = str(SOURCE_DIR / "configs" / "protocols" / "two-axis.yaml")


def assert_same_as_file(run, path):
    """Every array of the run equals the file's dataset bit for bit (NaN
    where NaN), and the solver's counts agree."""
    with h5py.File(path, "r") as f:
        pairs = [
            ("time", run.time), ("joint_angles", run.joint_angles),
            ("joint_rates", run.joint_rates), ("link_pose", run.link_pose),
            ("input_tension", run.input_tension),
            ("input_length_change", run.input_length_change),
            ("stuck_nodes", run.stuck_nodes), ("slack_elements", run.slack_elements),
            ("diagnostics/constraint_violation", run.constraint_violation),
            ("diagnostics/energy", run.energy),
        ]
        for k in range(len(run.cable_tensions)):
            pairs += [(f"cables/{k + 1}/tension", run.cable_tensions[k]),
                      (f"cables/{k + 1}/slip_velocity", run.slip_velocities[k]),
                      (f"cables/{k + 1}/stuck", run.stuck[k])]
        for name, ours in pairs:
            theirs = f[name][()]
            assert ours.shape == theirs.shape, name
            # Bit equality: the same doubles, not merely close ones.
            assert ours.tobytes() == theirs.astype(np.float64).tobytes(), name
        for attr in ("steps", "rejected_steps", "rhs_evaluations"):
            assert int(f.attrs[attr]) == getattr(run.summary, attr), attr
        def text(name):
            value = f.attrs.get(name, "")
            return value.decode() if isinstance(value, bytes) else value

        # What the file records of the run's origin: case, configuration,
        # protocol (absent for the configuration's own paper protocol).
        assert run.case_name == text("case")
        assert run.config_yaml == text("config_yaml")
        assert run.protocol_yaml == text("protocol_yaml")
        assert run.status == "completed"


def write_input_table(table, path):
    """A table of inputs as `--inputs` reads it: time_s, then cable<k>_m."""
    header = "time_s," + ",".join(f"cable{k}_m" for k in range(1, table.shape[1]))
    # repr: the shortest text that reads back to the same double.
    path.write_text(header + "\n" + "\n".join(",".join(repr(float(v)) for v in row)
                                              for row in table) + "\n")
    return path


def test_protocol_run_equals_command_line_run_file(exe, paper_config, paper_model, tmp_path):
    out = tmp_path / "cli.h5"
    run_ccsrm(exe, "simulate", "--config", paper_config, "--case", 2, "--protocol", TWO_AXIS,
              "--duration", 0.6, "--quiet", "--out", out)
    run = ccsrm.simulate(paper_model, case=2, protocol=TWO_AXIS, duration=0.6)
    assert run.summary.completed
    assert run.frames == 61
    assert_same_as_file(run, out)


def test_paper_protocol_with_values_equals_command_line(exe, paper_config, paper_model, tmp_path):
    out = tmp_path / "cli.h5"
    run_ccsrm(exe, "simulate", "--config", paper_config, "--case", 3, "--amplitude", 20,
              "--duration", 0.4, "--set", "T_d0=70", "--set", "beta=0.002", "--output-rate", 50,
              "--quiet", "--out", out)
    run = ccsrm.simulate(paper_model, {"T_d0": 70, "beta": 0.002}, case=3, amplitude_deg=20,
                         duration=0.4, output_rate=50)
    assert_same_as_file(run, out)
    # The run written from Python is the command's file too.
    ours = tmp_path / "py.h5"
    run.write(ours)
    again = ccsrm.read_run_file(ours)
    assert again.joint_angles.tobytes() == run.joint_angles.tobytes()


def test_recorded_inputs_equal_command_line_table(exe, paper_config, paper_model, tmp_path):
    # A smooth pull on cables 1 and 4 against each other, as an actuator log.
    t = np.arange(0.0, 0.5 + 1e-12, 0.01)
    pull = 2e-3 * (1 - np.cos(np.pi * t / 0.5)) / 2
    table = np.zeros((t.size, 1 + paper_model.num_cables))
    table[:, 0] = t
    table[:, 1] = pull
    table[:, 4] = -pull
    csv = write_input_table(table, tmp_path / "inputs.csv")
    out = tmp_path / "cli.h5"
    run_ccsrm(exe, "simulate", "--config", paper_config, "--case", 1, "--inputs", csv,
              "--quiet", "--out", out)
    run = ccsrm.simulate(paper_model, case=1, inputs=table)
    assert_same_as_file(run, out)


def test_settled_poses_replay_as_the_command_line_does(exe, paper_config, paper_model, tmp_path):
    # Five settled poses a second apart: cable 1 pulled 3 mm in steps and let
    # back to zero, as a pose log records them.
    pull = np.array([0.0, 1e-3, 3e-3, 1.5e-3, 0.0])
    table = np.zeros((pull.size, 1 + paper_model.num_cables))
    table[:, 0] = np.arange(pull.size, dtype=float)
    table[:, 1] = pull
    csv = write_input_table(table, tmp_path / "poses.csv")
    out = tmp_path / "cli.h5"
    run_ccsrm(exe, "simulate", "--config", paper_config, "--case", 2, "--inputs", csv,
              "--quasi-static", "--quiet", "--out", out)
    run = ccsrm.simulate(paper_model, case=2, inputs=table, quasi_static=True)
    assert_same_as_file(run, out)
    # A frame at each pose (no gap limit for poses a second apart).
    assert run.time.tolist() == table[:, 0].tolist()
    # Friction keeps part of the bend after the pull is let back to zero;
    # the frictionless arm (case 1) is straight again.
    back = np.abs(run.joint_angles[-1]).max()
    frictionless = ccsrm.simulate(paper_model, case=1, inputs=table, quasi_static=True)
    assert np.abs(frictionless.joint_angles[-1]).max() < 1e-7
    assert back > 1e-3 * np.abs(run.joint_angles[2]).max()


def test_sample_times_are_the_frames(paper_model):
    times = [0.0, 0.013, 0.2, 0.25]
    run = ccsrm.simulate(paper_model, case=1, duration=0.25, sample_times=times)
    assert run.time.tolist() == times
    assert run.joint_angles.shape == (4, paper_model.num_joints, 2)


def test_arrays_are_read_only_views_of_the_run(paper_model):
    run = ccsrm.simulate(paper_model, case=1, duration=0.1)
    angles = run.joint_angles
    assert not angles.flags.owndata and not angles.flags.writeable
    # Two views share the run's memory: no copy per access.
    assert np.shares_memory(angles, run.joint_angles)
    del run  # the view keeps the run alive
    assert np.isfinite(angles).all()
    assert angles.shape[1:] == (12, 2)
    assert len(ccsrm.simulate(paper_model, case=1, duration=0.05).cable_tensions) == 6


def test_parameters_by_the_command_lines_names_and_bounds(paper_model):
    p = paper_model.parameters
    table = {info.name: info for info in ccsrm.parameter_table()}
    assert list(p.keys()) == list(table)
    assert p.info("beta").upper == table["beta"].upper
    with pytest.raises(ccsrm.InputError) as e:
        p["beta"] = 3.0
    assert str(e.value) == "Parameters: parameter 'beta' = 3 is outside [0, 0.1] s"
    assert p["beta"] == paper_model.parameters["beta"]  # unchanged
    p["joint_friction.coulomb_nm"] = 0.01
    assert p.effects_on == ["joint_friction"]
    assert "joint_friction.coulomb_nm" in p.keys()
    assert paper_model.parameters.effects_on == []  # the model is read-only
    assert [e.name for e in ccsrm.effects()][0] == "joint_friction"
    offsets = paper_model.effect_parameters("mocap_offset")
    assert offsets[:2] == ["mocap_offset.joint1_x_rad", "mocap_offset.joint1_y_rad"]
    assert len(offsets) == 2 * paper_model.num_joints
    with pytest.raises(ccsrm.InputError, match="unknown effect 'no_such'"):
        paper_model.effect_parameters("no_such")


def test_parameters_object_drives_the_run(paper_model):
    p = paper_model.parameters
    p["T_d0"] = 70.0
    by_object = ccsrm.simulate(paper_model, p, case=3, duration=0.1)
    by_dict = ccsrm.simulate(paper_model, {"T_d0": 70.0}, case=3, duration=0.1)
    assert by_object.joint_angles.tobytes() == by_dict.joint_angles.tobytes()


@pytest.mark.parametrize("call, message", [
    (lambda m: ccsrm.load_config("no/such/arm.yaml"), "no/such/arm.yaml: cannot open for reading"),
    (lambda m: ccsrm.simulate(m, {"beta": 3}), "params: parameter 'beta' = 3 is outside [0, 0.1] s"),
    (lambda m: ccsrm.simulate(m, {"friction": 1}), "params: unknown parameter 'friction'"),
    (lambda m: ccsrm.simulate(m, case=7), "--case: must be 1, 2, 3 or 4, found 7"),
    (lambda m: ccsrm.simulate(m, ccsrm.load_config(ccsrm.bundled_config("three-segment.yaml"))
                              .parameters),
     "params: parameters of an arm of 12 joints and 9 cables, the model has 12 and 6"),
    (lambda m: ccsrm.simulate(m, protocol="no/such/protocol.yaml"),
     "no/such/protocol.yaml: cannot open for reading"),
    (lambda m: ccsrm.simulate(m, protocol=TWO_AXIS, inputs=np.zeros((3, 7))),
     "--protocol: and --inputs exclude each other: give one"),
    (lambda m: ccsrm.simulate(m, inputs=np.zeros((3, 4))),
     "inputs: has 3 cable columns, the arm has 6 driving cables"),
    (lambda m: ccsrm.simulate(m, inputs=np.zeros(5)), "inputs: expected a 2-D array"),
    (lambda m: ccsrm.simulate(m, duration=0.1, sample_times=[0.05, 0.01]),
     "sample_times: sample_times[1] = 0.010000 must be non-decreasing and within [0, duration]"),
    (lambda m: ccsrm.simulate(m, duration=-1), "--duration: must be > 0 s"),
])
def test_bad_arguments_raise_the_librarys_message(paper_model, call, message):
    with pytest.raises(ccsrm.InputError) as e:
        call(paper_model)
    assert message in str(e.value)
    assert "\n" not in str(e.value)  # one line, as the command prints it


def test_bad_config_message_is_the_command_lines(exe, tmp_path):
    bad = tmp_path / "bad.yaml"
    text = (SOURCE_DIR / "configs" / "paper.yaml").read_text()
    bad.write_text(text.replace("links: 6", "links: -6", 1))
    cli = run_ccsrm(exe, "simulate", "--config", bad, "--duration", 0.1, "--quiet",
                    "--out", tmp_path / "x.h5", check=False)
    assert cli.returncode != 0
    with pytest.raises(ccsrm.InputError) as e:
        ccsrm.load_config(bad)
    assert str(e.value) in cli.stderr


def test_ctrl_c_cancels_a_run(paper_model):
    # What a simulated second of case 2 costs here and now, start-up
    # included (past the protocol's 48 s the arm holds, which costs no more
    # per second), so that the bound below holds at any speed and load.
    start = time.monotonic()
    ccsrm.simulate(paper_model, case=2, duration=2.0)
    per_simulated_s = (time.monotonic() - start) / 2.0
    # interrupt_main() is what Ctrl-C does to the main thread: the run must
    # stop at its next poll (every 0.1 s) and raise KeyboardInterrupt.
    duration = 1000.0
    timer = threading.Timer(0.5, _thread.interrupt_main)
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        ccsrm.simulate(paper_model, case=2, duration=duration)
    elapsed = time.monotonic() - start
    timer.join()
    # A run that went on to its end and only then let the interruption
    # through would take about duration * per_simulated_s (minutes); one
    # cancelled takes 0.5 s and a poll. A quarter of the whole run tells
    # the two apart on any machine, however loaded.
    assert elapsed < 0.25 * duration * per_simulated_s, (elapsed, per_simulated_s)


def test_two_threads_simulate_at_the_same_time(paper_model):
    # Each thread's own CPU clock, sampled every 50 ms while both run: were
    # the GIL (or any lock) held through a run, the other thread would wait
    # without CPU while it ran, and the sampler could not even run (it needs
    # the GIL), so no short window would see both threads advance. Released,
    # both advance in the same windows, on free cores or on cores shared with
    # other jobs alike: no speed or load is assumed. (The speed-up on free
    # cores is a benchmark's figure, not a test's.)
    done = threading.Event()
    started = threading.Barrier(3)
    clocks, cpu_s = {}, {}

    def one(k):
        clocks[k] = time.pthread_getcpuclockid(threading.get_ident())
        started.wait()
        t0 = time.thread_time()
        ccsrm.simulate(paper_model, case=2, duration=20.0)
        cpu_s[k] = time.thread_time() - t0
        done.wait()  # alive, so that its clock can still be read

    threads = [threading.Thread(target=one, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    started.wait()
    samples = []  # (wall, cpu of thread 0, cpu of thread 1)
    try:
        while len(cpu_s) < 2:
            samples.append((time.monotonic(), time.clock_gettime(clocks[0]),
                            time.clock_gettime(clocks[1])))
            time.sleep(0.05)
        samples.append((time.monotonic(), time.clock_gettime(clocks[0]),
                        time.clock_gettime(clocks[1])))
    finally:
        done.set()
        for t in threads:
            t.join()
    # CPU both threads spent in the same windows; a window is counted while
    # the sampler ran on time (at most 0.25 s: five sampling periods), as it
    # cannot while a run holds the GIL.
    together = sum(min(b1 - a1, b2 - a2) for (w0, a1, a2), (w1, b1, b2) in zip(samples, samples[1:])
                   if w1 - w0 <= 0.25)
    shorter = min(cpu_s.values())
    # Side by side, most of the shorter run's CPU falls in windows that the
    # other run shares; one after the other, almost none does.
    assert together > 0.5 * shorter, (together, cpu_s, len(samples))


@pytest.mark.slow
def test_paper_case_2_over_the_whole_protocol_equals_command_line(exe, paper_config, paper_model,
                                                                   tmp_path):
    out = tmp_path / "cli.h5"
    run_ccsrm(exe, "simulate", "--config", paper_config, "--case", 2, "--quiet", "--out", out)
    run = ccsrm.simulate(paper_model, case=2)
    assert run.summary.completed and run.frames == 4801
    assert_same_as_file(run, out)


def test_a_nan_is_refused_not_read_as_not_given(paper_model):
    # Issue 47, 9: NaN is the library's "not given"; passed in, it is refused.
    for name in ("duration", "amplitude_deg", "output_rate"):
        with pytest.raises(ccsrm.InputError) as e:
            ccsrm.simulate(paper_model, case=1, **{name: float("nan")})
        assert name in str(e.value) and "finite" in str(e.value)


def test_arguments_of_the_wrong_type_raise_type_error(paper_model):
    # Issue 47, 13: a TypeError naming the argument, not pybind11's
    # RuntimeError naming a C++ type.
    with pytest.raises(TypeError) as e:
        ccsrm.simulate(paper_model, case=1, duration=0.1, sample_times=np.zeros((2, 3)))
    assert "sample_times: expected a 1-D sequence" in str(e.value) and "(2, 3)" in str(e.value)
    with pytest.raises(TypeError) as e:
        ccsrm.simulate(paper_model, ["mu", 0.2], case=1, duration=0.1)
    assert "params: expected a dict of numbers" in str(e.value)


def test_inputs_beyond_the_arm_are_refused_not_simulated(paper_model):
    # Issue 47, 10: a cable pulled 10 m in 10 ms hung the run at t = 0.
    inputs = np.zeros((2, 7))
    inputs[1, 0] = 0.01
    inputs[1, 1] = 10.0
    with pytest.raises(ccsrm.InputError) as e:
        ccsrm.simulate(paper_model, inputs=inputs)
    assert "pulls cable 1 in by 10 m" in str(e.value)
