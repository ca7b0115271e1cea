"""Check the times the README states against the times a CI run measured, so that no time in the README drifts:

    python -m tools.readme_times TIMES.jsonl      # exit 1 when a stated time is more than 50 % off its measurement

TIMES.jsonl holds one JSON object a line, ``{"NAME": seconds}``, as ``.ci/run`` writes them for each step it times.
Each entry of :data:`CLAIMS` finds one stated time in the README and names the measurement it states.
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"

CLAIMS = {
    "tests_cpu": re.compile(r"set up and run the tests \(about (?P<value>\d+(?:\.\d+)?) (?P<unit>min|s) on 2 cores"),
}
"""measurement name: the README's statement of it (a number and its unit, min or s). The README states the time
of its test command on two cores; ``tests_cpu``, the CPU time of that command, is its wall time on an idle two-core
machine (the suite runs mostly on one core) and, unlike the wall time, does not grow when the machine is shared."""

TOLERANCE = 0.5
"""The largest relative difference between a stated time and its measurement."""


def measured_times(lines: list[str]) -> dict[str, float]:
    """{name: seconds} of JSON lines ``{"NAME": seconds}`` (a later line for the same name wins)."""
    times = {}
    for line in lines:
        if line.strip():
            times.update({name: float(seconds) for name, seconds in json.loads(line).items()})
    return times


def stated_seconds(readme: str, claim: re.Pattern) -> float | None:
    """The time (s) the README states for ``claim``, or None where it states none."""
    match = claim.search(readme)
    if match is None:
        return None
    return float(match["value"]) * (60.0 if match["unit"] == "min" else 1.0)


def disagreements(readme: str, times: dict[str, float]) -> list[str]:
    """What in ``readme`` disagrees with ``times``: a claim the README no longer makes, a claim with no measurement,
    or a stated time more than :data:`TOLERANCE` off its measurement."""
    found = []
    for name, claim in CLAIMS.items():
        stated = stated_seconds(readme, claim)
        if stated is None:
            found.append(f"{name}: the README no longer states it (pattern {claim.pattern!r})")
        elif name not in times:
            found.append(f"{name}: no measurement of it in this run")
        elif abs(stated - times[name]) > TOLERANCE * times[name]:
            found.append(f"{name}: the README says {stated / 60:.1f} min, this run measured {times[name] / 60:.1f} min "
                         f"(more than {TOLERANCE:.0%} off)")
    return found


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 1:
        print(__doc__.strip().splitlines()[2].strip(), file=sys.stderr)
        return 2
    times = measured_times(Path(argv[0]).read_text(encoding="utf-8").splitlines())
    problems = disagreements(README.read_text(encoding="utf-8"), times)
    for name, seconds in sorted(times.items()):
        print(f"measured {name}: {seconds / 60:.1f} min")
    for problem in problems:
        print(f"README time: {problem}", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
