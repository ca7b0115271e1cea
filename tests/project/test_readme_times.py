"""tools/readme_times.py, which .ci/run calls with the times it measured: a README time more than 50 % off its
measurement, or no longer stated, fails the check; the README states every time the check knows."""

from tools.readme_times import CLAIMS, README, disagreements, measured_times, stated_seconds

STATED = "# 2. set up and run the tests (about 10 min on 2 cores, compiling included)"


def test_a_time_within_half_its_measurement_passes_and_one_beyond_fails():
    assert stated_seconds(STATED, CLAIMS["tests_cpu"]) == 600.0
    assert disagreements(STATED, {"tests_cpu": 700.0}) == []
    assert disagreements(STATED, {"tests_cpu": 401.0}) == []
    [too_slow] = disagreements(STATED, {"tests_cpu": 1300.0})
    [too_fast] = disagreements(STATED, {"tests_cpu": 300.0})
    assert "10.0 min" in too_slow and "21.7 min" in too_slow and "5.0 min" in too_fast


def test_a_missing_statement_or_measurement_fails():
    assert "no longer states" in disagreements("set up and run the tests (quickly)", {"tests_cpu": 600.0})[0]
    assert "no measurement" in disagreements(STATED, {})[0]


def test_the_measurements_read_as_ci_writes_them():
    assert measured_times(['{"tests": 610}', "", '{"fast_tests_3.12": 200}', '{"tests": 620}']) == \
        {"tests": 620.0, "fast_tests_3.12": 200.0}


def test_the_readme_states_every_time_the_check_knows():
    text = README.read_text(encoding="utf-8")
    assert all(stated_seconds(text, claim) is not None for claim in CLAIMS.values())
