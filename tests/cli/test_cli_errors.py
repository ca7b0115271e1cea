"""Every user mistake on the command line is one line on stderr naming the argument, with exit status 2."""

import os

import pytest

from comanip import presets
from comanip.cli.main import main

GOOD_MODEL = "name: mine\nbody: {type: point_mass, n: 2}\nh: 0.02\nH: 30\ngamma: 0.98\nnu: 1.0e-4\nkappa: 0.02\nwidth: 0.01\n"


def run_cli(argv, capsys) -> tuple[int, str]:
    """Exit status and stderr of ``comanip argv`` run in this process."""
    return main(argv), capsys.readouterr().err


def assert_one_line_error(code: int, err: str, *fragments: str) -> None:
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert "error:" in err
    for fragment in fragments:
        assert fragment in err, (fragment, err)


@pytest.mark.parametrize("text, fragments", [
    ("name: [unclosed\n", ["--preset", "not valid YAML", "line 2"]),
    ("name: mine\nbody: {type: point_mass, n: 2}\nh: 0.02\nH: 30\n", ["--preset", "'gamma'", "'nu'", "'kappa'", "'width'"]),
    (GOOD_MODEL + "speed: 3\n", ["--preset", "unknown model fields ['speed']", "allowed"]),
    (GOOD_MODEL.replace("h: 0.02", "h: fast"), ["--preset", "h must be a number between 0.0001 and 1", "'fast'"]),
    (GOOD_MODEL.replace("H: 30", "H: 2.5"), ["--preset", "H must be an integer"]),
    (GOOD_MODEL.replace("n: 2}", "n: 2, size: 3}"), ["--preset", "body of type 'point_mass' takes the parameters", "size"]),
    (GOOD_MODEL.replace("{type: point_mass, n: 2}", "rocket"), ["--preset", "body must be a mapping"]),
    ("- 1\n- 2\n", ["--preset", "does not hold a model mapping"]),
    ("", ["--preset", "is empty"]),
])
def test_bad_model_yaml_is_one_line(tmp_path, capsys, text, fragments):
    path = tmp_path / "model.yaml"
    path.write_text(text)
    assert_one_line_error(*run_cli(["plan", "--preset", str(path), "--out", str(tmp_path / "out")], capsys), *fragments)
    assert not (tmp_path / "out").exists()


def test_presets_load_raises_value_errors_naming_the_problem(tmp_path):
    (tmp_path / "folder.yaml").mkdir()
    with pytest.raises(ValueError, match="is a directory"):
        presets.load(tmp_path / "folder.yaml")
    with pytest.raises(ValueError, match="does not exist"):
        presets.load(tmp_path / "absent.yaml")
    with pytest.raises(ValueError, match="must be one of"):
        presets.load("plannar")


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads every file")
def test_unreadable_files_are_one_line(tmp_path, capsys):
    for name in ("model.yaml", "observed.csv"):
        (tmp_path / name).write_text(GOOD_MODEL)
        (tmp_path / name).chmod(0)
    assert_one_line_error(*run_cli(["plan", "--preset", str(tmp_path / "model.yaml")], capsys), "--preset", "cannot read")
    assert_one_line_error(*run_cli(["estimate", "--observations", str(tmp_path / "observed.csv")], capsys),
                          "--observations", "not readable")


@pytest.mark.parametrize("argv, fragments", [
    (["estimate", "--candidates", "0.3,0;0.2"], ["--candidates", "equal length", "'0.3,0;0.2'"]),
    (["estimate", "--observations", "{tmp}"], ["--observations", "is a directory"]),
    (["estimate", "--observations", "{tmp}/empty.csv"], ["--observations", "is empty"]),
    (["estimate", "--observations", "{tmp}/absent.csv"], ["--observations", "does not exist"]),
    (["fit", "--mt-table", "{tmp}"], ["--mt-table", "is a directory"]),
    (["handover", "--transition-model", "{tmp}/empty.csv"], ["--transition-model", "is empty"]),
    (["transition", "fit", "--data", "{tmp}"], ["--data", "is a directory"]),
    (["plan", "--goal", "0.3,abc"], ["--goal", "expected comma-separated numbers"]),
    (["plan", "--goal", "0.3,0,0"], ["goal must have shape (2,)"]),
    (["plan", "--width", "-1"], ["width must be a finite number > 0"]),
    (["plan", "--preset", "plannar"], ["--preset", "must be one of"]),
    (["estimate"], ["give the observation"]),
])
def test_argument_mistakes_are_one_line(tmp_path, capsys, argv, fragments):
    (tmp_path / "empty.csv").write_text("")
    argv = [a.format(tmp=tmp_path) for a in argv] + (["--out", str(tmp_path / "out")] if argv[0] in ("plan", "estimate") else [])
    assert_one_line_error(*run_cli(argv, capsys), *fragments)


def test_debug_shows_the_traceback(tmp_path):
    path = tmp_path / "model.yaml"
    path.write_text("name: [unclosed\n")
    with pytest.raises(ValueError, match="not valid YAML"):
        main(["--debug", "plan", "--preset", str(path)])


def test_help_has_no_literal_double_backticks(capsys):
    for argv in (["--help"], ["fit", "--help"], ["transition", "--help"], ["estimate", "--help"]):
        assert main(argv) == 0
        assert "``" not in capsys.readouterr().out


@pytest.mark.parametrize("argv, fragments", [
    (["handover", "--goal", "0.3,0.1,0.2", "--goal", "0.3,0.1"], ["goal must have shape (3,)"]),
    (["handover", "--max-wall-time", "-1"], ["max_wall_time", "> 0"]),
    (["transition", "generate", "--widths", "0.01,-0.02"], ["widths must be > 0"]),
    (["transition", "generate", "--workers", "0"], ["workers must be an integer ≥ 1"]),
    (["ros", "--speed", "2"], ["--speed", "--replay"]),
    (["fit", "--scheduler", "localhost", "--mt-table", "mt.csv"], ["--scheduler", "protocol://host:port"]),
])
def test_long_commands_check_inputs_before_making_their_folder(tmp_path, capsys, argv, fragments):
    """A mistake in any goal or sweep setting is found before the first plan is solved or the folder is made."""
    out = tmp_path / "out"
    target = out / "data.csv" if argv[0] == "transition" else out
    assert_one_line_error(*run_cli([*argv, "--out", str(target)], capsys), *fragments)
    assert not out.exists()


def _observations(path, time_scale=1.0, position_scale=1.0):
    """A 0.3 m reach's states at 50 Hz in the CSV 'comanip estimate --observations' reads, times and
    positions (and velocities) scaled."""
    import numpy as np

    t = np.arange(0.0, 0.42, 0.02)
    s = t / 0.6
    x, v = 0.3 * (10 * s**3 - 15 * s**4 + 6 * s**5), 0.3 / 0.6 * (30 * s**2 - 60 * s**3 + 30 * s**4)
    lines = ["t_s,q0,q1,qdot0,qdot1"] + [f"{time_scale * a:.6g},{position_scale * b:.6g},0,{position_scale * c:.6g},0"
                                         for a, b, c in zip(t, x, v)]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("scales, fragments", [((1000.0, 1.0), ["column 't_s'", "look like milliseconds", "--skip-unit-check"]),
                                               ((1.0, 1000.0), ["columns q0..q1", "look like millimetres"])])
def test_observations_in_ms_or_mm_are_one_line(tmp_path, capsys, scales, fragments):
    path = _observations(tmp_path / "observed.csv", *scales)
    assert_one_line_error(*run_cli(["estimate", "--observations", str(path), "--out", str(tmp_path / "out")], capsys),
                          "--observations", *fragments)
    assert not (tmp_path / "out").exists()


def test_read_observations_reads_unusual_units_when_told():
    import tempfile
    from pathlib import Path

    from comanip.recordings.observation_files import read_observations

    with tempfile.TemporaryDirectory() as folder:
        path = _observations(Path(folder) / "observed.csv", 1000.0)
        times, states = read_observations(path, 2, check_units=False)
        assert times[1] == pytest.approx(20.0) and states.shape == (21, 4)
        with pytest.raises(ValueError, match="look like degrees"):
            read_observations(_observations(Path(folder) / "degrees.csv", 1.0, 100.0), 2, joint_angles=True)


@pytest.mark.parametrize("goal, fragments", [
    ("2,0", ["the goal is 2 m from the start, beyond a person's reach", "peak hand speed"]),
    ("300,0", ["the goal is 300 m from the start", "is it in mm?"]),
])
def test_an_implausible_human_reach_is_planned_with_a_warning(tmp_path, capsys, goal, fragments):
    """Were a silent 'solved' at 8.5 m/s (2 m) and a bare 'goal_not_reached' (300, meant as mm)."""
    import json

    code = main(["plan", "--goal", goal, "--out", str(tmp_path)])
    err = capsys.readouterr().err
    warnings = [line for line in err.splitlines() if line.startswith("comanip plan: warning: ")]
    assert warnings and "Traceback" not in err, err
    for fragment in fragments:
        assert fragment in err, (fragment, err)
    saved = json.loads((tmp_path / "plan.json").read_text())
    assert "warning:" in saved["message"] and code in (0, 1)


def test_a_reach_within_a_persons_reach_has_no_warning(tmp_path, capsys):
    assert main(["plan", "--goal", "0.45,0", "--out", str(tmp_path)]) == 0
    assert "warning" not in capsys.readouterr().err


def test_help_texts_name_no_issue_session_or_spec(capsys):
    """Help is product text: no 'issue 11', 'session' or 'SPEC' (the formulation document's old name)."""
    import re

    from comanip.cli.main import build_parser

    def parsers(parser):
        yield parser
        for action in parser._actions:
            for sub in getattr(action, "choices", None) or {}:
                if isinstance(action.choices, dict):
                    yield from parsers(action.choices[sub])

    for parser in parsers(build_parser()):
        text = parser.format_help()
        assert not re.search(r"\bissue\s*\d|\bsession|\bSPEC\b", text, re.IGNORECASE), (parser.prog, text)


def test_numeric_arguments_out_of_range_are_one_line_before_any_work(tmp_path, capsys):
    """Fuzzed numbers reach no solver: each is refused in one line and no output folder is made."""
    out = tmp_path / "out"
    for argv, fragment in [(["plan", "--goal", "1e300,0"], "goal must lie within"),
                           (["plan", "--goal", "nan,0"], "goal must be finite"),
                           (["plan", "--max-wall-time", "0"], "max_wall_time"),
                           (["fit", "--mt-table", __file__, "--max-evaluations", "0", "--no-progress"], "--max-evaluations"),
                           (["fit", "--mt-table", __file__, "--sigma-obs", "nan", "--no-progress"], "sigma_obs"),
                           (["estimate", "--observed", "0.01,0,0.3,0", "--t-obs", "nan"], "t_obs")]:
        assert_one_line_error(*run_cli([*argv, "--out", str(out)], capsys), fragment)
        assert not out.exists(), argv


def test_an_observation_in_mm_gives_an_estimate_with_a_warning(tmp_path, capsys):
    """--observed in mm (10 mm, 300 mm/s read as m and m/s): the estimated reach is no person's, and says so."""
    main(["estimate", "--observed", "10,0,300,0", "--t-obs", "0.1", "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert "comanip estimate: warning: the goal is" in err and "peak hand speed" in err and "Traceback" not in err


class Built(BaseException):
    """Raised where a command would build a model, planner or estimator (BaseException, so the CLI's handler of
    user errors does not catch it): a test that sees it found an input checked too late."""


def _refuse_to_build(*args, **kwargs):
    raise Built


@pytest.mark.parametrize("extra, fragment", [
    (["--width", "-1"], "width"),
    (["--start", "0,0,0"], "start"),
    (["--prior", "0.3"], "prior_goal"),
    (["--prior-std", "-1"], "prior_std"),
    (["--max-wall-time", "0"], "max_wall_time"),
    (["--candidates", "0.3,0,0;0.2,0.2,0"], "--candidates"),
])
def test_estimate_checks_every_input_before_the_estimator_is_built(tmp_path, capsys, monkeypatch, extra, fragment):
    from comanip.cli import estimate_command

    monkeypatch.setattr(estimate_command, "GoalEstimator", _refuse_to_build)
    argv = ["estimate", "--observed", "0.01,0,0.3,0", "--t-obs", "0.1", *extra, "--out", str(tmp_path / "out")]
    assert_one_line_error(*run_cli(argv, capsys), fragment)
    assert not (tmp_path / "out").exists()


def test_estimate_refuses_the_paper_method_for_an_arm_before_the_estimator_is_built(tmp_path, capsys, monkeypatch):
    from comanip.cli import estimate_command

    monkeypatch.setattr(estimate_command, "GoalEstimator", _refuse_to_build)
    home = presets.franka().body.home_position
    observed = ",".join(str(v) for v in [*home, *[0.0] * 7])
    argv = ["estimate", "--preset", "franka", "--method", "paper", "--observed", observed, "--t-obs", "0.1",
            "--out", str(tmp_path / "out")]
    assert_one_line_error(*run_cli(argv, capsys), "method 'paper'")
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("extra, fragment", [
    (["--width", "-1"], "width"),
    (["--max-wall-time", "0"], "max_wall_time"),
    (["--goal", "0.3,0"], "goal"),
    (["--out", "{file}"], "is a file"),
])
def test_handover_checks_every_input_before_the_transition_model_or_planner_is_built(tmp_path, capsys, monkeypatch,
                                                                                     extra, fragment):
    from comanip.multicomponent import transition_model
    from comanip.planning import planner

    monkeypatch.setattr(transition_model, "TransitionModel", _refuse_to_build)
    monkeypatch.setattr(planner, "Planner", _refuse_to_build)
    (tmp_path / "file").write_text("not a folder")
    argv = ["handover", "--out", str(tmp_path / "out"), *[word.format(file=tmp_path / "file") for word in extra]]
    assert_one_line_error(*run_cli(argv, capsys), fragment)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("action, out", [("fit", "{file}"), ("plot", "{file}/transition.png")])
def test_transition_fit_and_plot_check_the_output_before_the_model_is_fitted(tmp_path, capsys, monkeypatch, action, out):
    from comanip.multicomponent import transition_model

    monkeypatch.setattr(transition_model, "TransitionModel", _refuse_to_build)
    (tmp_path / "file").write_text("not a folder")
    assert_one_line_error(*run_cli(["transition", action, "--out", out.format(file=tmp_path / "file")], capsys), "is a file")


def test_ros_replay_reads_its_csv_before_the_node_is_built(tmp_path, capsys, monkeypatch):
    pytest.importorskip("rclpy")
    from comanip.ros import replay

    monkeypatch.setattr(replay, "Replay", _refuse_to_build)
    hand = tmp_path / "hand.csv"
    hand.write_text("t_s,q0,q1,q2\n0,0,0,0\n")
    assert_one_line_error(*run_cli(["ros", "--replay", str(hand), "--out", str(tmp_path / "out")], capsys),
                          "needs the columns", "qdot0")
    assert not (tmp_path / "out").exists()


def test_python_dash_m_comanip_runs_the_command_and_reports_a_mistake_in_one_line():
    """``python -m comanip`` is the ``comanip`` command (how the ROS node runs in its own process): a mistake
    exits with status 2 and one line on stderr."""
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-m", "comanip", "plan", "--preset", "no_such_preset"], capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 2, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and "no_such_preset" in done.stderr
