"""benchmarks/real_people.py's leave-one-person-out: a person's reaches never reach the people model or the
templates that score them, and the person-by-person table says which targets the rows meet."""

import sys

import pytest

from comanip.estimation.people import people_model, template_matching
from tests.project.benchmark_scripts import load_benchmark
from tests.project.test_forecast_peers import people_of_reaches


@pytest.fixture(scope="module")
def real_people():
    """benchmarks/real_people.py as a module."""
    return load_benchmark("real_people")


def test_a_person_left_out_is_never_seen_by_what_scores_them(real_people, monkeypatch):
    people = people_of_reaches()
    monkeypatch.setattr(real_people, "people_reaches", lambda *args: people)
    fitted = []
    monkeypatch.setattr(people_model.PeopleModel, "fit",
                        lambda recordings, kind: fitted.append(("people", {r.name for r in recordings})) or fitted[-1][1])
    monkeypatch.setattr(template_matching, "TemplateLibrary",
                        lambda recordings, step: fitted.append(("templates", {r.name for r in recordings})) or fitted[-1][1])
    movements, person_of, people_for, library_for = real_people.leave_one_person_out(None, None, None, sys.stderr)
    assert [r.name for r in movements] == [r.name for rs in people.values() for r in rs]
    for recording in movements:
        others = {r.name for person, rs in people.items() if person != person_of[recording.name] for r in rs}
        assert people_for(recording) == others and library_for(recording) == others
    assert len(fitted) == 2 * len(people)                              # once per person, when first asked


def rows_of(errors: dict, fractions) -> list[dict]:
    """Result rows of {(person, predictor): error / D} at every fraction, the estimator's region holding the endpoint."""
    return [{"person": person, "predictor": predictor, "fraction": f, "error": error,
             "covered": True if predictor.startswith("Online") else None}
            for (person, predictor), error in errors.items() for f in fractions]


def test_the_person_table_says_who_the_estimator_beats(real_people):
    name = "OnlineGoalEstimator (arm)"
    errors = {("P", name): 0.1, ("P", "constant velocity"): 0.2, ("P", "current position"): 0.3,
              ("Q", name): 0.3, ("Q", "constant velocity"): 0.2, ("Q", "current position"): 0.4}
    diagnosed = [{"person": "P", "jumps": 0.0}, {"person": "Q", "jumps": 0.05}]
    text = real_people.people_markdown(name, rows_of(errors, real_people.FRACTIONS), diagnosed)
    lines = {line.split(" | ")[0]: line for line in text.splitlines()}
    assert "| yes |" in lines["| P"] and "| no |" in lines["| Q"]
    assert "| 1 of 2 | no |" in text                                    # 50 % of the people, not 80 %
    assert "at most 5.0 % (Q) | no |" in text
    assert "100–100 % | no |" in text                                  # every region holds: too wide, not 80–98 %
    # one reach a person, each held: consistent with a region that holds 95 % of the time; 100 reaches all held are not
    assert f"| {2 * len(real_people.PEOPLE_FRACTIONS)} of {2 * len(real_people.PEOPLE_FRACTIONS)} | yes |" in text
    many = real_people.people_markdown(name, 100 * rows_of(errors, real_people.FRACTIONS), diagnosed)
    assert f"| 0 of {2 * len(real_people.PEOPLE_FRACTIONS)} | no |" in many
