"""docs/data_formats.md against the code: the documented columns, keys and shapes are the ones the code
writes and reads, so a format that changes without its documentation fails here.

Each format's section in the doc is a heading ``### <name>`` followed by a table whose first column holds the
column or key names in backticks; a name with ``{k}`` (degrees of freedom 0..n-1), ``{j}`` (activation stages
1..m) or ``{a}`` (task axes x, y[, z]) stands for one column per value, nested in the order they appear.
"""

import csv
import inspect
import itertools
import json
import re
from dataclasses import MISSING
from importlib import import_module
from pathlib import Path

import numpy as np
import pytest

import comanip
from comanip import presets
from comanip.belief.noise import NOISE_FORMS
from comanip.bodies import BODY_TYPES, body_from_config
from comanip.recordings.observation_files import read_observations
from comanip.cli.outputs import write_manifest
from comanip.estimation import GoalEstimator, OnlineEstimate, OnlineGoalEstimator, goal_posterior
from comanip.estimation.one_shot.goal_estimate import GoalEstimate
from comanip.fitting.movement_times import MT_COLUMNS
from comanip.recordings.trial_files import load_recordings
from comanip.planning.starts.arm_reach_library import bundled_library
from comanip.fitting.fit_result import FIT_STATUSES, FitResult
from comanip.model import ReachingModel
from comanip.multicomponent import transition_csv
from comanip.multicomponent.handover import HandoverSchedule
from comanip.multicomponent.transition_model import TransitionModel
from comanip.objectives.discounting import DISCOUNT_FORMS
from comanip.objectives.reward import GOAL_COVARIANCE_FORMS, REWARD_FORMS
from comanip.planning.plan import Plan
from comanip.simulation.scenario import TrialRecord
from tests.project.test_docs import subcommand_tree

DOC = Path(__file__).resolve().parents[2] / "docs" / "data_formats.md"


def section(heading: str) -> list[str]:
    """The lines of the doc's section ``### heading``, up to the next heading."""
    lines = DOC.read_text().splitlines()
    start = lines.index(f"### {heading}")
    end = next((k for k in range(start + 1, len(lines)) if lines[k].startswith("#")), len(lines))
    return lines[start + 1:end]


def table(heading: str, index: int = 0) -> list[list[str]]:
    """The body rows (cells, stripped) of the section's table number ``index``; ``\\|`` is a literal |."""
    blocks = [list(group) for is_row, group in itertools.groupby(section(heading), lambda l: l.startswith("|")) if is_row]
    return [[cell.strip() for cell in re.split(r"(?<!\\)\|", row.strip())[1:-1]] for row in blocks[index][2:]]


def code_block(heading: str) -> str:
    """The text of the section's first fenced code block, with a final newline."""
    lines = section(heading)
    start = next(k for k, line in enumerate(lines) if line.startswith("```"))
    end = lines.index("```", start + 1)
    return "\n".join(lines[start + 1:end]) + "\n"


def ticked(cell: str) -> list[str]:
    """The names in backticks in a cell, in order."""
    return re.findall(r"`([^`]+)`", cell)


def names(heading: str) -> list[str]:
    """The first backticked name of each row of the section's table."""
    return [ticked(row[0])[0] for row in table(heading)]


def expand(patterns: list[str], n: int = 0, stages: int = 0, axes: str = "xyz") -> list[str]:
    """Column names from the doc's patterns, one per value of each placeholder, nested in order."""
    values = {"k": range(n), "j": range(1, stages + 1), "a": axes}
    out = []
    for pattern in patterns:
        keys = re.findall(r"\{(\w)\}", pattern)
        out += [pattern.format(**dict(zip(keys, combo))) for combo in itertools.product(*(values[k] for k in keys))]
    return out


def documented_shapes(heading: str, sizes: dict) -> dict[str, tuple | None]:
    """{key: shape} from the first table's shape column (its second), the sizes' names (H, n, d, nx, K, C, T, ...)
    evaluated with ``sizes``; rows without a shape in parentheses are left out."""
    shapes = {}
    for row in table(heading):
        match = re.search(r"\(([^)]*)\)", row[1])
        if match:
            shapes[ticked(row[0])[0]] = tuple(eval(term, {}, dict(sizes)) for term in match.group(1).split(",") if term.strip())
    return shapes


def header(path: Path) -> list[str]:
    with open(path, newline="") as f:
        return next(csv.reader(f))


def check_shapes(data: dict, shapes: dict) -> None:
    for key, shape in shapes.items():
        if data[key] is not None:
            assert np.shape(data[key]) == shape, f"{key}: documented {shape}, written {np.shape(data[key])}"


@pytest.fixture(scope="module")
def planar_plan(planar_planner):
    return planar_planner.solve(np.zeros(4), [0.3, 0.1], 0.02)


@pytest.fixture(scope="module")
def human_plan():
    return comanip.Planner(presets.human()).solve(np.zeros(4), [0.2, 0.0], 0.02)


# ---- inputs ---------------------------------------------------------------------------------------------------

def test_model_yaml_keys_required_fields_and_allowed_words_are_the_models():
    rows = {ticked(row[0])[0]: row for row in table("Model YAML")}
    assert list(rows) == list(presets.planar().config())
    fields = ReachingModel.__dataclass_fields__
    required = [name for name, f in fields.items() if f.default is MISSING and f.default_factory is MISSING]
    assert [name for name, row in rows.items() if row[1] == "yes"] == required
    for key, forms in (("noise", NOISE_FORMS), ("goal_covariance", GOAL_COVARIANCE_FORMS), ("reward", REWARD_FORMS),
                       ("discount", DISCOUNT_FORMS)):
        assert set(ticked(rows[key][3])) == set(forms), key
        assert re.search(r"\(`(\w+)`\)$", rows[key][3]).group(1) == fields[key].default, key


def test_model_yaml_body_types_and_parameters_are_the_body_classes():
    documented = {ticked(row[0])[0]: ticked(row[1]) for row in table("Model YAML", 1)}
    assert set(documented) == set(BODY_TYPES)
    for kind, parameters in documented.items():
        module, cls = BODY_TYPES[kind].split(":")
        assert parameters == list(inspect.signature(getattr(import_module(module), cls)).parameters), kind
    assert body_from_config({"type": "point_mass", "n": 2, "mass": [[2.0, 0.0], [0.0, 2.0]]}).n == 2   # both mass forms load


def test_observations_example_is_read_and_its_documented_columns_are_required(tmp_path, planar_plan):
    columns = expand(names("Observations CSV"), n=2)
    example = code_block("Observations CSV")
    path = tmp_path / "reach.csv"
    path.write_text(example)
    assert header(path) == columns
    times, states = read_observations(path, 2)
    assert times.shape == (3,) and states.shape == (3, 4)
    rows = [dict(zip(columns, line.split(","))) for line in example.split()[1:]]
    for missing in columns:
        kept = [c for c in columns if c != missing]
        reduced = tmp_path / f"without_{missing}.csv"
        reduced.write_text(",".join(kept) + "\n" + "".join(",".join(r[c] for c in kept) + "\n" for r in rows))
        with pytest.raises(ValueError, match=missing):
            read_observations(reduced, 2)
    # a plan CSV reads back as observations, and the example estimates the goal the doc says
    assert np.allclose(read_observations(planar_plan.save_csv(tmp_path / "plan.csv"), 2)[1], planar_plan.mean)
    estimate = GoalEstimator(presets.planar()).estimate(states[0], states[-1], times[-1])
    assert np.allclose(estimate.goal, [0.3, 0.1], atol=2e-3) and estimate.success


def test_recordings_and_movement_time_columns(tmp_path):
    rows = {row[0]: row[1] for row in table("Recordings and movement-time tables")}
    assert tuple(ticked(rows["movement-time table"])) == MT_COLUMNS
    recording = [c for c in ticked(rows["recordings (a CSV, or a folder of them)"]) if not c.endswith("z")]
    path = tmp_path / "reaches.csv"
    path.write_text(",".join(recording) + "\n" + "".join(f"a,{0.02 * i},{0.01 * i},0,0.3,0,0.02\n" for i in range(4)))
    trial, = load_recordings(path)
    assert trial.name == "a" and trial.position.shape == (4, 2) and trial.width == 0.02
    trials_table = tmp_path / "trials.csv"
    trials_table.write_text(",".join(c for c in ticked(rows["trials table"]) if not c.endswith("z")) + "\na,0.3,0,0.02\n")
    bare = tmp_path / "bare" / "a.csv"
    bare.parent.mkdir()
    bare.write_text("t,x,y\n0,0,0\n0.02,0.01,0\n0.04,0.02,0\n")
    assert load_recordings(bare.parent, trials=trials_table)[0].width == 0.02


def test_transition_csv_columns_and_required_ones_are_transition_csv_columns():
    rows = table("Transition CSV")
    assert tuple(ticked(row[0])[0] for row in rows) == transition_csv.COLUMNS
    assert tuple(ticked(row[0])[0] for row in rows if row[1] == "yes") == transition_csv.REQUIRED_COLUMNS


def test_transition_sidecar_keys_are_the_shipped_datasets():
    metadata = transition_csv.read_transition_metadata(transition_csv.shipped_dataset_path())
    assert names("Transition-data sidecar JSON") == list(metadata)


def test_transition_model_json_keys(tmp_path):
    ratio, width = np.meshgrid([0.2, 0.5, 0.8], [0.01, 0.04])
    model = TransitionModel((ratio.ravel(), width.ravel(), 0.4 * ratio.ravel() + width.ravel()), n_restarts=0)
    saved = json.loads(model.save(tmp_path / "model.json").read_text())
    rows = {ticked(row[0])[0]: row for row in table("Transition model JSON")}
    assert list(rows) == list(saved)
    assert ticked(rows["kernel"][1]) == list(saved["kernel"])
    assert saved["kind"] == ticked(rows["kind"][1])[0]
    assert set(saved["training_data"]) <= set(transition_csv.COLUMNS)
    TransitionModel.load(tmp_path / "model.json")


def test_arm_reach_library_arrays_are_the_saved_ones(tmp_path):
    model = presets.load("franka_rest")
    library = bundled_library(model)
    rows = {ticked(row[0])[0]: row for row in table("Arm reach library (npz)")}
    with np.load(library.save(tmp_path / "library.npz")) as saved:
        assert list(rows) == list(saved.files)
        E, H, n = len(library.goals), model.H, model.n
        sizes = {"E": E, "H": H, "n": n, "2n": 2 * n, "3": 3}
        for name, row in rows.items():
            shape = tuple(sizes[part.strip()] for part in row[1].strip("()").split(",") if part.strip())
            assert saved[name].shape == shape, name


def test_people_model_arrays_are_the_saved_ones(tmp_path):
    from comanip.estimation.people.people_model import shipped_people_model

    def expanded(name: str) -> list[str]:                 # {a,b}_{x,y} names every a_x, a_y, b_x, b_y
        parts = [part.split(",") for part in re.split(r"\{([^}]*)\}", name)]
        return ["".join(choice) for choice in itertools.product(*parts)]

    documented = [full for row in table("People model (npz)") for name in ticked(row[0]) for full in expanded(name)]
    with np.load(shipped_people_model("arm").save(tmp_path / "people.npz")) as saved:
        assert sorted(documented) == sorted(saved.files)


# ---- outputs --------------------------------------------------------------------------------------------------

def test_every_command_has_its_row_of_files_and_the_manifest_keys(tmp_path):
    tree = subcommand_tree()
    commands = [ticked(row[0])[0].split()[1:] for row in table("Output folders and their files")]
    subcommands = set(tree)
    assert {words[0] for words in commands} == subcommands
    assert all(set(words[1].replace("\\|", "|").split("|")) <= tree[words[0]] for words in commands if len(words) > 1)
    manifest_rows = {ticked(row[0])[0]: row for row in table("manifest.json")}
    assert set(ticked(manifest_rows["command"][1])) == subcommands
    (tmp_path / "plan.csv").write_text("t_s\n0\n")
    manifest = json.loads(write_manifest(tmp_path, "plan", [tmp_path / "plan.csv"]).read_text())
    assert list(manifest_rows) == list(manifest)
    assert re.fullmatch(r"\d{4}-\d\d-\d\d \d\d:\d\d:\d\d", manifest["written"]) and list(manifest["files"]) == ["plan.csv"]


@pytest.mark.parametrize("which", ["planar", "human"])
def test_plan_csv_header_follows_the_documented_rule(tmp_path, which, planar_plan, human_plan):
    plan = planar_plan if which == "planar" else human_plan
    n, d = plan.torque.shape[1], plan.ee_mean.shape[1]
    stages = (plan.mean.shape[1] - 2 * n) // n
    assert stages == (0 if which == "planar" else 2)
    written = header(plan.save_csv(tmp_path / "plan.csv"))
    assert written == expand(names("Plan CSV"), n=n, stages=stages, axes="xyz"[:d])
    with open(tmp_path / "plan.csv") as f:
        assert sum(1 for _ in f) == 1 + len(plan.t)
    # the examples written out in the text
    planar_header = code_block("Plan CSV").strip().split(",")
    added, after = re.search(r"adds `([^`]+)` after `([^`]+)`", " ".join(section("Plan CSV"))).groups()
    at = planar_header.index(after) + 1
    assert written == (planar_header if which == "planar" else planar_header[:at] + added.split(",") + planar_header[at:])


@pytest.mark.parametrize("which", ["planar", "human"])
def test_plan_json_keys_and_shapes(which, planar_plan, human_plan):
    plan = planar_plan if which == "planar" else human_plan
    data = json.loads(json.dumps(plan.to_dict()))
    assert names("Plan JSON") == list(data)
    sizes = {"H": len(plan.torque), "n": plan.torque.shape[1], "d": plan.ee_mean.shape[1], "nx": plan.mean.shape[1]}
    check_shapes(data, documented_shapes("Plan JSON", sizes))


def test_goal_estimate_and_posterior_json_keys_and_shapes(planar_planner, planar_plan):
    estimate = GoalEstimator(planar_planner).estimate(np.zeros(4), planar_plan.mean[10], planar_plan.t[10])
    data = json.loads(json.dumps(estimate.to_dict()))
    assert list(data) == names("Plan JSON") + names("Goal estimate JSON")
    assert [f for f in GoalEstimate.__dataclass_fields__ if f not in Plan.__dataclass_fields__] == names("Goal estimate JSON")
    sizes = {"H": 30, "n": 2, "d": 2, "nx": 4, "rows": len(estimate.multipliers)}
    check_shapes(data, documented_shapes("Goal estimate JSON", sizes))
    steps = [5, 10, 15]
    posterior = goal_posterior(planar_planner, np.zeros(4), planar_plan.mean[steps], planar_plan.t[steps], [[0.3, 0.1], [0.2, 0.2]])
    data = json.loads(json.dumps(posterior.to_dict()))
    assert names("Posterior JSON") == list(data)
    check_shapes(data, documented_shapes("Posterior JSON", {"K": 3, "C": 2, "d": 2}))


def test_online_estimate_json_keys_and_shapes(planar_planner, planar_plan, tmp_path):
    """Mid-reach on a plan's own hand: every documented key in order, the documented shapes, the path's too."""
    estimator = OnlineGoalEstimator(planar_planner, np.zeros(4))
    for k in range(1, 12):
        estimate = estimator.update(planar_plan.t[k], planar_plan.ee_mean[k], planar_plan.ee_velocity[k])
    assert estimate.success and estimate.forecast is not None
    data = json.loads(estimate.save_json(tmp_path / "estimate.json").read_text())
    assert list(data) == names("Online estimate JSON") == ["success", *OnlineEstimate.__dataclass_fields__]
    check_shapes(data, documented_shapes("Online estimate JSON", {"n": 2, "d": 2, "nx": 4}))
    K1 = len(data["path"]["t_s"])
    assert K1 > 2 and data["path"]["t_s"][0] == pytest.approx(planar_plan.t[11])
    shapes = {"position_m": (K1, 2), "velocity_m_s": (K1, 2), "covariance_m2": (K1, 2, 2)}
    assert {key: np.shape(data["path"][key]) for key in shapes} == shapes
    assert np.shape(data["timed_reach"]["mean"]) == (len(data["timed_reach"]["t"]), 4)
    assert set(data["forecast"]) == {"stop_time_s", "pace", "phase_s"}


def test_handover_schedule_csv_and_json(tmp_path):
    t = np.linspace(0.0, 0.3, 4)
    path = np.outer(t, [1.0, 0.5, 0.0])
    schedule = HandoverSchedule(t=t, rest_position=path, rest_velocity=np.tile([1.0, 0.5, 0.0], (4, 1)),
                                stiffness=np.array([400.0, 400.0, 200.0, 0.0]), goal=np.array([0.3, 0.15, 0.0]), width=0.02,
                                goal_distance=0.335, transition_distance=0.1, transition_distance_std=0.01,
                                transition_time=0.1, transition_position=path[1], ramp_time=0.2, leading_stiffness=400.0,
                                status="within_plan")
    assert header(schedule.save_csv(tmp_path / "handover_0.csv")) == expand(names("Handover schedule CSV"), axes="xyz")
    data = json.loads(schedule.save_json(tmp_path / "handover_0.json").read_text())
    assert names("Handover schedule JSON") == list(data)
    check_shapes(data, documented_shapes("Handover schedule JSON", {"T": 4, "d": 3}))


def test_simulation_trial_csv_columns(tmp_path):
    K = 11
    arrays = {name: np.zeros((K, 3)) for name in TrialRecord.COLUMNS}
    record = TrialRecord(t=np.arange(K) * 1e-3, goal=np.zeros(3), **arrays)
    record.save_csv(tmp_path / "sync_near_trial0.csv")
    assert header(tmp_path / "sync_near_trial0.csv") == expand(names("Simulation trial CSV"), axes="xyz")
    times = np.loadtxt(tmp_path / "sync_near_trial0.csv", delimiter=",", skiprows=1)[:, 0]
    assert np.allclose(np.diff(times), 0.005)     # "one row every 5 ms" of the 1 kHz loop


def test_fit_json_keys_are_fit_results(tmp_path):
    result = FitResult(success=False, status="failed", message="", model=presets.planar(), values={"kappa": 0.01},
                       initial_values={"kappa": 0.01}, std_errors={"kappa": np.nan}, laplace_std_errors={"kappa": np.nan},
                       objective=np.nan, objective_kind="", evaluations=0, fit_time=0.0)
    data = json.loads(result.save_json(tmp_path / "fit.json").read_text())
    assert names("Fit JSON") == list(data)
    assert data["model"] == presets.planar().config() and data["objective"] is None     # NaN as null
    statuses = ticked(table("Fit JSON")[1][1])
    assert tuple(statuses) == FIT_STATUSES
