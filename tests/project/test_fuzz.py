"""Fuzz the public API and the CLI with bad and extreme inputs (hypothesis).

Each input must give a ValueError with a message, or a plan with a status and finite arrays: never another
exception or a silent NaN. The count of inputs tried is printed at the end of the session (conftest.py).
"""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import comanip
from comanip.cli.main import main
from comanip.estimation import GoalEstimator

pytestmark = pytest.mark.slow  # about 30 s: CI runs it; the fast subset (-m "not slow") leaves it out

FUZZ_COUNT = {"inputs": 0}
# whether the inputs are the same every run (CI) or new each run (locally) is the profile's choice: tests/conftest.py
FAST = settings(max_examples=150)

numbers = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-10**12, 10**12),
                    st.sampled_from([0.0, -0.0, 1e-300, 1e300, -1e300]))
vectors = st.one_of(st.lists(numbers, min_size=0, max_size=6), numbers, st.text(max_size=5), st.none(),
                    st.lists(st.lists(numbers, min_size=1, max_size=3), min_size=1, max_size=3))


@pytest.fixture(scope="module")
def small_planner():
    return comanip.Planner(comanip.presets.planar().replace(H=8))


def check_plan_or_value_error(call):
    """call() returns a Plan with a status and finite arrays, or raises ValueError with a message."""
    FUZZ_COUNT["inputs"] += 1
    try:
        plan = call()
    except ValueError as error:
        assert str(error), "ValueError without a message"
        return
    assert isinstance(plan.status, str) and plan.status
    for name in ("t", "mean", "cov", "torque", "ee_mean", "ee_cov", "ee_velocity"):
        assert np.all(np.isfinite(getattr(plan, name))), (name, plan.status)
    assert math.isfinite(plan.objective) or not plan.success


@FAST
@given(start=vectors, goal=vectors, width=st.one_of(numbers, st.none()), wall=st.one_of(numbers, st.none()))
def test_planner_solve(small_planner, start, goal, width, wall):
    check_plan_or_value_error(lambda: small_planner.solve(start, goal, width, max_wall_time=wall if wall is None else
                                                          (min(wall, 2.0) if isinstance(wall, (int, float)) and wall > 0 else wall)))


@FAST
@given(goal=st.lists(st.floats(-1e6, 1e6), min_size=2, max_size=2), width=st.floats(1e-6, 1e3))
def test_planner_solve_extreme_but_valid(small_planner, goal, width):
    check_plan_or_value_error(lambda: small_planner.solve(np.zeros(4), goal, width, max_wall_time=2.0))


model_fields = st.fixed_dictionaries({}, optional={
    "h": numbers, "H": st.one_of(st.integers(-5, 12), numbers), "gamma": numbers, "nu": numbers, "kappa": numbers,
    "width": numbers, "noise": st.text(max_size=8), "reward": st.sampled_from(["gaussian", "hit", "bogus", ""]),
    "effective_k": numbers, "stop_weight": numbers, "joint_velocity_weight": numbers, "activation": st.lists(numbers, max_size=2),
    "discount": st.sampled_from(["exponential", "hyperbolic", "x"])})


@FAST
@given(changes=model_fields)
def test_model_parameters_then_a_plan(changes):
    def build_and_plan():
        model = comanip.presets.planar().replace(H=6).replace(**changes)
        if model.H > 12:
            raise ValueError("horizon too long for the fuzz budget")
        return comanip.Planner(model).solve(np.zeros(4), [0.2, 0.0], max_wall_time=2.0)
    check_plan_or_value_error(build_and_plan)


yaml_texts = st.one_of(st.text(max_size=60), st.sampled_from([
    "name: [unclosed", "", "- 1", "body: 3", "body: {type: point_mass}", "body: {type: point_mass, n: 7}\nh: 1",
    "h: 0.02\nH: 30\ngamma: 0.9\nnu: 1\nkappa: 0.1\nwidth: 0.01\nbody: {type: panda, damping: x}",
    "h: .nan\nH: 30\ngamma: 0.9\nnu: 1\nkappa: 0.1\nwidth: 0.01\nbody: {type: point_mass, n: 2}"]))


@FAST
@given(text=yaml_texts)
def test_presets_load_any_file(tmp_path_factory, text):
    FUZZ_COUNT["inputs"] += 1
    path = tmp_path_factory.mktemp("yaml") / "model.yaml"
    path.write_text(text)
    try:
        comanip.presets.load(path)
    except ValueError as error:
        assert str(error) and "\n" not in str(error)


arguments = st.lists(st.one_of(st.sampled_from(["--goal", "--start", "--width", "--max-wall-time", "--candidates",
                                                "--t-obs", "--observed", "--prior", "--preset", "--method"]),
                               st.text(alphabet="0123456789.,;-e naif", max_size=12)), max_size=6)


@settings(max_examples=400)
@given(command=st.sampled_from(["plan", "estimate"]), argv=arguments)
def test_cli_never_tracebacks(tmp_path_factory, capsys, command, argv):
    FUZZ_COUNT["inputs"] += 1
    out = tmp_path_factory.mktemp("out")
    code = main([command, *argv, "--out", str(out), "--max-wall-time", "1"] + (["--preset", "planar"] if "--preset" not in argv else []))
    err = capsys.readouterr().err
    assert code in (0, 1, 2), (argv, code)
    assert "Traceback" not in err
    if code == 2:
        assert err.count("\n") == 1 and "error:" in err, err


@pytest.fixture(scope="module")
def small_estimator():
    return GoalEstimator(comanip.presets.planar().replace(H=8))


@FAST
@given(observed=vectors, t_obs=numbers, prior=st.one_of(st.none(), vectors), width=st.one_of(st.none(), numbers))
def test_goal_estimate(small_estimator, observed, t_obs, prior, width):
    check_plan_or_value_error(lambda: small_estimator.estimate(np.zeros(4), observed, t_obs, prior, width, max_wall_time=2.0))


def test_found_by_fuzzing_a_huge_activation_time_constant_is_refused():
    with pytest.raises(ValueError, match="activation time constants must be ≤ 1000 h"):
        comanip.presets.planar().replace(activation=[3.6e14])


# --- the Panda: any start pose, singular and beyond the joint limits included ------------------------------------

@pytest.fixture(scope="module")
def franka_planner():
    return comanip.Planner(comanip.presets.franka())


def franka_poses():
    """q (7,) rad: the home pose, singular poses (arm stretched: q4 at its upper limit, q6 at 0 or pi; every
    joint at 0), joints at and beyond their limits, or anything finite or not."""
    body = comanip.presets.franka().body
    q_min, q_max = np.asarray(body.q_min, float), np.asarray(body.q_max, float)
    stretched = np.array([0, 0, 0, q_max[3], 0, 0, 0])
    special = [np.asarray(body.home_position, float), np.zeros(7), stretched, stretched + [0, 0, 0, 0, 0, np.pi, 0],
               q_min, q_max, q_max + 0.5]
    joint = st.one_of(st.floats(-4.0, 4.0), st.sampled_from([math.nan, math.inf, 0.0]))
    return st.one_of(st.sampled_from(special), st.lists(joint, min_size=7, max_size=7).map(np.array),
                     st.lists(joint, min_size=0, max_size=9))


@settings(max_examples=30)
@given(q=franka_poses(), qdot=st.one_of(st.just(np.zeros(7)), st.lists(st.floats(-5.0, 5.0), min_size=7, max_size=7).map(np.array)),
       goal=st.one_of(st.lists(st.floats(-2.0, 2.0), min_size=3, max_size=3), vectors))
def test_franka_any_pose(franka_planner, q, qdot, goal):
    """A plan with a status and finite arrays within its wall-time budget, or a ValueError: never a crash or a NaN."""
    start = np.r_[np.ravel(np.asarray(q, float)), qdot] if np.size(q) == 7 else q
    check_plan_or_value_error(lambda: franka_planner.solve(start, goal, max_wall_time=0.5))


# --- the long-running commands: every input is checked before any work ------------------------------------------

class InputsAccepted(BaseException):
    """Raised where a command would start its work: every argument got past the checks (BaseException, so the
    CLI's handler of user errors does not catch it)."""


def _accept(*args, **kwargs):
    raise InputsAccepted


numbers_text = st.text(alphabet="0123456789.,;-e naif", max_size=10)
SCALARS = ["1", "3", "0.3", "0.05", "0", "-1", "1e9", "1e-9", "nan", "inf", "2.5"]
VECTORS = ["0.3,0.1", "0.3,0,0.2", "0.45,0.15,0.2", "0,0,0,0", "0,0,0,0,0,0", "0.2,0.4", "0.2,-0.4", "nan,0,0",
           "1e9,0,0", "0.3"]
#: option: values a user might plausibly type (in range or not); random text is drawn too
LONG_COMMANDS = {
    "simulate": (["simulate"], {"--trials": SCALARS, "--goal": ["near", "far", *VECTORS], "--width": SCALARS,
                                "--kappa": SCALARS, "--seed": SCALARS, "--duration": SCALARS},
                 ("comanip.simulation.scenario_runs", "ScenarioSetup")),
    "handover": (["handover"], {"--start": VECTORS, "--goal": VECTORS, "--width": SCALARS, "--ramp-time": SCALARS,
                                "--stiffness": SCALARS, "--rate": SCALARS, "--arm-length": SCALARS,
                                "--max-wall-time": SCALARS, "--preset": ["planar", "cartesian", "human", "nope"]},
                 ("comanip.planning.planner", "Planner")),
    "transition generate": (["transition", "generate"], {"--distances": VECTORS, "--widths": VECTORS, "--trials": SCALARS,
                                                         "--arm-length": SCALARS, "--steps": SCALARS, "--seed": SCALARS,
                                                         "--workers": SCALARS, "--preset": ["planar", "cartesian", "franka"]},
                            ("comanip.cli.transition_command", "generate_transition_data")),
    "library": (["library"], {"--spacing": SCALARS, "--shell": ["0.12 0.33", "0.3 0.1", "0.1", "-1 2", "0 nan"],
                              "--preset": ["franka_rest", "planar", "nope"]},
                ("comanip.cli.library_command", "Planner")),
}
#: the --out each command writes (a folder unless named here)
OUT_FILES = {"transition generate": "data.csv", "library": "library.npz"}


@settings(max_examples=300)
@given(command=st.sampled_from(sorted(LONG_COMMANDS)), data=st.data())
def test_long_commands_give_one_line_errors(tmp_path_factory, capsys, monkeypatch, command, data):
    """simulate, handover, transition generate and library: a user mistake is one line and exit status 2, never a
    traceback. Inputs that pass every check reach the command's work, replaced here by InputsAccepted so that
    the suite does not wait for simulations (about one input in ten gets there)."""
    import importlib

    FUZZ_COUNT["inputs"] += 1
    words, options, (module, work) = LONG_COMMANDS[command]
    scenario = [data.draw(st.sampled_from(["sync", "handover", "bogus", ""]))] if command == "simulate" else []
    names = data.draw(st.lists(st.sampled_from(sorted(options)), max_size=4))
    # a value with spaces is several words (--shell takes two)
    argv = [word for name in names for word in (name, *data.draw(st.one_of(st.sampled_from(options[name]), numbers_text)).split(" "))]
    argv += data.draw(st.lists(numbers_text, max_size=1))
    out = tmp_path_factory.mktemp("out") / OUT_FILES.get(command, "")
    with monkeypatch.context() as patch:
        patch.setattr(importlib.import_module(module), work, _accept)
        try:
            code = main([*words, *scenario, *argv, "--out", str(out)])
        except InputsAccepted:
            return
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert code == 2, (argv, code, err)
    assert err.count("\n") == 1 and "error:" in err, err


@FAST
@given(text=st.one_of(st.text(max_size=80), st.sampled_from([
    "", "distance_over_arm_length,width_m\n", "distance_over_arm_length,width_m,transition_distance_m\n0.2,0.01,nan\n",
    "distance_over_arm_length,width_m,transition_distance_m\n0.2,0.01\n", "a,b,c\n1,2,3\n", "\x00\x01"])),
       command=st.sampled_from(["fit", "plot"]))
def test_transition_data_files(tmp_path_factory, capsys, text, command):
    """transition fit/plot --data with an empty, malformed or half-filled CSV: one line, status 2."""
    FUZZ_COUNT["inputs"] += 1
    folder = tmp_path_factory.mktemp("data")
    data = folder / "transition.csv"
    data.write_text(text)
    out = folder / ("out" if command == "fit" else "out/figure.png")
    code = main(["transition", command, "--data", str(data), "--out", str(out)])
    err = capsys.readouterr().err
    assert "Traceback" not in err
    if code != 0:
        assert code == 2 and err.count("\n") == 1 and "error:" in err, err


# --- regressions: inputs the fuzzing found -----------------------------------------------------------------------

@pytest.mark.parametrize("goal", [[0.0, 1.3407807929942597e154], [1e200, 0.0], [0.0, -1.0000001e6]])
def test_found_by_fuzzing_a_goal_whose_distance_overflows_is_a_value_error(small_planner, goal):
    """Was OverflowError: the reach library's grid index of an infinite distance (reach_library.py)."""
    with pytest.raises(ValueError, match="goal must lie within ±1e\\+06 per coordinate"):
        small_planner.solve(np.zeros(4), goal)


def test_the_reach_library_skips_a_distance_that_overflows():
    from comanip.planning.reach_parameters import ReachParameters
    from comanip.planning.starts.reach_library import ReachLibrary

    library = ReachLibrary(None, lambda params: pytest.fail("no entry to solve"), 2, 4, 0.02)
    assert library.guess(ReachParameters(np.zeros(4), np.array([0.0, 1.35e154]), 0.02)) is None


@pytest.mark.parametrize("h", [1e-300, 1e-5, 2.0, 1e12, math.nan])
def test_found_by_fuzzing_a_time_step_out_of_range_is_a_value_error(h):
    """Was a plan ending 'failed' with NaN arrays (h = 1e-300 s: the torques overflow)."""
    with pytest.raises(ValueError, match="h must be a number between 0.0001 and 1 \\(s, time step\\)"):
        comanip.presets.planar().replace(h=h)


# --- fitting: every argument and recording checked before any plan --------------------------------------------------

def _trial():
    from comanip.fitting import Trial

    t = np.arange(0.0, 0.62, 0.02)
    return Trial("a", t, np.column_stack([0.3 * t / 0.6, 0 * t]), np.array([0.3, 0.0]), 0.02)


@FAST
@given(sigma_obs=numbers, start_tolerance=numbers, max_evaluations=st.one_of(numbers, st.booleans()), step=numbers,
       bounds=st.one_of(st.none(), st.dictionaries(st.sampled_from(["kappa", "gamma", "nu"]),
                                                   st.one_of(st.tuples(numbers, numbers), numbers, st.text(max_size=3)), max_size=2)),
       parameters=st.one_of(st.lists(st.sampled_from(["kappa", "gamma", "nu", "sigma_obs", "H", "bogus", "kappa.0"]), max_size=3),
                            st.text(max_size=6)))
def test_fit_model_arguments(monkeypatch, sigma_obs, start_tolerance, max_evaluations, step, bounds, parameters):
    """fit_model refuses a bad argument with a ValueError before it plans anything (planning is replaced by
    InputsAccepted here)."""
    import comanip.fitting.fit as fit

    FUZZ_COUNT["inputs"] += 1
    with monkeypatch.context() as patch:
        patch.setattr(fit, "ConditionPlanner", _accept)
        try:
            fit.fit_model(comanip.presets.planar(), [_trial()], parameters, sigma_obs=sigma_obs, bounds=bounds,
                          start_tolerance=start_tolerance, max_evaluations=max_evaluations, step=step, progress=False)
        except InputsAccepted:
            return
        except ValueError as error:
            assert str(error) and "\n" not in str(error)


@FAST
@given(text=st.one_of(st.text(max_size=120), st.lists(st.tuples(st.sampled_from(["a", "b"]), numbers, numbers, numbers),
                                                      min_size=1, max_size=8).map(
    lambda rows: "trial,t,x,y,goal_x,goal_y,width\n" + "".join(f"{r[0]},{r[1]},{r[2]},{r[3]},0.3,0,0.02\n" for r in rows))))
def test_load_recordings_any_file(tmp_path_factory, text):
    from comanip.fitting import load_recordings

    FUZZ_COUNT["inputs"] += 1
    path = tmp_path_factory.mktemp("rec") / "r.csv"
    path.write_text(text)
    try:
        trials = load_recordings(path)
    except ValueError as error:
        assert str(error) and "\n" not in str(error)
    else:
        assert all(np.all(np.isfinite(trial.t)) and np.all(np.diff(trial.t) > 0) for trial in trials)


def test_a_start_beyond_the_documented_range_is_a_value_error(small_planner):
    with pytest.raises(ValueError, match="start must lie within ±1e\\+06 per coordinate"):
        small_planner.solve([1e300, 0.0, 0.0, 0.0], [0.3, 0.0])


def test_a_horizon_beyond_the_documented_range_is_a_value_error():
    with pytest.raises(ValueError, match="H must be ≤ 1000"):
        comanip.presets.planar().replace(H=10**9)
