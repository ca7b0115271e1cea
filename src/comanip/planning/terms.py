"""What a Newton-type solver of the reaching problem asks of the problem: the :class:`Curvature` protocol and
the typed data one evaluation hands from the objective to the Hessian, the limits and the goal derivatives.

Notation as in :mod:`comanip.planning.curvature` and ``docs/notation.md``: x = tau flattened step by step
(H·n,), parameters p = [s0 (nx,), goal (d,), width]; z_i = (mu_x,i (d,), vech Sigma_x,i (nv,)) with
nv = d(d+1)/2 and nz = d + nv; phi_i the per-step reward term; f = J / |J_best(w)|. Per-step arrays are
stacked horizontally, step i = 0..H in columns (as CasADi's ``map`` returns them).

Two implementations: :class:`~comanip.planning.curvature.ReachCurvature` (point masses, exact Hessian,
data :class:`ReachTerms`) and :class:`~comanip.planning.linearised_curvature.LinearisedCurvature` (arms,
approximate Hessian, data :class:`ArmTerms`, and :class:`Rollout` from the value-only evaluation).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from comanip.optim import Evaluation
from comanip.planning.reach_parameters import ReachParameters


@dataclass(frozen=True, eq=False)
class StateBelief:
    """The state's belief along a plan."""

    mean: np.ndarray
    """Mean states (H+1, nx)."""
    cov: np.ndarray
    """Their covariances (H+1, nx, nx)."""


@dataclass(frozen=True, eq=False)
class GoalDerivatives:
    """The objective's derivatives in the goal g (d,), m, at one evaluation at torques x (H·n,)."""

    gradient: np.ndarray
    """∂f/∂g (d,)."""
    cross: np.ndarray
    """∂²f/∂x∂g (H·n, d)."""
    hessian: np.ndarray
    """∂²f/∂g² (d, d)."""


@dataclass(eq=False, slots=True)
class ReachTerms:
    """One evaluation at torques x: what the Hessian and the goal derivatives need (point masses)."""

    x: np.ndarray
    """Torques evaluated (H·n,), N·m or N."""
    width: float
    """Goal width w (m)."""
    phi_hess: np.ndarray
    """∇²_z~ phi_i (H+1, d + r, d + r) in each step's reduced coordinates z~_i = (mu_x,i, U_iᵀ vech Sigma_x,i)
    (:class:`~comanip.planning.curvature.ReachCurvature`; r the rank of the covariance rows)."""
    phi_grad: np.ndarray
    """∇_z~ phi_i (H+1, d + r) in the same coordinates."""


@dataclass(eq=False)
class Rollout:
    """The forward rollout alone at torques x (an arm's value-only evaluation): enough for the path limits."""

    x: np.ndarray
    """Torques evaluated (H·n,)."""
    width: float
    """Goal width w (m)."""
    mean: np.ndarray
    """Mean states mu_i stacked (2n, H+1)."""


@dataclass(eq=False)
class ArmPieces:
    """The per-step pieces of an arm's approximate Hessian at one evaluation
    (:mod:`comanip.planning.linearised_curvature`)."""

    A: np.ndarray
    """Step Jacobians d mu_{i+1}/d mu_i stacked (2n, 2n·H)."""
    B: np.ndarray
    """Step Jacobians d mu_{i+1}/d tau_i stacked (2n, n·H)."""
    J: np.ndarray
    """Kinematic Jacobians J(q_i) stacked (d, n·(H+1))."""
    phi_hess: np.ndarray
    """∇²_z phi_i stacked (nz, nz·(H+1))."""
    phi_grad: np.ndarray
    """∇_z phi_i stacked (nz, H+1)."""
    kinematic_hessian: np.ndarray
    """∇²_q [λ·x_ee(q) + <Λ, J Sigma_qq Jᵀ>] at q_i stacked (n, n·(H+1)) (the kinematics' curvature)."""
    dvech: np.ndarray
    """d vech Sigma_x,i / d q_i stacked (nv, n·(H+1))."""


@dataclass(eq=False)
class ArmTerms:
    """One evaluation at torques x for a nonlinear body: the belief rollout (f and its gradient come with it).
    The Hessian's pieces and the mean sensitivities are computed from the rollout on first request and kept
    here (:meth:`~comanip.planning.linearised_curvature.LinearisedCurvature.pieces`,
    :meth:`~comanip.planning.linearised_curvature.LinearisedCurvature.mean_sensitivities`): a Newton
    iteration that keeps its last Hessian and has no limit in its working set does not need them."""

    x: np.ndarray
    """Torques evaluated (H·n,), N·m."""
    goal: np.ndarray
    """Goal g (d,), m."""
    width: float
    """Goal width w (m)."""
    mean: np.ndarray
    """Mean states mu_i stacked (2n, H+1)."""
    cov: np.ndarray
    """State covariances Sigma_i stacked (2n, 2n·(H+1))."""
    pieces: ArmPieces | None = field(default=None, repr=False)
    """The Hessian's per-step pieces, computed on first request."""
    sensitivities: np.ndarray | None = field(default=None, repr=False)
    """d mu_i / d tau_k (H+1, 2n, H, n), computed on first request and kept with the evaluation it belongs to."""


class Curvature(Protocol):
    """Objective, gradient and Hessian terms of one model's reaching problem, normalised by |J_best(w)|.

    ``evaluate`` computes everything one point needs at once and returns it as typed data; the other
    methods read that data, so a Newton iteration evaluates each point once.
    """

    exact: bool
    """The Hessian is exact (Newton converges quadratically); False: an approximation the solver corrects
    with secant updates."""
    carries_belief: bool
    """The data holds the mean path and its sensitivities (:meth:`mean_path`, :meth:`mean_sensitivities`,
    :meth:`trajectory`); False: the belief comes from the problem's expanded rollout."""

    def normaliser(self, width: float) -> float:
        """|J_best(w)| for width w (m)."""

    def evaluate(self, x: np.ndarray, params: ReachParameters) -> Evaluation[ReachTerms | ArmTerms]:
        """f, ∇f (H·n,) and the data at torques x (H·n,) and parameters p."""

    def value(self, x: np.ndarray, params: ReachParameters) -> float:
        """f at torques x."""

    def value_and_data(self, x: np.ndarray, params: ReachParameters) -> Evaluation[Rollout | None]:
        """f and data enough for the path limits (no gradient) at torques x, as cheaply as the curvature can."""

    def hessian(self, data: ReachTerms) -> np.ndarray:
        """∇²f (H·n, H·n), exact or approximate (see :attr:`exact`)."""

    def goal_derivatives(self, data: ReachTerms) -> GoalDerivatives:
        """∂f/∂g (d,), ∂²f/∂x∂g (H·n, d), ∂²f/∂g² (d, d)."""
