"""Closed-loop reaching: replan from the noisy state at every control cycle, as a person with visual feedback does,
or as a robot's controller does at its own rate.

Every cycle of ``period`` seconds (the model's h by default) the loop replans the full H-step problem from the state
s_k, starting from the previous plan shifted to the cycle's time (:class:`~comanip.planning.replanner.Replanner`:
until it converges, or on a budget of Newton iterations or wall time per cycle); the plan's first torque tau_0 is
sent, the next cycle is prepared (:meth:`~comanip.planning.replanner.Replanner.prepare`), and tau_0 is
executed for the cycle with signal-dependent noise, s_{k+1} = f(s_k, (I + E_k) tau_0) with the forward-Euler step of
the cycle's length, E_k drawn as the model's noise form says. The receding window keeps its length H, so the person
always looks H·h seconds ahead. The first plan is a full solve from the start. By default the replan starts from the
actual state; with an :class:`~comanip.execution.delayed_observation.Observation` it starts from the person's
estimate of it, made from noisy, delayed measurements by :class:`~comanip.execution.kalman_filter.DelayedKalmanFilter`.
A goal may jump mid-reach (``goal_jumps``): from then on the replans aim at the new goal.
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from comanip.arguments import as_nonnegative, as_optional_positive, as_position
from comanip.belief.noise import sample_torque_error
from comanip.execution.kalman_filter import DelayedKalmanFilter
from comanip.execution.delayed_observation import Observation
from comanip.model import ReachingModel
from comanip.objectives.reach_objective import velocity_cost
from comanip.optim import Progress
from comanip.planning.planner import Planner
from comanip.planning.replanner import Replanner, Replanning


@dataclass
class Execution:
    """One executed reach. Shapes: K executed cycles, n degrees of freedom, d task dimensions."""

    t: np.ndarray
    """Times (K+1,), s."""
    states: np.ndarray
    """Actual states [q; qdot] (K+1, nx), nx = model.state_size (2n, plus n per activation stage)."""
    commanded: np.ndarray
    """Commanded torques (K, n)."""
    executed: np.ndarray
    """Executed torques (I + E) tau (K, n)."""
    ee: np.ndarray
    """End-effector positions (K+1, d), m."""
    ee_velocity: np.ndarray
    """End-effector velocities (K+1, d), m/s."""
    failed_replans: int
    """Replans that did not converge (their best plan so far was used)."""
    estimates: np.ndarray | None = None
    """The person's estimates of the states (K+1, nx), which the replans started from (the last one after
    the final step); None when the replans started from the actual states (no observation model)."""
    goals: np.ndarray | None = None
    """The goal each cycle's replan aimed at (K, d), m."""
    replan_times: np.ndarray | None = None
    """Wall time of each cycle's replan (K,), s, from the state to tau_0; the first is the loop's first plan, a full
    solve."""
    preparation_times: np.ndarray | None = None
    """Wall time of each cycle's preparation of the next (K,), s, after tau_0 is sent (the replanning's
    ``prepare``)."""
    replan_statuses: list[str] | None = None
    """Each cycle's :class:`~comanip.optim.Progress` ('converged', 'converging', 'not_contracting'), K of them."""
    replan_iterations: np.ndarray | None = None
    """Newton iterations of each cycle's replan (K,)."""

    @property
    def ee_speed(self) -> np.ndarray:
        return np.linalg.norm(self.ee_velocity, axis=1)


def execute_receding_horizon(planner: Planner | Replanning, start, goal, width: float | None = None,
                             steps: int | None = None, rng: np.random.Generator | None = None, noise: bool = True,
                             max_wall_time: float | None = None, observation: Observation | None = None, *,
                             iterations: int | None = None, period: float | None = None,
                             goal_jumps=()) -> Execution:
    """Execute a reach in closed loop, replanning every cycle.

    Args:
        planner: a built :class:`Planner` (its model sets h, H, kappa and the noise form), or a replanning of one
            (a :class:`~comanip.planning.replanner.Replanner`, which then sets the budget).
        start: start state [q; qdot] (2n,) or the full state (nx,); goal: (d,) m; width: m (model default when None).
        steps: cycles to execute (default: H·h / period, rounded; H for cycles of h).
        rng: random generator for the motor (and sensory) noise (default: a fresh unseeded one).
        noise: False executes the commands exactly (a deterministic closed loop).
        max_wall_time: wall budget per replan (s), every cost of the cycle included; the cycle returns its best plan
            so far, after one Newton iteration at least. None: no wall budget.
        observation: an Observation replans from the Kalman estimate made from measurements of [q; qdot] with
            its noise and delay (the start is known exactly; cycles of h only); None uses the model's ``observation``,
            and replans from the actual state when the model has none. ``Observation(0, 0)`` forces the exact state
            (at any period).
        iterations: Newton iterations per replan (the real-time iteration: 1 or a few); None, and no
            ``max_wall_time``: each replan runs until it converges.
        period: the control cycle (s), h when None; need not be a whole number of model steps (100 Hz on a model of
            h = 0.035 s is 0.29 of a step).
        goal_jumps: (time (s), goal (d,)) pairs, in any order: from each time on, the replans aim at that goal (a
            target that jumps mid-reach).
    """
    replanning = _replanning(planner, iterations, max_wall_time)
    planner = replanning.planner
    model = planner.model
    start, goal, width = planner.check_inputs(start, goal, width)
    observation, period, steps = _loop_timing(model, observation, period, steps)
    jumps = sorted((as_nonnegative("goal jump time", time, "s"), as_position("goal jump goal", to, model.d))
                   for time, to in goal_jumps)
    return _closed_loop(replanning, start, goal, width, jumps, steps, period, observation, noise,
                        rng if rng is not None else np.random.default_rng())


def _closed_loop(replanning: Replanning, start: np.ndarray, goal: np.ndarray, width: float, jumps: list, steps: int,
                 period: float, observation: Observation | None, noise: bool, rng: np.random.Generator) -> Execution:
    """:func:`execute_receding_horizon`'s loop on checked inputs: ``jumps`` sorted (time s, goal (d,) m) pairs."""
    model = replanning.planner.model
    n, step = model.n, model.body.step_function(period)
    states = np.zeros((steps + 1, model.state_size))
    # the replans start from the person's estimate of the state: without an observation model, the state itself
    estimates = states if observation is None else np.zeros_like(states)
    states[0] = estimates[0] = start
    estimator = None if observation is None else DelayedKalmanFilter(model, observation, start)
    commanded, executed, goals = np.zeros((steps, n)), np.zeros((steps, n)), np.zeros((steps, model.d))
    replan_times, preparation_times = np.zeros(steps), np.zeros(steps)
    iterations_done, statuses = np.zeros(steps, dtype=int), []
    replan = None
    for k in range(steps):
        goals[k] = next((to for time, to in reversed(jumps) if time <= k * period + 1e-12), goal)
        replan = replanning.first_plan(estimates[k], goals[k], width) if replan is None else \
            replanning.replan(replan, estimates[k], period, goals[k], width)
        replan_times[k], iterations_done[k] = replan.wall_time, replan.iterations
        commanded[k] = replan.torque[0]
        statuses.append(str(replan.status))  # after the command, as a robot's loop reads it
        if k + 1 < steps:  # the next cycle's preparation, while this one's command runs
            preparation_times[k] = replanning.prepare(replan, period)
        error = sample_torque_error(commanded[k], model.kappa, model.noise, rng) if noise else 0.0
        executed[k] = commanded[k] + error
        states[k + 1] = np.asarray(step(states[k], executed[k])).ravel()
        if estimator is not None:
            seen = observation.measure(states[max(0, k + 1 - estimator.delay)], n, rng)
            estimates[k + 1] = estimator.update(commanded[k], seen)
    ee, ee_velocity = _hand_path(model, states)
    return Execution(t=period * np.arange(steps + 1), states=states, commanded=commanded, executed=executed,
                     ee=ee, ee_velocity=ee_velocity, failed_replans=sum(status != Progress.CONVERGED for status in statuses),
                     estimates=None if observation is None else estimates, goals=goals, replan_times=replan_times,
                     preparation_times=preparation_times, replan_statuses=statuses, replan_iterations=iterations_done)


def _replanning(planner, iterations: int | None, max_wall_time: float | None) -> Replanning:
    """The replanning :func:`execute_receding_horizon` runs: a :class:`Replanner` of a Planner with that budget,
    or the given replanning (which has its own); a one-line ValueError otherwise."""
    if not isinstance(planner, Planner) and (iterations is not None or max_wall_time is not None):
        raise ValueError("iterations and max_wall_time go with a Planner; a Replanner has its own budget")
    replanning = planner if not isinstance(planner, Planner) else Replanner(planner, iterations, max_wall_time)
    missing = [name for name in ("planner", "first_plan", "replan", "prepare") if not hasattr(replanning, name)]
    if missing:
        raise ValueError(f"planner must be a comanip.Planner or a replanning of one (a Replanner: planner, first_plan, "
                         f"replan and prepare); {type(replanning).__name__} has no {', '.join(missing)}")
    return replanning


def _loop_timing(model: ReachingModel, observation, period, steps) -> tuple[Observation | None, float, int]:
    """The loop's observation (the model's when None; none at all when exact and the cycle is not h), its period
    (s, h when None) and its number of cycles (H·h / period when None), checked."""
    observation = Observation.of(model) if observation is None else observation
    period = model.h if period is None else as_optional_positive("period", period, "s")
    steps = round(model.H * model.h / period) if steps is None else int(steps)
    if steps < 1:
        raise ValueError(f"steps must be ≥ 1, got {steps}")
    if observation is not None and not isinstance(observation, Observation):
        raise ValueError(f"observation must be None or a comanip.execution.Observation, got {type(observation).__name__}")
    if observation is not None and not np.isclose(period, model.h):
        if observation.position_std or observation.velocity_std or observation.delay:
            raise ValueError(f"a noisy or delayed observation needs cycles of the model's step h = {model.h} s, got "
                             f"period {period} s (Observation(0, 0) replans from the exact state at any period)")
        observation = None
    return observation, period, steps


def _hand_path(model: ReachingModel, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The hand's positions (K, d) m and velocities J(q) qdot (K, d) m/s of states (K, nx)."""
    body, n = model.body, model.n
    s_sym = ca.SX.sym("s", model.state_size)
    velocity = ca.Function("ee_velocity", [s_sym], [ca.mtimes(body.jacobian(s_sym[:n]), s_sym[n:2 * n])])
    ee = np.array([np.asarray(body.kinematics_function(s[:n])[0]).ravel() for s in states])
    return ee, np.array([np.asarray(velocity(s)).ravel() for s in states])


def executed_cost(planner: Planner, run: Execution, width: float | None = None) -> float:
    """J (docs/formulation.md §4) of what a run executed, on the model's steps t_i = i·h, i = 0..H, within it: the
    discounted reward of the actual hand (no covariance: Sigma = 0) for the goal its replans aimed at then;
    the effort of the executed torques, nu Σ_k ||(I + E_k) tau_k||² · (cycle / h) (cycles of any length weigh as
    the model's steps do); and the model's speed cost, if it has one, on the actual velocities. Lower is better;
    two loops compare on the same run length and noise.

    Args:
        planner: the run's planner (its problem's reward, discount weights and |J_best|).
        run: an :class:`Execution` of :func:`execute_receding_horizon`; width: the goal width w (m), the model's
            when None.
    """
    problem, model = planner.problem, planner.model
    width = model.width if width is None else width
    period = float(run.t[1] - run.t[0])
    times = model.h * np.arange(model.H + 1)
    times = times[times <= run.t[-1] + 1e-9]
    hand = np.stack([np.interp(times, run.t, axis) for axis in run.ee.T], axis=1)
    cycles = np.minimum((times / period + 1e-9).astype(int), len(run.goals) - 1)
    at_rest = np.zeros((model.d, model.d))
    reward = sum(-w * problem.reward.expected(x, at_rest, g, width)
                 for w, x, g in zip(problem.weights, hand, run.goals[cycles]))
    within = run.t[:-1] < times[-1] - 1e-9
    effort = model.nu * float(np.sum(np.square(run.executed[within]))) * period / model.h
    if not model.has_velocity_cost:
        return float(reward + effort)
    n = model.n
    velocities = np.stack([np.interp(times[1:], run.t, column) for column in run.states[:, n:2 * n].T], axis=1)
    at_rest_velocity = np.zeros((len(velocities), n, n))
    speed = problem.normaliser(width) * velocity_cost(velocities, at_rest_velocity, model.stop_weight,
                                                      model.joint_velocity_weight)
    return float(reward + effort + speed)
