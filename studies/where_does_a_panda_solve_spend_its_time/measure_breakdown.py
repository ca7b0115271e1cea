"""Where does a Panda solve spend its time? Per Newton iteration and per solve, piece by piece, on the workspace sets.

    PYTHONPATH=src .venv/bin/python -m studies.where_does_a_panda_solve_spend_its_time.measure_breakdown [--problems 45] [--compare REF] [--markdown]

The sampled sets of ``benchmarks/workspace.py`` (starts at rest): ``franka_rest`` warm (the plan to the problem's
goal, untimed, then the solve to its warm goal from it) and cold, and the paper's ``franka`` cold with its starts
one after another (``threads=1``: the pieces of starts solved side by side on threads cannot be told apart). Every
piece is timed where it runs (wall clock, inclusive):

- in the Newton iterations: the gradient evaluations (f, ∇f and the belief rollout), value-only evaluations (line
  search trials), the Hessian (its per-step pieces, the sensitivities and the assembly), the Cholesky
  factorisations (attempts that find the shifted matrix indefinite counted apart), the secant updates, and the rest
  of the iteration (working set, Woodbury solves, the loop in Python);
- per solve: the starts (candidates built and ranked by their objectives), the reachability witness (inverse
  kinematics), and building the returned plan.

Prints, per case, the median solve time and iterations, then per piece its calls and milliseconds per iteration
and its share of all solve time. ``--compare REF``: the same in a process importing REF's ``src`` (another
checkout, or a git revision of this repository), printed after this checkout's. ``--markdown``: one table for the
speed page instead, a column per case, REF's milliseconds in brackets. Timings move with the machine's load; the
counts do not.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
CASES = (("franka_rest", "warm"), ("franka_rest", "cold"), ("franka", "cold"))
LOOP_PIECES = ("gradient evaluation", "value-only evaluation", "Hessian", "Cholesky (factored)",
               "Cholesky (indefinite attempt)", "secant update")
SOLVE_PIECES = ("starts", "reachability witness", "building the plan")


class Clock:
    """Seconds and calls per piece; a piece timed inside another (an evaluation inside the starts) counts for the
    outer one only."""

    def __init__(self):
        self.seconds, self.calls, self.depth = defaultdict(float), defaultdict(int), 0

    def wrap(self, owner, name: str, piece: str | None, classify=None):
        """Replace ``owner.name`` by a timed call; ``classify(result)`` may rename the piece per call."""
        original = getattr(owner, name)
        clock = self

        def timed(*args, **kwargs):
            if clock.depth:
                return original(*args, **kwargs)
            clock.depth += 1
            started = time.perf_counter()
            try:
                result = original(*args, **kwargs)
            finally:
                clock.depth -= 1
            label = classify(result) if classify else piece
            clock.seconds[label] += time.perf_counter() - started
            clock.calls[label] += 1
            return result

        setattr(owner, name, timed)


def instrument(clock: Clock) -> None:
    """Time the pieces of the module docstring where they are called."""
    from comanip.optim import active_set_newton, factorisation, hessian_models
    from comanip.planning import planner as planner_module
    from comanip.planning.linearised_curvature import LinearisedCurvature
    from comanip.planning.newton_reach_solver import NewtonReachSolver
    from comanip.planning.starts.start_policy import StartPolicy

    clock.wrap(LinearisedCurvature, "evaluate", "gradient evaluation")
    clock.wrap(LinearisedCurvature, "value_and_data", "value-only evaluation")
    clock.wrap(LinearisedCurvature, "hessian", "Hessian")
    clock.wrap(factorisation, "_potrf", None,
               lambda result: "Cholesky (factored)" if result[1] == 0 else "Cholesky (indefinite attempt)")
    clock.wrap(hessian_models, "symmetric_rank_one_update", "secant update")
    clock.wrap(StartPolicy, "guesses", "starts")
    clock.wrap(planner_module.Planner, "goal_joints", "reachability witness")
    clock.wrap(NewtonReachSolver, "make_plan", "building the plan")
    assert active_set_newton  # the loop's own time is the rest of the solve


def measure(preset: str, kind: str, count: int) -> dict:
    """The case's median solve time (ms), median iterations, total iterations and solve time (s), and per piece its
    calls and seconds."""
    from threadpoolctl import threadpool_limits

    import comanip
    from benchmarks import workspace
    from comanip.planning.planner import SolverOptions

    model = comanip.presets.load(preset)
    planner = comanip.Planner(model, SolverOptions(threads=1))
    problems = [p for p in workspace.load(preset) if not p.moving][:count]
    home = model.body.home_position
    origin = np.asarray(model.body.kinematics_function(home)[0]).ravel()
    with threadpool_limits(1, user_api="blas"):
        planner.solve(np.r_[home, np.zeros(model.n)], origin + 0.2 * np.eye(model.d)[0], model.width)  # one-off work
        firsts = [planner.solve(p.start, p.goal, p.width) for p in problems] if kind == "warm" else None
        clock = Clock()
        instrument(clock)
        plans = [planner.solve(p.start, p.warm_goal, p.width, warm_start=firsts[k]) if kind == "warm"
                 else planner.solve(p.start, p.goal, p.width) for k, p in enumerate(problems)]
    times, iterations = [p.solve_time for p in plans], [p.iterations for p in plans]
    return {"median_ms": 1e3 * float(np.median(times)), "median_iterations": float(np.median(iterations)),
            "iterations": int(np.sum(iterations)), "seconds": float(np.sum(times)),
            "pieces": {piece: [clock.calls[piece], clock.seconds[piece]] for piece in LOOP_PIECES + SOLVE_PIECES}}


def table(preset: str, kind: str, row: dict, label: str) -> str:
    """The case's lines: the summary, then one line per piece."""
    its, total = row["iterations"], row["seconds"]
    lines = [f"{preset} {kind}{label}: median {row['median_ms']:.1f} ms, {row['median_iterations']:.0f} iterations "
             f"(median); {its} iterations in {total:.2f} s, {1e3 * total / its:.2f} ms per iteration",
             "    piece                           calls/it   ms/it   share"]
    accounted = 0.0
    for piece in LOOP_PIECES:
        calls, seconds = row["pieces"][piece]
        accounted += seconds
        lines.append(f"    {piece:<32}{calls / its:7.2f}{1e3 * seconds / its:9.3f}{100 * seconds / total:7.1f} %")
    solve_pieces = sum(row["pieces"][piece][1] for piece in SOLVE_PIECES)
    rest = total - accounted - solve_pieces
    lines.append(f"    {'rest of the iteration':<32}{'':7}{1e3 * rest / its:9.3f}{100 * rest / total:7.1f} %")
    solves = max(row["pieces"]["building the plan"][0], 1)
    lines.append("    per solve                       ms/solve")
    for piece in SOLVE_PIECES:
        seconds = row["pieces"][piece][1]
        lines.append(f"    {piece:<32}{1e3 * seconds / solves:9.2f}{'':7}{100 * seconds / total:7.1f} %")
    return "\n".join(lines)


def markdown(rows: dict, references: dict, command: str) -> str:
    """The speed page's table: a row per piece, a column per case (``rows`` and ``references`` keyed by case)."""

    def cell(row: dict, reference: dict | None, piece: str) -> str:
        its, total = row["iterations"], row["seconds"]
        seconds = row["pieces"][piece][1]
        text = f"{1e3 * seconds / its:.2f} ms, {100 * seconds / total:.0f} %"
        if reference is not None:
            text += f" ({1e3 * reference['pieces'][piece][1] / reference['iterations']:.2f})"
        return text

    def rest(row: dict) -> float:
        return row["seconds"] - sum(seconds for _, seconds in row["pieces"].values())

    cases = list(rows)
    lines = [f"Measured by `{command}` (ms per Newton iteration and share of all solve time"
             + (", in brackets the reference's ms" if references else "") + "):", "",
             "| piece (calls per iteration) | " + " | ".join(f"`{preset}` {kind}" for preset, kind in cases) + " |",
             "|---" * (len(cases) + 1) + "|"]
    for piece in LOOP_PIECES:
        calls = " / ".join(f"{rows[case]['pieces'][piece][0] / rows[case]['iterations']:.2f}" for case in cases)
        lines.append(f"| {piece} ({calls}) | " + " | ".join(cell(rows[c], references.get(c), piece) for c in cases) + " |")
    lines.append("| rest of the iteration | " + " | ".join(
        f"{1e3 * rest(rows[c]) / rows[c]['iterations']:.2f} ms, {100 * rest(rows[c]) / rows[c]['seconds']:.0f} %"
        for c in cases) + " |")

    def per_iteration(row: dict) -> str:
        return f"{1e3 * (row['seconds'] - sum(row['pieces'][p][1] for p in SOLVE_PIECES)) / row['iterations']:.2f} ms"

    lines.append("| **per iteration** | " + " | ".join(
        f"**{per_iteration(rows[c])}**" + (f" ({per_iteration(references[c])})" if c in references else "")
        for c in cases) + " |")
    for piece in SOLVE_PIECES:
        lines.append(f"| per solve: {piece} | " + " | ".join(
            f"{1e3 * rows[c]['pieces'][piece][1] / max(rows[c]['pieces']['building the plan'][0], 1):.1f} ms, "
            f"{100 * rows[c]['pieces'][piece][1] / rows[c]['seconds']:.0f} %" for c in cases) + " |")
    lines.append("| median solve, median iterations | " + " | ".join(
        f"{rows[c]['median_ms']:.1f} ms, {rows[c]['median_iterations']:.0f}"
        + (f" ({references[c]['median_ms']:.1f} ms, {references[c]['median_iterations']:.0f})" if c in references else "")
        for c in cases) + " |")
    return "\n".join(lines)


def measured_elsewhere(src: Path, preset: str, kind: str, count: int) -> dict:
    """measure(...) in a fresh process importing comanip from ``src``."""
    done = subprocess.run([sys.executable, "-m", __spec__.name, "--row", preset, kind, "--problems", str(count)],
                          env={**os.environ, "PYTHONPATH": str(src)}, cwd=ROOT, check=True, capture_output=True, text=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--problems", type=int, default=45, help="problems per case (default: %(default)s)")
    parser.add_argument("--compare", default=None,
                        help="another checkout to measure after this one, or a git revision of this repository")
    parser.add_argument("--markdown", action="store_true", help="one table for the speed page")
    parser.add_argument("--row", nargs=2, default=None, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.row is not None:
        print(json.dumps(measure(*args.row, args.problems)))
        return
    from benchmarks.solve_times import reference_source

    reference, clean_up = reference_source(args.compare) if args.compare else (None, lambda: None)
    rows, references = {}, {}
    try:
        for case in CASES:
            rows[case] = measured_elsewhere(ROOT / "src", *case, args.problems)
            if not args.markdown:
                print(table(*case, rows[case], ""), flush=True)
            if reference is not None:
                references[case] = measured_elsewhere(reference, *case, args.problems)
                if not args.markdown:
                    print(table(*case, references[case], " (REF)"), flush=True)
    finally:
        clean_up()
    if args.markdown:
        command = "studies/where_does_a_panda_solve_spend_its_time/measure_breakdown.py --markdown" + (
            f" --compare {args.compare}" if args.compare else "")
        print(markdown(rows, references, command))


if __name__ == "__main__":
    main()
