"""CasADi functions compiled to C and their disk cache (comanip.caching.compiled): keys, tags, background builds,
compilers stopped at exit, and the source fingerprint."""

import shutil
import subprocess
import warnings

import casadi as ca
import numpy as np

from comanip.caching import compiled as compiled_module
from comanip.caching.buffered_function import BufferedFunction
from comanip.caching.compiled import compile_in_background, compiled


def test_compiled_cache_keys_on_the_function_and_falls_back_without_a_compiler(tmp_path, monkeypatch):
    monkeypatch.setenv("COMANIP_CACHE_DIR", str(tmp_path))
    x = ca.SX.sym("x", 3)
    for kappa in (1.0, 2.0):
        f = ca.Function("cached_test", [x], [kappa * ca.sin(x) * ca.sumsqr(x)])
        fast = compiled(f)
        point = np.array([0.3, -1.0, 2.0])
        np.testing.assert_allclose(np.asarray(fast(point)).ravel(), np.asarray(f(point)).ravel(), rtol=1e-14)
    libraries = sorted(tmp_path.glob("cached_test_*.so"))
    assert len(libraries) == 2  # a changed constant is a changed function: a new library
    stamp = libraries[0].stat().st_mtime_ns
    compiled(ca.Function("cached_test", [x], [1.0 * ca.sin(x) * ca.sumsqr(x)]))
    assert libraries[0].stat().st_mtime_ns == stamp and len(list(tmp_path.glob("*.so"))) == 2  # reused, not rebuilt
    monkeypatch.setenv("CC", str(tmp_path / "no-such-compiler"))
    g = ca.Function("uncompiled_test", [x], [ca.cos(x)])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fallback = compiled(g)
    assert any("could not compile" in str(w.message) for w in caught)
    np.testing.assert_allclose(BufferedFunction(fallback)(np.ones(3))[0].ravel(), np.cos(np.ones(3)))


def test_a_build_for_this_processor_is_keyed_on_it_and_falls_back_to_the_plain_flags(tmp_path, monkeypatch):
    monkeypatch.setenv("COMANIP_CACHE_DIR", str(tmp_path))
    x = ca.SX.sym("x", 3)
    f = ca.Function("processor_test", [x], [ca.sin(x) * ca.sumsqr(x) + x[0] * x[1]])
    point = np.array([0.3, -1.0, 2.0])
    monkeypatch.setattr(compiled_module, "_processor", lambda: "fingerprint-a")
    monkeypatch.setattr(compiled_module, "PROCESSOR_FLAGS", ("-O2", "-mno-such-instructions", "-fPIC", "-shared"))
    assert compiled_module._flags(True) == ["-O2", "-mno-such-instructions", "-fPIC", "-shared",
                                            "-DCOMANIP_PROCESSOR=fingerprint-a"]
    assert compiled_module._flags(False) == list(compiled_module.COMPILE_FLAGS)
    # flags the compiler rejects: the plain build, same numbers up to rounding, filed under the plain flags
    fast = compiled_module.compiled_or_cached(f, "model A", for_this_processor=True)
    np.testing.assert_allclose(np.asarray(fast(point)).ravel(), np.asarray(f(point)).ravel(), rtol=1e-14)
    assert compiled_module.cached_compiled("processor_test", "model A") is not None
    assert compiled_module.cached_compiled("processor_test", "model A", for_this_processor=True) is None
    monkeypatch.setattr(compiled_module, "_processor", lambda: None)  # a compiler that names no processor
    assert compiled_module._flags(True) == list(compiled_module.COMPILE_FLAGS)


def test_a_build_for_this_processor_matches_the_uncompiled_function(tmp_path, monkeypatch):
    monkeypatch.setenv("COMANIP_CACHE_DIR", str(tmp_path))
    x = ca.SX.sym("x", 4)
    f = ca.Function("native_test", [x], [ca.mtimes(ca.reshape(ca.cos(x), 2, 2), ca.reshape(x, 2, 2)) * ca.sumsqr(x)])
    point = np.array([0.3, -1.0, 2.0, 0.7])
    fast = compiled(f, for_this_processor=True)
    np.testing.assert_allclose(np.asarray(fast(point)), np.asarray(f(point)), rtol=1e-13, atol=1e-15)


def test_a_tagged_build_is_found_without_generating_source_and_only_for_the_same_libraries(tmp_path, monkeypatch):
    monkeypatch.setenv("COMANIP_CACHE_DIR", str(tmp_path))
    x = ca.SX.sym("x", 2)
    f = ca.Function("tagged_test", [x], [ca.sin(x) * x[1]])
    first = compiled_module.compiled_or_cached(f, "model A")
    monkeypatch.setattr(ca, "CodeGenerator", None)  # generating source now fails
    again = compiled_module.compiled_or_cached(f, "model A")
    point = np.array([0.2, 3.0])
    np.testing.assert_array_equal(np.asarray(again(point)), np.asarray(first(point)))
    assert compiled_module.cached_compiled("tagged_test", "model B") is None
    version = compiled_module.metadata.version
    monkeypatch.setattr(compiled_module.metadata, "version", lambda name: "0.0" if name == "adam-robotics" else version(name))
    compiled_module._source_fingerprint.cache_clear()
    try:
        assert compiled_module.cached_compiled("tagged_test", "model A") is None  # another adam: another dynamics
    finally:
        monkeypatch.undo()
        compiled_module._source_fingerprint.cache_clear()


def test_background_compile_skips_a_collected_owner_and_builds_for_a_live_one(tmp_path, monkeypatch):
    monkeypatch.setenv("COMANIP_CACHE_DIR", str(tmp_path))
    x = ca.SX.sym("x", 2)

    class Owner:
        function = ca.Function("background_test", [x], [ca.exp(x) * x[0]])

    kept, dropped = Owner(), Owner()
    with compiled_module.compilers().turn:  # as if another build were running: both wait their turn
        gone = compile_in_background(dropped, lambda owner: [owner.function])
        built = compile_in_background(kept, lambda owner: [owner.function])
        del dropped  # collected before its turn
    assert gone.result(timeout=120) is None
    point = np.array([0.5, -2.0])
    np.testing.assert_array_equal(np.asarray(built.result(timeout=120)[0](point)), np.asarray(Owner.function(point)))
    assert len(list(tmp_path.glob("background_test_*.so"))) == 1


def test_a_compiler_running_at_exit_is_stopped_and_its_scratch_removed(tmp_path):
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    process = subprocess.Popen(["sleep", "60"])
    compiled_module.compilers().running[process] = str(scratch)
    try:
        compiled_module.compilers().stop_running()
    finally:
        compiled_module.compilers().running.pop(process, None)
    assert process.poll() is not None and not scratch.exists()


def test_the_compile_cache_survives_an_edit_outside_what_the_compiled_functions_are_built_from(tmp_path):
    """The fingerprint that keys compiled functions (the Panda's take minutes to build) changes with the code they
    are built from (the objective, the reach problem, a body), not with the people model, a plot, a command or a
    scenario."""
    package = tmp_path / "comanip"
    shutil.copytree(compiled_module.PACKAGE, package, ignore=shutil.ignore_patterns("__pycache__", "*.pkl", "*.npz"))
    before = compiled_module._source_fingerprint(package)
    for outside in ("estimation/people/people_model.py", "estimation/online/online_estimator.py", "plots/plan_figure.py", "plots/__init__.py",
                    "cli/main.py", "simulation/sync_scenario.py", "recordings/recording.py"):
        (package / outside).write_text((package / outside).read_text() + "\n# an edit\n")
        assert compiled_module._source_fingerprint.__wrapped__(package) == before, outside
    for inside in ("objectives/reward.py", "planning/reach_problem.py", "bodies/panda.py", "model.py"):
        edited = tmp_path / inside.replace("/", "_")
        shutil.copytree(package, edited / "comanip")
        (edited / "comanip" / inside).write_text((edited / "comanip" / inside).read_text() + "\n# an edit\n")
        assert compiled_module._source_fingerprint.__wrapped__(edited / "comanip") != before, inside


def test_the_fingerprint_starts_from_the_modules_that_compile():
    """The planner's curvature modules hand functions to the compiler; the module that only reads the cache folder
    (the validation's arm section) and the module defining the builders are not among them."""
    modules = compiled_module.compiling_modules()
    assert {"comanip.planning.curvature", "comanip.planning.linearised_curvature"} <= modules
    assert not modules & {"comanip.caching.compiled", "comanip.validation.arm_section"}


def test_a_python_that_exits_with_a_compiler_running_stops_it(tmp_path):
    """A process's compilers are stopped when Python exits (a background build's daemon thread dies with Python and
    would leave its compiler running): a Python that exits with one running leaves no such process behind."""
    import os
    import sys

    scratch = tmp_path / "scratch"
    scratch.mkdir()
    script = (f"import subprocess; from comanip.caching import compiled\n"
              f"process = subprocess.Popen(['sleep', '60'], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)\n"
              f"compiled.compilers().running[process] = {str(scratch)!r}\n"
              f"print(process.pid, flush=True)\n")
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    pid = int(run.stdout.split()[0])
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        pass  # stopped and reaped
    else:
        os.kill(pid, 9)
        raise AssertionError(f"the compiler process {pid} outlived the Python that started it")
    assert not scratch.exists()
