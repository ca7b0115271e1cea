"""The core install plans and estimates without any extra, and asking for a part whose extra is missing says
which extra to install, in one line, from the Python API, the command line and the examples alike.

Each check runs in a fresh interpreter in which the extras' modules cannot be imported (``sys.modules[name] =
None``, which makes ``import name`` fail as for a module that is not installed), so that the installed extras of
the test environment do not hide an import of one of them."""

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from comanip.extras import EXTRAS, MissingExtra, exit_without, missing, require

ROOT = Path(__file__).resolve().parents[2]
BLOCKED = sorted({module for _, modules in EXTRAS.values() for module in modules} | {"pinocchio", "geometry_msgs"})
BLOCK = f"import sys\nfor name in {BLOCKED!r}:\n    sys.modules[name] = None\n"


def run_without_extras(code: str, *args: str) -> subprocess.CompletedProcess:
    """Run ``code`` in a fresh interpreter in which no extra's module can be imported."""
    env = {**os.environ, "MPLBACKEND": "Agg",
           "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT / "src"), os.environ.get("PYTHONPATH")]))}
    return subprocess.run([sys.executable, "-c", BLOCK + textwrap.dedent(code), *args], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=600)


def test_import_and_a_planar_reach_and_estimate_need_no_extra():
    run = run_without_extras("""
        import numpy as np
        import comanip

        model = comanip.presets.planar()
        plan = comanip.Planner(model).solve(np.zeros(4), [0.3, 0.0], 0.02)
        online = comanip.OnlineGoalEstimator(model, np.zeros(4))
        for i in range(1, 11):
            estimate = online.update(plan.t[i], plan.mean[i, :2], plan.mean[i, 2:])
        print(plan.status, np.round(estimate.goal, 2).tolist())
    """)
    assert run.returncode == 0, run.stderr[-3000:]
    status, goal = run.stdout.strip().splitlines()[-1].split(" ", 1)
    assert status == "solved"
    assert goal.startswith("[0.3")


@pytest.mark.parametrize("code, extra", [
    ("comanip.presets.franka()", "panda"),
    ("import comanip.simulation", "sim"),
    ("import comanip.ros.node", "ros"),
    ("import comanip.caching.worker_cache", "sweeps"),
])
def test_the_api_names_the_missing_extra_in_one_line(code, extra):
    run = run_without_extras(f"""
        import comanip
        from comanip.extras import MissingExtra
        try:
            {code}
        except MissingExtra as error:
            print(type(error).__mro__[1].__name__, error.extra, "|", error)
    """)
    assert run.returncode == 0, run.stderr[-3000:]
    base, named, message = run.stdout.strip().split(" ", 2)
    assert base == "ModuleNotFoundError" and named == extra
    assert f"needs the '{extra}' extra: pip install 'comanip[{extra}]'" in message and "\n" not in message.strip()


@pytest.mark.parametrize("argv, extra", [
    (["simulate", "sync", "--trials", "1"], "sim"),
    (["plan", "--preset", "franka"], "panda"),
    (["ros"], "ros"),
])
def test_the_command_line_names_the_missing_extra_in_one_line(tmp_path, argv, extra):
    run = run_without_extras("import sys\nfrom comanip.cli.main import main\nsys.exit(main(sys.argv[1:]))",
                             *argv, "--out", str(tmp_path / "out"))
    assert run.returncode == 2
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and f"needs the '{extra}' extra: pip install 'comanip[{extra}]'" in lines[0], run.stderr


@pytest.mark.parametrize("script, extra", [("ros_node_replay.py", "ros"), ("sync_scenario.py", "sim")])
def test_an_example_without_its_extra_prints_the_hint_not_a_traceback(script, extra):
    path = ROOT / "examples" / script
    run = run_without_extras(f"import runpy, sys\nsys.path.insert(0, {str(path.parent)!r})\n"
                             f"runpy.run_path({str(path)!r}, run_name='__main__')")
    assert run.returncode == 1
    assert run.stderr.strip().splitlines() == [str(MissingExtra(extra, EXTRAS[extra][1][0]))]


def test_require_and_missing_in_this_environment():
    assert require("math", "data").sqrt(4.0) == 2.0
    with pytest.raises(MissingExtra, match="the 'data' extra") as error:
        require("comanip_no_such_module", "data")
    assert isinstance(error.value, ImportError) and error.value.name == "comanip_no_such_module"
    with pytest.raises(ValueError, match="extra must be one of"):
        require("math", "no-such-extra")
    installed = [extra for extra in EXTRAS if _distributions_installed(extra)]
    assert installed, "the test environment installs the extras it tests"
    for extra in installed:    # an extra whose distributions are installed finds its modules
        assert missing(extra) is None, extra
    exit_without(*installed)   # returns: nothing is missing
    for extra in set(EXTRAS) - set(installed):
        assert missing(extra) is not None, extra


def _distributions_installed(extra: str) -> bool:
    """Whether every distribution pyproject.toml's ``extra`` names is installed (the tested set installs all of them;
    the oldest set every extra but 'data')."""
    import re
    import tomllib
    from importlib import metadata

    specs = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["optional-dependencies"][extra]
    names = [re.match(r"[A-Za-z0-9_.-]+", spec).group(0) for spec in specs]
    try:
        return all(metadata.version(name) for name in names if name != "comanip")
    except metadata.PackageNotFoundError:
        return False


def test_pyproject_states_ranges_and_the_constraints_pin_them():
    import re
    import tomllib

    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    core = project["dependencies"]
    assert not [spec for spec in core if "==" in spec], core
    names = {re.match(r"[A-Za-z0-9_.-]+", spec).group(0).lower() for spec in core}
    assert not names & {"mujoco", "dask", "adam-robotics", "example-robot-data", "liecasadi", "rosbags", "cursory"}, names
    extras = project["optional-dependencies"]
    assert set(EXTRAS) <= set(extras) and set(extras["all"][0].split("[")[1].rstrip("]").split(",")) == set(EXTRAS)
    pinned = {line.split("==")[0].lower().replace("_", "-") for line in (ROOT / "constraints.txt").read_text().splitlines()
              if "==" in line}
    wanted = {re.match(r"[A-Za-z0-9_.-]+", spec).group(0).lower().replace("_", "-")
              for specs in [core, *extras.values()] for spec in specs if not spec.startswith("comanip")}
    assert wanted <= pinned, sorted(wanted - pinned)


def test_ci_runs_the_readme_test_command_with_the_constraints():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    command = next(line for line in readme.splitlines() if "python -m pytest" in line and line.startswith("python3"))
    assert "-c constraints.txt" in command
    assert command in (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()


def test_the_lower_bounds_are_the_oldest_set():
    """Every lower bound in pyproject.toml (the core and every extra but 'data', whose cursory needs a newer numpy) is
    the version constraints-oldest.txt pins, the set CI runs the fast tests against."""
    import re
    import tomllib

    def name(text: str) -> str:
        return text.lower().replace("_", "-")

    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    extras = {extra: specs for extra, specs in project["optional-dependencies"].items() if extra not in ("data", "docs")}
    bounds = {name(match[1]): match[2] for spec in [*project["dependencies"], *sum(extras.values(), [])]
              if (match := re.match(r"([A-Za-z0-9_.-]+)(?:\[[^]]*\])?>=([0-9][^,;\s]*)", spec))}
    oldest = {name(pin): version for pin, version in
              re.findall(r"^([A-Za-z0-9_.-]+)==(\S+)$", (ROOT / "constraints-oldest.txt").read_text(), re.M)}
    assert "numpy" in bounds and "mujoco" in bounds
    assert {package: version for package, version in bounds.items() if oldest.get(package) != version} == {}
