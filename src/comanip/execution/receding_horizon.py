"""Closed-loop reaching: replan from the noisy state at every step, as a person with visual feedback does.

At step k the planner solves the full H-step problem from the state s_k (warm-started with the previous
plan shifted by one step); the first torque tau_0 is executed with signal-dependent noise,
s_{k+1} = f(s_k, (I + E_k) tau_0), E_k drawn as the model's noise form says. The receding window keeps its
length H, so the person always looks H·h seconds ahead. By default the replan starts from the actual state;
with an :class:`~comanip.execution.delayed_observation.Observation` it starts from the person's estimate of it,
made from noisy, delayed measurements by :class:`~comanip.execution.kalman_filter.DelayedKalmanFilter`.
"""

from __future__ import annotations

from dataclasses import dataclass

import casadi as ca
import numpy as np

from comanip.belief.noise import sample_torque_error
from comanip.execution.kalman_filter import DelayedKalmanFilter
from comanip.execution.delayed_observation import Observation
from comanip.planning.planner import Planner


@dataclass
class Execution:
    """One executed reach. Shapes: K executed steps, n degrees of freedom, d task dimensions."""

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

    @property
    def ee_speed(self) -> np.ndarray:
        return np.linalg.norm(self.ee_velocity, axis=1)


def execute_receding_horizon(planner: Planner, start, goal, width: float | None = None, steps: int | None = None,
                             rng: np.random.Generator | None = None, noise: bool = True,
                             max_wall_time: float | None = None, observation: Observation | None = None) -> Execution:
    """Execute a reach in closed loop with replanning every step.

    Args:
        planner: a built :class:`Planner` (its model sets h, H, kappa and the noise form).
        start: start state [q; qdot] (2n,) or the full state (nx,); goal: (d,) m; width: m (model default when None).
        steps: steps to execute (default H).
        rng: random generator for the motor (and sensory) noise (default: a fresh unseeded one).
        noise: False executes the commands exactly (a deterministic closed loop).
        max_wall_time: budget per replan (s); a late replan still yields its best plan so far.
        observation: an Observation replans from the Kalman estimate made from measurements of [q; qdot] with
            its noise and delay (the start is known exactly); None uses the model's ``observation``, and replans
            from the actual state when the model has none. ``Observation(0, 0)`` forces the exact state.
    """
    model = planner.model
    observation = Observation.of(model) if observation is None else observation
    start, goal, width = planner.check_inputs(start, goal, width)
    steps = model.H if steps is None else int(steps)
    if steps < 1:
        raise ValueError(f"steps must be ≥ 1, got {steps}")
    if observation is not None and not isinstance(observation, Observation):
        raise ValueError(f"observation must be None or a comanip.execution.Observation, got {type(observation).__name__}")
    rng = rng if rng is not None else np.random.default_rng()
    body, n = model.body, model.n
    s_sym, tau_sym = ca.SX.sym("s", model.state_size), ca.SX.sym("tau", n)
    step = ca.Function("step", [s_sym, tau_sym], [body.discrete_step(s_sym, tau_sym, model.h)])
    velocity = ca.Function("ee_velocity", [s_sym], [ca.mtimes(body.jacobian(s_sym[:n]), s_sym[n:2 * n])])

    states = np.zeros((steps + 1, model.state_size))
    # the replans start from the person's estimate of the state: without an observation model, the state itself
    estimates = states if observation is None else np.zeros_like(states)
    states[0] = estimates[0] = start
    estimator = None if observation is None else DelayedKalmanFilter(model, observation, start)
    commanded = np.zeros((steps, n))
    executed = np.zeros((steps, n))
    failed = 0
    plan = None
    for k in range(steps):
        warm = None if plan is None else np.vstack([plan.torque[1:], plan.torque[-1:]])
        plan = planner.solve(estimates[k], goal, width, warm_start=warm, max_wall_time=max_wall_time)
        failed += not plan.converged
        commanded[k] = plan.torque[0]
        error = sample_torque_error(commanded[k], model.kappa, model.noise, rng) if noise else 0.0
        executed[k] = commanded[k] + error
        states[k + 1] = np.asarray(step(states[k], executed[k])).ravel()
        if estimator is not None:
            seen = observation.measure(states[max(0, k + 1 - estimator.delay)], n, rng)
            estimates[k + 1] = estimator.update(commanded[k], seen)
    ee = np.array([np.asarray(body.kinematics_function(s[:n])[0]).ravel() for s in states])
    ee_velocity = np.array([np.asarray(velocity(s)).ravel() for s in states])
    return Execution(t=model.h * np.arange(steps + 1), states=states, commanded=commanded, executed=executed,
                     ee=ee, ee_velocity=ee_velocity, failed_replans=failed,
                     estimates=None if observation is None else estimates)
