"""Progress lines suit a log: one line per shown update, no carriage-return redraws; compiles say so."""

import time

import casadi as ca

from comanip.caching.compiled import compiled
from comanip.progress import LOG_INTERVAL, elapsed, progress_bar


def test_a_bar_in_a_log_writes_few_whole_lines(capsys):
    with progress_bar("reaches", 1000, "reach") as bar:
        for _ in range(1000):
            bar.update()
    err = capsys.readouterr().err
    assert "\r" not in err
    lines = err.splitlines()
    assert 1 <= len(lines) <= 3 and lines[-1].startswith("reaches: 100%"), lines


def test_a_long_call_gets_a_start_and_a_done_line(capsys):
    with elapsed("building"):
        time.sleep(0.05)
    lines = capsys.readouterr().err.splitlines()
    assert lines == ["building: 00:00", "building: done in 00:00"] and LOG_INTERVAL >= 5


def test_the_first_compile_of_a_function_is_announced(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("COMANIP_CACHE_DIR", str(tmp_path))
    x = ca.SX.sym("x")
    square = ca.Function("progress_square", [x], [x * x])
    assert float(compiled(square)(3.0)) == 9.0
    err = capsys.readouterr().err
    assert "compiling progress_square to C" in err and "done in" in err
    compiled(square)                                   # cached: silent
    assert capsys.readouterr().err == ""


def test_every_bar_of_the_package_goes_through_comanip_progress():
    """A bar made with tqdm directly redraws with carriage returns in a log file; comanip.progress gives one line
    per update there. Only comanip/progress.py may call tqdm itself."""
    import re
    from pathlib import Path

    import comanip

    root = Path(comanip.__file__).parent
    direct = [str(path.relative_to(root)) for path in root.rglob("*.py")
              if path.name != "progress.py" and re.search(r"\btqdm\s*\(", path.read_text(encoding="utf-8"))]
    assert direct == [], f"these modules make tqdm bars themselves: {direct}"


def test_nested_bars_in_a_log_have_no_cursor_movements(capsys):
    """Two bars at once (a model build around a compile) make tqdm move the cursor up to redraw; a log gets none."""
    with progress_bar("outer", 2, "step") as outer:
        with progress_bar("inner", 3, "step") as inner:
            inner.update(3)
        outer.update(2)
    err = capsys.readouterr().err
    assert "\x1b" not in err and "\r" not in err
    assert any(line.startswith("inner: 100%") for line in err.splitlines())
