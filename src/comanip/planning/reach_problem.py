"""The reaching problem as CasADi expressions, shared by the planner and the goal estimator.

Symbols: tau (n, H) torques, s0 (nx,) start state (nx = 2n, plus n per activation stage), goal (d,) m,
width (scalar) m. From them, by single shooting through the belief dynamics: means[i] (nx,), covs[i] (nx, nx), ee_means[i] (d,),
ee_covs[i] (d, d) for i = 0..H, and the docs/formulation.md §4 objective J. Which symbols are decision variables and
which are parameters is the caller's choice (the estimator makes the goal a decision variable).
"""

from __future__ import annotations

from functools import cached_property

import casadi as ca
import numpy as np

from comanip.belief.propagation import belief_step_function, end_effector_belief_function
from comanip.model import ReachingModel
from comanip.objectives.discounting import discount_weights
from comanip.objectives.reach_objective import reach_objective, velocity_cost
from comanip.objectives.reward import GoalReward
from comanip.caching.buffered_function import BufferedFunction
from comanip.planning.plan import Plan
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.terms import StateBelief


class ReachProblem:
    """Single-shooting expressions of one model's reaching problem (built once, in SX)."""

    def __init__(self, model: ReachingModel):
        self.model = model
        body, n, d, H, nx = model.body, model.n, model.d, model.H, model.state_size
        self.tau = ca.SX.sym("tau", n, H)
        self.s0 = ca.SX.sym("s0", nx)
        self.goal = ca.SX.sym("goal", d)
        self.width = ca.SX.sym("width")

        step = belief_step_function(body, model.h, model.kappa, model.noise)
        ee = end_effector_belief_function(body)
        self.means, self.covs = [self.s0], [ca.SX.zeros(nx, nx)]
        for i in range(H):
            mu, Sigma = step(self.means[-1], self.covs[-1], self.tau[:, i])
            self.means.append(mu)
            self.covs.append(Sigma)
        ee_beliefs = [ee(m, S) for m, S in zip(self.means, self.covs)]
        self.ee_means = [x for x, _ in ee_beliefs]
        self.ee_covs = [S for _, S in ee_beliefs]
        self.weights = weights = discount_weights(model.gamma, H, model.discount)
        """Discount weights w_i (H+1,) of the reward terms."""
        self.reward = GoalReward.of(model)
        self.objective = reach_objective(self.ee_means, self.ee_covs, [self.tau[:, i] for i in range(H)],
                                         self.goal, self.width, weights, model.nu, self.reward)
        # The best objective attainable (hand on the goal with no noise at every step, no effort), used to
        # normalise J for the solver so its tolerances mean the same for every width; the minimiser is unchanged.
        self.best_objective = -float(np.sum(weights)) * self.reward.peak(self.width)
        self._weight_sum = float(np.sum(weights))
        self._normalised = (float("nan"), float("nan"))  # (width, |J_best|) of the last normaliser call
        self.normaliser_function = ca.Function("normaliser", [self.width], [-self.best_objective])
        """``width -> |J_best(w)|`` as a CasADi function (for building other functions of the width)."""
        if model.has_velocity_cost:  # relative to the best reward, so it means the same for every width
            self.objective += -self.best_objective * velocity_cost(
                [m[n:2 * n] for m in self.means[1:]], [S[n:2 * n, n:2 * n] for S in self.covs[1:]],
                model.stop_weight, model.joint_velocity_weight)

        self.trajectory = ca.Function(
            "trajectory", [ca.vec(self.tau), self.s0, self.goal, self.width],
            [ca.horzcat(*self.means), ca.horzcat(*self.covs), ca.horzcat(*self.ee_means),
             ca.horzcat(*self.ee_covs), self.objective],
            ["tau", "s0", "goal", "width"], ["mean", "cov", "ee_mean", "ee_cov", "J"])
        q, qdot = ca.SX.sym("q", n), ca.SX.sym("qdot", n)
        self._ee_velocity = BufferedFunction(ca.Function("ee_velocity", [q, qdot], [ca.mtimes(body.jacobian(q), qdot)]).map(H + 1))
        # NumPy in and out without CasADi's DM conversions (they cost more than a point mass's rollout itself)
        self._trajectory = BufferedFunction(self.trajectory)
        self._trajectory_outputs = self.trajectory.name_out()
        self._ee_belief = BufferedFunction(ee.map(H + 1))

    @cached_property
    def _plan_rollout(self) -> tuple[BufferedFunction, list[slice]]:
        """A plan in one call, built on first use (a plan without a belief computed by the solver: a point mass's,
        whose expanded rollout is cheap): the trajectory with the end effector's mean velocity J(mu_q) mu_qdot, every
        output column by column in one vector, and the slice of each output in it."""
        n, body = self.model.n, self.model.body
        rollout = self.trajectory.call([ca.vec(self.tau), self.s0, self.goal, self.width]) \
            + [ca.horzcat(*[ca.mtimes(body.jacobian(m[:n]), m[n:2 * n]) for m in self.means])]
        ends = np.cumsum([0] + [piece.numel() for piece in rollout])
        function = BufferedFunction(ca.Function("plan_rollout", [ca.vec(self.tau), self.s0, self.goal, self.width],
                                                [ca.densify(ca.vertcat(*[ca.vec(piece) for piece in rollout]))]))
        return function, [slice(a, b) for a, b in zip(ends[:-1], ends[1:])]

    def normaliser(self, width: float) -> float:
        """|J_best(w)| (> 0) for a goal width w (m): the solvers divide J by it, so their tolerances mean the same
        for every width. The last width's value is kept (a solve asks at every Hessian, always the same width)."""
        width = float(width)
        if width != self._normalised[0]:
            self._normalised = (width, self._weight_sum * self.reward.peak(width))
        return self._normalised[1]

    def objective_value(self, torque: np.ndarray, start, goal, width) -> float:
        """J (docs/formulation.md §4) of torques (H, n) from start (2n,) to goal (d,) of width w (m)."""
        return float(self._rollout(torque, start, goal, width)["J"].item())

    def _rollout(self, torque: np.ndarray, start, goal, width) -> dict[str, np.ndarray]:
        """:attr:`trajectory`'s outputs by name: mean (nx, H+1), cov (nx, nx·(H+1)), ee_mean (d, H+1),
        ee_cov (d, d·(H+1)), J."""
        return dict(zip(self._trajectory_outputs, self._trajectory(np.ravel(torque), start, goal, width)))

    def make_plan(self, torque, params: ReachParameters, *, status: str, success: bool, message: str,
                  solve_time: float, iterations: int, extras: dict | None = None, belief: StateBelief | None = None,
                  objective=None) -> Plan:
        """A :class:`Plan` for torques (H, n) of the reach ``params``: rolls the belief out and fills every field.

        ``belief`` and ``objective`` (J) already computed for these torques skip the rollout (for an arm the
        expanded rollout is costly).
        """
        model = self.model
        start, goal, width = params.start, params.goal, params.width  # the compiled rollouts take them apart
        n2, d, H = model.state_size, model.d, model.H
        torque = np.asarray(torque, dtype=float).reshape(H, model.n)
        if belief is None:
            rollout, pieces = self._plan_rollout
            out = rollout.vector(np.ravel(torque), start, goal, width)
            mean, cov, ee_mean, ee_cov, J, ee_velocity = (out[piece] for piece in pieces)
            # (rows, H+1) matrices column by column are their transposes row by row; the covariances' blocks alike
            mean, ee_mean, ee_velocity = mean.reshape(H + 1, n2), ee_mean.reshape(H + 1, d), ee_velocity.reshape(H + 1, d)
            cov, ee_cov = cov.reshape(H + 1, n2, n2).transpose(0, 2, 1), ee_cov.reshape(H + 1, d, d).transpose(0, 2, 1)
        else:
            mean, cov = belief.mean, belief.cov
            ee_mean, ee_cov = (np.asarray(v) for v in self._ee_belief(mean.T, cov.transpose(1, 0, 2).reshape(n2, -1)))
            J = np.asarray(objective, dtype=float)
            ee_mean, ee_cov = ee_mean.T, ee_cov.reshape(d, H + 1, d).transpose(1, 0, 2)
            ee_velocity = self._ee_velocity(mean[:, : model.n].T, mean[:, model.n:2 * model.n].T)[0].T
        return Plan(
            success=bool(success), status=status, message=message, objective=float(J.item()),
            solve_time=solve_time, iterations=iterations, t=model.h * np.arange(H + 1),
            mean=mean, cov=cov, torque=torque,
            ee_mean=ee_mean, ee_cov=ee_cov, ee_velocity=ee_velocity,
            start=start, goal=goal, width=width,
            model_name=model.name, extras=extras or {})
