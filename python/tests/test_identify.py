"""ccsrm.identify against `ccsrm identify`: the same fit.json."""
import json

import pytest

import ccsrm
from conftest import run_ccsrm

# What differs between two identical fits: time and the paths of the files.
TIMING = {"wall_time_s", "real_time_factor"}


def without_timing(value):
    if isinstance(value, dict):
        return {k: without_timing(v) for k, v in value.items() if k not in TIMING}
    if isinstance(value, list):
        return [without_timing(v) for v in value]
    return value


def test_fit_equals_command_lines_fit_json(exe, experiment, tmp_path):
    # The fit of tests/identify/cli_test.cc: one free parameter, two
    # iterations, on the generated experiment.
    out = tmp_path / "fit_cli"
    run_ccsrm(exe, "identify", "--data", experiment, "--free", "T_p", "--set", "mu=0",
              "--set", "mu_s=0", "--max-iterations", 2, "--threads", 2, "--quiet", "--out", out)
    cli = json.loads((out / "fit.json").read_text())
    iterations = []
    fit = ccsrm.identify([experiment], free="T_p", set={"mu": 0, "mu_s": 0},
                         max_iterations=2, threads=2, out=tmp_path / "fit_py",
                         progress=iterations.append)
    written = json.loads((tmp_path / "fit_py" / "fit.json").read_text())
    assert without_timing(written) == without_timing(cli)
    # The summary's JSON is fit.json without the names of the folder's files.
    for e in written["experiments"]:
        e.pop("angles_file"), e.pop("run_file")
    assert without_timing(fit.to_dict()) == without_timing(written)
    # One report per iteration, from the start (iteration 0).
    assert [p["iteration"] for p in iterations] == list(range(len(iterations)))
    assert iterations[0]["cost"] == fit.cost_history[0] and "T_p" in iterations[-1]["values"]
    # Issue 44: the verdict, as fit.json and the command's report give it.
    assert fit.verdict == cli["adequacy"]["verdict"] and fit.adequacy == cli["adequacy"]
    assert fit.adequate == cli["adequacy"]["adequate"]
    assert fit.full_report().startswith("model: " + fit.verdict)
    t_p = fit["T_p"]
    assert t_p.free and t_p.value == cli["parameters"]["T_p"]["value"]
    assert "T_p" in fit.full_report()


@pytest.mark.parametrize("kwargs, message", [
    (dict(free="mu,friction"), "--free: unknown parameter 'friction'"),
    (dict(free=" "), "--free: is empty: give at least one name"),
    (dict(free="mu,,T_p"), "--free: empty item in 'mu,,T_p'"),
    (dict(free="T_p", set={"beta": 3}), "--set: parameter 'beta' = 3 is outside [0, 0.1] s"),
    (dict(free="T_p", threads=0), "identify: threads: must be in 1..1024"),
    (dict(free="T_p", relative_step=0.5), "identify: relative_step must be in (0, 0.1]"),
    # Issue 47, 9: 0 iterations is no fit (it would say "converged", unmoved).
    (dict(free="T_p", max_iterations=0), "--max-iterations: is 0: a fit takes at least 1"),
])
def test_bad_fit_options_raise_before_any_run(experiment, kwargs, message):
    with pytest.raises(ccsrm.InputError) as e:
        ccsrm.identify(experiment, **kwargs)
    assert message in str(e.value)


def test_an_error_in_the_progress_function_is_raised_after_the_fit(experiment):
    def progress(p):
        raise RuntimeError(f"stop at {p['iteration']}")

    with pytest.raises(RuntimeError, match="stop at 0"):
        ccsrm.identify(experiment, free="T_p", max_iterations=1, threads=2, progress=progress)


def test_bad_experiment_names_the_file(tmp_path):
    bad = tmp_path / "not-an-experiment.h5"
    bad.write_bytes(b"no hdf5 here")
    with pytest.raises(ccsrm.InputError) as e:
        ccsrm.identify([bad], free="T_p")
    assert str(bad) in str(e.value)


def test_loop_equals_command_lines_loop_json(exe, experiment, tmp_path):
    # A small loop: one free parameter, two candidates, one round.
    options = ["--candidates", "table_tilt,joint_friction", "--free", "T_p", "--set", "mu=0",
               "--set", "mu_s=0", "--max-rounds", 1, "--max-iterations", 2, "--threads", 2]
    out = tmp_path / "loop_cli"
    run_ccsrm(exe, "loop", "--data", experiment, *options, "--quiet", "--out", out)
    cli = json.loads((out / "loop.json").read_text())
    loop = ccsrm.loop([experiment], candidates=["table_tilt", "joint_friction"], free="T_p",
                      set=["mu=0", "mu_s=0"], max_rounds=1, max_iterations=2, threads=2,
                      out=tmp_path / "loop_py")
    written = json.loads((tmp_path / "loop_py" / "loop.json").read_text())
    assert without_timing(written) == without_timing(cli)
    assert without_timing(loop.to_dict()) == without_timing(written)
    assert loop.conclusion.splitlines()[0] in loop.full_report()
    assert loop.final_fit["T_p"].value == written["parameters"]["T_p"]["value"]


def test_bad_loop_options(experiment):
    with pytest.raises(ccsrm.InputError) as e:
        ccsrm.loop(experiment, candidates="table_tilt,no_such_effect", free="T_p")
    assert "no_such_effect" in str(e.value)


def test_out_goes_through_the_commands_output_policy(experiment, tmp_path):
    # A folder of the user's is not an earlier fit: refused before any run,
    # and left as it was (the command line refuses it alike).
    user = tmp_path / "thesis"
    user.mkdir()
    (user / "notes.txt").write_text("mine")
    with pytest.raises(ccsrm.InputError) as e:
        ccsrm.identify(experiment, free="T_p", max_iterations=1, out=user)
    assert str(user) in str(e.value) and "--out" in str(e.value)
    assert (user / "notes.txt").read_text() == "mine"
    with pytest.raises(ccsrm.InputError):
        ccsrm.loop(experiment, free="T_p", max_rounds=1, out=user)
    assert sorted(p.name for p in user.iterdir()) == ["notes.txt"]
    # A stub that looks like an earlier fit (issue 47, 3): only what ccsrm
    # wrote there, on the folder's manifest, makes an earlier output.
    (user / "fit.json").write_text('{"schema":"ccsrm-fit/1"}')
    with pytest.raises(ccsrm.InputError) as e:
        ccsrm.identify(experiment, free="T_p", max_iterations=1, out=user)
    assert "'notes.txt', which ccsrm did not write" in str(e.value)
    assert sorted(p.name for p in user.iterdir()) == ["fit.json", "notes.txt"]


def test_resume_needs_a_stopped_fit_and_the_loop_takes_a_config(experiment, tmp_path):
    # The job's resume: nothing to resume in a folder without a checkpoint.
    with pytest.raises(ccsrm.InputError) as e:
        ccsrm.identify(experiment, free="T_p", out=tmp_path / "fresh", resume=True)
    assert "no checkpoint here" in str(e.value)
    with pytest.raises(ccsrm.InputError) as e:
        ccsrm.identify(experiment, free="T_p", resume=True)
    assert "--resume" in str(e.value)
    # config= is the command's --config: a file of another arm is refused,
    # naming the experiment.
    from conftest import SOURCE_DIR
    other = SOURCE_DIR / "configs" / "three-segment.yaml"
    if not other.exists():
        pytest.skip(f"{other} not found")
    with pytest.raises(ccsrm.InputError) as e:
        ccsrm.loop(experiment, free="T_p", config=other, max_rounds=1)
    assert "describes an arm of" in str(e.value)


def test_predict_equals_command_lines_pred_json(exe, experiment, tmp_path):
    # A parameter file as the model: the generated experiment's truth, so
    # the prediction's residual is the mocap pipeline's and its noise's.
    params = tmp_path / "truth.yaml"
    params.write_text("T_p: 60\n")
    out = tmp_path / "pred_cli"
    run_ccsrm(exe, "predict", "--data", experiment, "--params", params, "--threads", 1, "--quiet",
              "--out", out)
    cli = json.loads((out / "pred.json").read_text())
    prediction = ccsrm.predict(experiment, params=params, threads=1, out=tmp_path / "pred_py")
    written = json.loads((tmp_path / "pred_py" / "pred.json").read_text())
    assert without_timing(written) == without_timing(cli)
    assert prediction.completed and prediction.message == "every run completed"
    assert prediction.verdict == cli["verdict"] and prediction.adequate == cli["adequate"]
    assert prediction.verdict in prediction.full_report()
    # The summary's JSON is pred.json without the names of the folder's files.
    for r in written["recordings"]:
        for key in [k for k in r if k.endswith("_file")]:
            r.pop(key)
    assert without_timing(prediction.to_dict()) == without_timing(written)
    # Joint angles here, no tracked points.
    assert prediction.rms_deg > 0 and prediction.tracked_points == {}
    # write() goes through the same output policy: an earlier prediction
    # folder is replaced, a folder of the user's refused.
    assert sorted(prediction.write(tmp_path / "pred_py")) == sorted(
        str(p) for p in (tmp_path / "pred_py").iterdir() if p.name != "ccsrm-manifest.txt")
    user = tmp_path / "thesis"
    user.mkdir()
    (user / "notes.txt").write_text("mine")
    with pytest.raises(ccsrm.InputError):
        prediction.write(user)
    with pytest.raises(ccsrm.InputError) as e:
        ccsrm.predict(experiment, params=tmp_path / "missing.yaml")
    assert "missing.yaml" in str(e.value)
