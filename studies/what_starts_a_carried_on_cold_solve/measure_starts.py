"""What starts a point mass's cold solve from a start whose motion carries the hand on, as well as the full search
and in about as few Newton iterations as a warm solve?

    PYTHONPATH=src python -m studies.what_starts_a_carried_on_cold_solve.measure_starts \
        [--presets planar,cartesian] [--sets workspace,random] [--seed 0] [--problems 200] [--markdown]

A 'ranked' cold solve from a moving start whose stop ends away from the start, to a goal beyond ``narrow_ratio``
widths (:meth:`StartPolicy.carried_on <comanip.planning.starts.StartPolicy.carried_on>`), solves every minimum-jerk
guess to convergence and keeps the best (``cold_search="all"`` does so for every cold solve). On those problems of
each set (``workspace``: the preset's sampled workspace set, benchmarks/workspace.py; ``random``: cold_quality.py's
random problems of ``--seed``), this measures cheaper choices of starts against that full search (:data:`STRATEGIES`
describes each):

- the lowest-objective minimum-jerk guess alone (the baseline of benchmarks/drifting_starts.py);
- partial solves: ``k`` Newton iterations from every guess, then only the best continued;
- a scan of minimum-jerk guesses over many durations, ranked by objective, the best one or two solved;
- the tangential predictor in the start's velocity from the reach library's at-rest plans: d tau*/d s0 =
  -(∇²_ττ f)⁻¹ ∂²f/∂τ∂s0 at each plan near a local optimum for the same start position, goal and width, the
  predicted starts ranked by objective (alone, and beside the minimum-jerk guesses);
- the same from each rest optimum run at paces 0.6–1.4 (one Hessian per optimum), the lowest solved, or the 3–4
  lowest raced for k Newton iterations and the best continued, or the lowest solved beside the one or two
  lowest-objective guesses.

The findings are in README.md beside this script.

Each start is solved as the planner solves it (the planner's solver, one BLAS thread). Printed per preset and set:
the carried-on problems; per strategy the Newton iterations of the solves it runs (median / p90 / largest, summed
over its starts, partial iterations included), what it spends building its starts (objective evaluations, Hessians
and factorisations, counted per problem, median), the share of problems within 1e-4 relative of the full search's
objective, the largest relative excess, successes against the full search's, and whether the cold-search rule of
benchmarks/cold_quality.py holds (≥ 98 % within 1e-4, never more than 1e-3 worse, successes not fewer). The last
line of each set gives the median and p90 Newton iterations of the planner's own cold solves of the whole set (rest
and moving), the yardstick of the target. Progress goes to stderr.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass
from typing import Callable

import casadi as ca
import numpy as np

import comanip
from comanip.optim import SolverResult
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.starts.initial_guess import minimum_jerk_torques
from comanip.planning.starts.reach_library import PACES, at_pace

from benchmarks.cold_quality import RULE_CLOSE, RULE_SHARE, RULE_WORST, problems, workspace_problems  # noqa: E402

SCAN_FRACTIONS = np.linspace(0.15, 0.95, 17)
"""Durations of the scanned minimum-jerk guesses, as fractions of the horizon (the planner's three: 0.25, 0.5,
0.75)."""


@dataclass
class Outcome:
    """What one strategy ended with on one problem."""

    fun: float
    """The best normalised objective of the starts it solved."""
    success: bool
    iterations: int
    """Newton iterations of its solves, partial ones included."""
    evaluations: int = 0
    """Objective evaluations spent ranking starts."""
    hessians: int = 0
    """Hessians assembled and factorised to build starts."""


class Problem:
    """One carried-on problem and the pieces its strategies share (the guesses, their solves)."""

    def __init__(self, planner, params: ReachParameters):
        self.planner, self.params = planner, params
        self.starts, self.solver = planner.starts, planner.solver
        self.guesses = self.starts.cold_guesses(params, planner.options.n_starts)
        self.guess_objectives = [self.starts.objective(guess, params) for guess in self.guesses]
        self._solved: dict[int, SolverResult] = {}

    def solved_guess(self, k: int) -> SolverResult:
        if k not in self._solved:
            self._solved[k] = self.solve(self.guesses[k])
        return self._solved[k]

    def solve(self, torque: np.ndarray) -> SolverResult:
        """One start solved to the end, as the planner solves it alone."""
        return self.solver.results([torque], self.params)[0]

    def full_search(self) -> Outcome:
        results = [self.solved_guess(k) for k in range(len(self.guesses))]
        return best_of(results)

    def rest_params(self) -> ReachParameters:
        """The same problem from the start position at rest."""
        model = self.planner.model
        start = np.zeros(model.state_size)
        start[: model.n] = self.params.start[: model.n]
        return ReachParameters(start, self.params.goal, self.params.width)


def best_of(results: list[SolverResult], evaluations: int = 0, hessians: int = 0, extra_iterations: int = 0) -> Outcome:
    best = min(results, key=lambda r: r.fun)
    return Outcome(best.fun, best.success, sum(r.nit for r in results) + extra_iterations, evaluations, hessians)


# -- strategies ------------------------------------------------------------------------------------------------------
def lowest_guess(problem: Problem) -> Outcome:
    k = int(np.argmin(problem.guess_objectives))
    return best_of([problem.solved_guess(k)], evaluations=len(problem.guesses))


def two_lowest_guesses(problem: Problem) -> Outcome:
    order = np.argsort(problem.guess_objectives)[:2]
    return best_of([problem.solved_guess(int(k)) for k in order], evaluations=len(problem.guesses))


def partial(k: int) -> Callable[[Problem], Outcome]:
    """``k`` Newton iterations from every guess, the lowest objective there solved on."""

    def strategy(problem: Problem) -> Outcome:
        solver, params = problem.solver, problem.params
        with solver.blas:
            solves = [solver.newton_solve(guess, params, np.inf, solver.curvature) for guess in problem.guesses]
            firsts = [solve.advance(k) for solve in solves]
            best = min(range(len(solves)), key=lambda j: firsts[j].fun)
            final = solves[best].advance(solver.max_iterations)
        spent = sum(r.nit for j, r in enumerate(firsts) if j != best)
        return Outcome(final.fun, final.success, spent + final.nit)

    return strategy


def scan_guesses(problem: Problem) -> list[np.ndarray]:
    model = problem.planner.model
    starts = problem.starts
    goal_q = model.body.inverse_kinematics(problem.params.goal, problem.params.start[: model.n])
    return list(minimum_jerk_torques(model.body, model.h, model.H, problem.params.start, goal_q,
                                     SCAN_FRACTIONS * model.duration, starts.linear_dynamics))


def scan(count: int) -> Callable[[Problem], Outcome]:
    """Minimum-jerk guesses of :data:`SCAN_FRACTIONS` durations, the ``count`` of lowest objective solved."""

    def strategy(problem: Problem) -> Outcome:
        guesses = scan_guesses(problem)
        objectives = [problem.starts.objective(g, problem.params) for g in guesses]
        chosen = np.argsort(objectives)[:count]
        return best_of([problem.solve(guesses[k]) for k in chosen], evaluations=len(guesses))

    return strategy


class VelocityPredictor:
    """The tangential predictor of a plan's optimal torques in the start state s0, for one point-mass planner.

    The mean is affine in the torques and the start, mu_x,i = C_i s0 + Σ_k G_ik tau_k with C_i = J [A^i]_q (d, nx),
    and the covariance does not depend on s0; the reward of step i depends on mu_x,i - g. So ∂²f/∂τ∂s0 =
    Σ_i Z_iᵀ ∂²phi_i/∂z_i∂mu_x,i C_i, the goal's cross derivative (:meth:`ReachCurvature.goal_cross_derivative`) with
    each step's columns mapped by C_i instead of -I.
    """

    def __init__(self, planner):
        model = planner.model
        self.curvature, self.model = planner.solver.curvature, model
        n, nx = model.n, model.state_size
        s, tau = ca.SX.sym("s", nx), ca.SX.sym("tau", n)
        A = np.asarray(ca.evalf(ca.jacobian(model.body.discrete_step(s, tau, model.h), s)))
        J = np.asarray(model.body.kinematics_function(np.zeros(n))[1])
        powers = [np.eye(nx)]
        for _ in range(model.H):
            powers.append(A @ powers[-1])
        self.free_response = np.array([J @ P[:n] for P in powers])  # (H+1, d, nx)

    def cross_derivative(self, data) -> np.ndarray:
        """∂²f/∂τ∂s0 (H·n, nx) at the evaluation's data."""
        d = self.model.d
        Z = self.curvature._reduced_rows(data)  # (H+1, d + r, H·n)
        mapped = np.einsum("irm,imj->irj", data.phi_hess[:, :, :d], self.free_response)  # (H+1, d + r, nx)
        return Z.reshape(-1, Z.shape[2]).T @ mapped.reshape(-1, mapped.shape[2])

    def predict(self, torque: np.ndarray, base: ReachParameters, params: ReachParameters) -> np.ndarray:
        """Torques (H, n) for ``params`` predicted from torques (H, n) near an optimum for ``base`` (same goal and
        width, another start): one Newton step of ``base`` together with the first-order move of the optimum,
        tau - (∇²f)⁻¹ (∇f + ∂²f/∂τ∂s0 (s0 - s0_base))."""
        evaluation = self.curvature.evaluate(np.ravel(torque), base)
        hessian = self.curvature.hessian(evaluation.data)
        rhs = evaluation.gradient + self.cross_derivative(evaluation.data) @ (params.start - base.start)
        step = _positive_definite_solve(hessian, rhs)
        return (np.ravel(torque) - step).reshape(torque.shape)


def _positive_definite_solve(matrix: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """matrix⁻¹ rhs, the matrix shifted by a multiple of I until its Cholesky factorisation succeeds."""
    shift = 0.0
    scale = float(np.max(np.abs(np.diag(matrix))))
    while True:
        try:
            factor = np.linalg.cholesky(matrix + shift * np.eye(len(matrix)))
            return np.linalg.solve(factor.T, np.linalg.solve(factor, rhs))
        except np.linalg.LinAlgError:
            shift = max(2 * shift, 1e-6 * scale)


def library_plans(problem: Problem, every: bool) -> list[np.ndarray]:
    """The reach library's plans for the start position at rest: near each local optimum (at their own pace) or the
    nearest entry's best."""
    rest = problem.rest_params()
    library = problem.starts.library
    library.fill(rest, bracket=every)
    if not every:
        found = library.guess(rest)
        return [] if found is None else [found]
    plans = library.local_optima(rest)
    return plans[PACES.index(1.0)::len(PACES)]


def predicted(every: bool, with_guesses: bool) -> Callable[[Problem], Outcome]:
    """The library's at-rest plans moved to the start's velocity by the tangential predictor, ranked by objective
    (``with_guesses``: beside the minimum-jerk guesses), the lowest solved."""

    def strategy(problem: Problem) -> Outcome:
        predictor = PREDICTORS[id(problem.planner)]
        rest = problem.rest_params()
        plans = library_plans(problem, every)
        candidates = [predictor.predict(plan, rest, problem.params) for plan in plans]
        if with_guesses:
            candidates += problem.guesses
        objectives = [problem.starts.objective(c, problem.params) for c in candidates]
        chosen = candidates[int(np.argmin(objectives))]
        return best_of([problem.solve(chosen)], evaluations=len(candidates), hessians=len(plans))

    return strategy


WIDE_PACES = (0.6, 0.7, 0.8, 0.9, 1.0, 1.1, 1.2, 1.3, 1.4)
"""Paces (:func:`at_pace`) at which :func:`paced_predictions` runs each rest plan: the moving-start optima of the
Cartesian preset arrive up to half again as late as the rest plans, or earlier."""


def paced_predictions(problem: Problem, paces=WIDE_PACES) -> tuple[list[np.ndarray], int]:
    """Each rest optimum of the library (:func:`library_plans`) at each pace, plus the velocity correction of the
    tangential predictor at its own pace: -(∇²f)⁻¹ ∂²f/∂τ∂s0 (s0 - s0_rest), one Hessian per plan; and the
    Hessians spent."""
    predictor = PREDICTORS[id(problem.planner)]
    curvature, rest = predictor.curvature, problem.rest_params()
    plans = library_plans(problem, every=True)
    candidates = []
    for plan in plans:
        evaluation = curvature.evaluate(np.ravel(plan), rest)
        hessian = curvature.hessian(evaluation.data)
        move = predictor.cross_derivative(evaluation.data) @ (problem.params.start - rest.start)
        correction = -_positive_definite_solve(hessian, move).reshape(plan.shape)
        candidates += [at_pace(plan, pace) + correction for pace in paces]
    return candidates, len(plans)


def raced(count: int, k: int, paces=WIDE_PACES, with_guesses: bool = True) -> Callable[[Problem], Outcome]:
    """The paced predictions (and the minimum-jerk guesses), the ``count`` of lowest objective each given ``k``
    Newton iterations, the best of them then solved on."""

    def strategy(problem: Problem) -> Outcome:
        candidates, hessians = paced_predictions(problem, paces)
        if with_guesses:
            candidates += problem.guesses
        objectives = [problem.starts.objective(c, problem.params) for c in candidates]
        chosen = [candidates[j] for j in np.argsort(objectives)[:count]]
        solver, params = problem.solver, problem.params
        with solver.blas:
            solves = [solver.newton_solve(c, params, np.inf, solver.curvature) for c in chosen]
            firsts = [solve.advance(k) for solve in solves]
            best = min(range(len(solves)), key=lambda j: firsts[j].fun)
            final = solves[best].advance(solver.max_iterations)
        spent = sum(r.nit for j, r in enumerate(firsts) if j != best)
        return Outcome(final.fun, final.success, spent + final.nit, len(candidates), hessians)

    return strategy


def prediction_and_guesses(guesses: int) -> Callable[[Problem], Outcome]:
    """The lowest-objective paced prediction and the ``guesses`` lowest-objective minimum-jerk guesses, each solved
    (the two families end on different local optima)."""

    def strategy(problem: Problem) -> Outcome:
        candidates, hessians = paced_predictions(problem)
        objectives = [problem.starts.objective(c, problem.params) for c in candidates]
        predicted_start = candidates[int(np.argmin(objectives))]
        order = np.argsort(problem.guess_objectives)[:guesses]
        results = [problem.solve(predicted_start)] + [problem.solved_guess(int(k)) for k in order]
        return best_of(results, evaluations=len(candidates) + len(problem.guesses), hessians=hessians)

    return strategy


PREDICTORS: dict[int, VelocityPredictor] = {}

STRATEGIES: dict[str, Callable[[Problem], Outcome]] = {
    "all guesses (full search)": Problem.full_search,
    "lowest-objective guess": lowest_guess,
    "two lowest-objective guesses": two_lowest_guesses,
    "partial k=2, best continued": partial(2),
    "partial k=3, best continued": partial(3),
    "partial k=5, best continued": partial(5),
    "scan of 17 durations, best solved": scan(1),
    "scan of 17 durations, best two solved": scan(2),
    "predictor from nearest rest plan": predicted(every=False, with_guesses=False),
    "predictor from each rest optimum": predicted(every=True, with_guesses=False),
    "predictor from each rest optimum + guesses": predicted(every=True, with_guesses=True),
    "paced predictions + guesses, lowest solved": raced(1, 0),
    "paced predictions + guesses, 3 lowest raced k=1": raced(3, 1),
    "paced predictions + guesses, 3 lowest raced k=2": raced(3, 2),
    "paced predictions + guesses, 4 lowest raced k=2": raced(4, 2),
    "paced predictions + guesses, 4 lowest raced k=3": raced(4, 3),
    "lowest paced prediction + lowest guess": prediction_and_guesses(1),
    "lowest paced prediction + two lowest guesses": prediction_and_guesses(2),
}


# -- the tables ------------------------------------------------------------------------------------------------------
def spread(values) -> str:
    values = np.asarray(values)
    return f"{np.median(values):.0f} / {np.percentile(values, 90):.0f} / {values.max()}" if values.size else "–"


def measure(preset: str, problem_set: str, count: int, seed: int, names: list[str]) -> tuple[list[list[str]], str]:
    """Rows (one per strategy) for one preset and set, and the yardstick line."""
    model = comanip.presets.load(preset)
    planner = comanip.Planner(model)
    PREDICTORS[id(planner)] = VelocityPredictor(planner)
    cases = workspace_problems(preset, count) if problem_set == "workspace" else problems(model, count, seed)
    outcomes: dict[str, list[tuple[float, Outcome, Outcome]]] = {name: [] for name in names}
    every_cold = []
    for index, (start, goal, width) in enumerate(cases):
        every_cold.append(planner.solve(start, goal, width).iterations)
        params = ReachParameters(model.full_state(start), goal, width)
        if not planner.starts.carried_on(params):
            continue
        problem = Problem(planner, params)
        full = problem.full_search()
        for name in names:
            outcome = STRATEGIES[name](problem)
            outcomes[name].append(((outcome.fun - full.fun) / abs(full.fun), outcome, full))
        print(f"  {preset} {problem_set} problem {index}", file=sys.stderr, flush=True)
    rows = []
    for name in names:
        part = outcomes[name]
        if not part:
            rows.append([preset, problem_set, "0", name] + ["–"] * 7)
            continue
        excess = np.array([p[0] for p in part])
        close, worst = float(np.mean(excess <= RULE_CLOSE)), float(max(excess.max(), 0.0))
        ok, ok_full = sum(p[1].success for p in part), sum(p[2].success for p in part)
        met = close >= RULE_SHARE and worst <= RULE_WORST and ok >= ok_full
        cost = f"{np.median([p[1].evaluations for p in part]):.0f} / {np.median([p[1].hessians for p in part]):.0f}"
        rows.append([preset, problem_set, str(len(part)), name, spread([p[1].iterations for p in part]), cost,
                     f"{close:.1%}", f"{worst:.1e}", f"{ok}/{ok_full}", "met" if met else "NOT met"])
    yardstick = (f"{preset} {problem_set}: the planner's cold solves of all {len(every_cold)} problems, Newton iterations "
                 f"median {np.median(every_cold):.0f}, p90 {np.percentile(every_cold, 90):.0f}")
    return rows, yardstick


HEADER = ["preset", "set", "carried on", "strategy", "iterations (median / p90 / max)", "evaluations / Hessians",
          "within 1e-4", "largest excess", "successes", "rule"]


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--presets", default="planar,cartesian")
    parser.add_argument("--sets", default="workspace,random", help="workspace (sampled sets), random (cold_quality.py's)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the random problems (default: %(default)s)")
    parser.add_argument("--problems", type=int, default=200, help="problems per set, carried on or not")
    parser.add_argument("--strategies", default=None, help="names separated by semicolons (default: all)")
    parser.add_argument("--markdown", action="store_true", help="print a Markdown table")
    args = parser.parse_args(argv)
    names = list(STRATEGIES) if args.strategies is None else [s.strip() for s in args.strategies.split(";")]
    rows, yardsticks = [], []
    for preset in args.presets.split(","):
        for problem_set in args.sets.split(","):
            found, yardstick = measure(preset, problem_set, args.problems, args.seed, names)
            rows += found
            yardsticks.append(yardstick)
            print(yardstick, file=sys.stderr, flush=True)
    print(f"random problems: seed {args.seed}; rule: within {RULE_CLOSE:g} relative in ≥ {RULE_SHARE:.0%}, "
          f"never more than {RULE_WORST:g} worse, successes not fewer")
    if args.markdown:
        print("| " + " | ".join(HEADER) + " |")
        print("|" + "---|" * len(HEADER))
        for row in rows:
            print("| " + " | ".join(row) + " |")
    else:
        widths = [max(len(h), *(len(r[k]) for r in rows)) for k, h in enumerate(HEADER)]
        print("  ".join(h.ljust(w) for h, w in zip(HEADER, widths)))
        for row in rows:
            print("  ".join(c.ljust(w) for c, w in zip(row, widths)))
    for line in yardsticks:
        print(line)


if __name__ == "__main__":
    main()
