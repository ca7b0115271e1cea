"""Objective, gradient and a structure-exploiting Hessian of the reaching problem, for Newton-type solvers.

Notation (docs/formulation.md §2–4, ``docs/notation.md``): torques tau (H, n), flattened step by step into x (H·n,); the end-effector belief at
step i as z_i = (mu_x,i (d,), vech Sigma_x,i (d(d+1)/2,)); the per-step reward term
phi_i(z_i) = -w_i R(mu_x,i, Sigma_x,i). Everything is divided by |J_best(w)| (the planner's normaliser), so

    f(x) = J(tau) / |J_best| = Σ_i phi_i(z_i(tau)) / |J_best| + nu Σ_k ||tau_k||² / |J_best|.

Along the mean trajectory, with A_i, B_i the step Jacobians and J_i the kinematic Jacobian,

    d mu_x,i / d tau_k = G_ik = J_i [A_{i-1} ... A_{k+1} B_k]_q   (d, n), zero for k ≥ i,
    Sigma_x,i          = Σ_{k<i} G_ik N(tau_k) G_ikᵀ,

so the Hessian is a sum of small per-step pieces,

    ∇²f = Σ_i Z_iᵀ ∇²phi_i Z_i + blockdiag_k ∇²_tau <S_k, N(tau_k)> + 2 nu I / |J_best|,
    Z_i = dz_i/dtau,   S_k = Σ_i G_ikᵀ Λ_i G_ik,   Λ_i = d phi_i / d Sigma_x,i.

N(tau) is quadratic in tau for every noise form, so dN/dtau is linear and ∇²_tau <S, N> is a constant
linear map of S. For a point mass (linear dynamics, x_ee = q) G is constant and the formula is the exact
Hessian, at the cost of one batched matrix product instead of CasADi's forward-over-reverse sweep through
the whole rollout (about 870 000 SX instructions for the Cartesian preset).
"""

from __future__ import annotations

import warnings

import casadi as ca
import numpy as np

from comanip.belief.noise import noise_covariance
from comanip.objectives.reach_objective import velocity_cost
from comanip.objectives.reward import GoalReward
from comanip.model import model_key
from comanip.caching.buffered_function import BufferedFunction
from comanip.caching.compiled import cached_compiled, compile_in_background, compiled_or_cached
from comanip.optim import Evaluation
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.reach_problem import ReachProblem
from comanip.planning.terms import GoalDerivatives, ReachTerms


class ReachCurvature:
    """f, its gradient and its Hessian for one model's reaching problem, exact for a linear body (a point mass: the
    planner's :class:`~comanip.planning.body_kind.PointMass` builds it; an arm's is
    :class:`~comanip.planning.linearised_curvature.LinearisedCurvature`); a :class:`~comanip.planning.terms.Curvature`.

    Parameters p = [s0 (2n,), goal (d,), width] as in the planner; x = tau flattened (H·n,).

    Args:
        problem: the model's :class:`ReachProblem`.
        compile: True: build the per-solve functions as C (:mod:`comanip.caching.compiled`): about a third
            faster per solve, at a few seconds' build per new model. None: load them if an earlier build for
            this model is in the disk cache, else run CasADi's virtual machine until
            :meth:`compile_in_background` has built them. False: the virtual machine.

    One curvature serves one thread at a time: its evaluations and Hessians go through arrays it owns (the
    compiled functions' buffers, the rows of Z~).
    """

    exact = True
    """The Hessian is exact."""
    carries_belief = False
    """The data holds no mean path: a point mass's belief comes from the problem's expanded rollout."""

    def __init__(self, problem: ReachProblem, compile: bool | None = False):
        model = self.model = problem.model
        self.problem = problem
        n, d, H = model.n, model.d, model.H
        self.size = n * H
        self._triangle = np.array([(a, b) for b in range(d) for a in range(b + 1)])
        self._tag = model_key(model)
        self._noise_hessian = _noise_second_derivatives(model)
        self._G = _constant_sensitivities(model)
        self._velocity_hessian = _velocity_cost_hessian(problem)
        self._build_constant_products()
        reduced = d + self._U.shape[2]
        # where the terms' output vector's pieces end: the gradient, the per-step Hessians, the per-step gradients
        self._term_ends = np.cumsum([1 + n * H, reduced * reduced * (H + 1), reduced * (H + 1)])
        self._reduced_shapes = ((H + 1, reduced, reduced), (H + 1, reduced))
        params = ca.vertcat(problem.s0, problem.goal, problem.width)
        functions = [self._terms_function(problem),
                     ca.Function("reach_value", [ca.vec(problem.tau), params], [problem.objective / -problem.best_objective])]
        if compile:
            functions = [compiled_or_cached(function, self._tag) for function in functions]
        elif compile is None:
            cached = [cached_compiled(function.name(), self._tag) for function in functions]
            functions = cached if all(f is not None for f in cached) else functions
        self._terms, self._value = (BufferedFunction(function) for function in functions)
        self._compiling = None  # the background build's future (compile_in_background)

    # -- the compiled per-solve function -------------------------------------------------------------
    def _terms_function(self, problem: ReachProblem) -> ca.Function:
        """``(x, p) -> [f; grad f; ∇²_z~ phi_i for i = 0..H; ∇_z~ phi_i for i = 0..H]`` in one output vector, the
        per-step pieces in the reduced coordinates z~_i (:meth:`_build_constant_products`), each Hessian row by
        row: :meth:`evaluate` reshapes the slices as they are (a call copies one array out instead of four)."""
        x = ca.vec(problem.tau)
        scale = -problem.best_objective
        f = problem.objective / scale
        step_terms = _reward_derivatives_function(problem.model)
        hessians, gradients = [], []
        for T, w, mu_x, Sigma_x in zip(self._T, problem.weights, problem.ee_means, problem.ee_covs):
            vech = ca.vertcat(*[Sigma_x[a, b] for a, b in self._triangle])
            hess, grad = step_terms(mu_x, vech, problem.goal, problem.width, w / scale)
            T = ca.DM(T)
            hessians.append(ca.vec(ca.mtimes([T.T, hess, T])))  # symmetric: column by column is row by row
            gradients.append(ca.mtimes(T.T, grad))
        return ca.Function("reach_terms", [x, ca.vertcat(problem.s0, problem.goal, problem.width)],
                           [ca.vertcat(f, ca.gradient(f, x), *hessians, *gradients)], ["x", "p"], ["f_grad_phi_hess_phi_grad"])

    def _build_constant_products(self) -> None:
        """Z's mean rows and the coefficients of its covariance rows (linear in tau), fixed for a linear body.

        The covariance rows of step i, dvech Sigma_x,i/dtau, span only a few directions of the vech space
        (one for isotropic noise on an isotropic point mass: Sigma_x,i ∝ I), so they are stored in an
        orthonormal basis U_i of that span: Z_i = blockdiag(I, U_i) Z~_i exactly, and the Hessian's
        products shrink with the rows.
        """
        model, G = self.model, self._G
        n, d, H = model.n, model.d, model.H
        self._effort = 2 * model.nu
        a, b = self._triangle.T
        # dvech Sigma_x,i[v] / dtau_k[j] = Σ_l K[i, v, k, j, l] tau_k[l], v = (a, b) in vech order
        K = np.einsum("ikar,jlrs,ikbs->iabkjl", G, self._noise_hessian, G, optimize=True)[:, a, b]
        flat = K.reshape(H + 1, len(a), -1)
        U, singular, _ = np.linalg.svd(flat, full_matrices=False)
        rank = max(1, int(np.max(np.sum(singular > 1e-12 * singular.max(), axis=1))))
        self._U = np.ascontiguousarray(U[:, :, :rank])  # (H+1, nv, r)
        self._K = np.ascontiguousarray(np.einsum("ivr,ivkjl->irkjl", self._U, K))  # (H+1, r, H, n, n)
        # isotropic and per-channel noise: N's second derivative is diagonal in (j, l), and the contraction
        # with tau is an elementwise product (ten times faster than the general one)
        off_diagonal = self._noise_hessian * (1 - np.eye(n))[:, :, None, None]
        self._K_diagonal = None if off_diagonal.any() else np.ascontiguousarray(np.einsum("irkjj->irkj", self._K))
        self._mean_rows = np.ascontiguousarray(G.transpose(0, 2, 1, 3)).reshape(H + 1, d, H, n)
        # z~_i = (mu_x,i, U_iᵀ vech Sigma_x,i): its Hessian is Tᵀ ∇²phi T with T = blockdiag(I_d, U_i)
        self._T = np.zeros((H + 1, d + len(a), d + rank))
        self._T[:, :d, :d] = np.eye(d)
        self._T[:, d:, d:] = self._U
        self._rows = np.empty((H + 1, d + rank, H, n))  # Z~ (_reduced_rows), its mean rows fixed
        self._rows[:, :d] = self._mean_rows
        # flat indices of the Hessian's block-diagonal entries (k·n + j, k·n + l), in the order of the blocks output
        k, j, l = np.meshgrid(np.arange(H), np.arange(n), np.arange(n), indexing="ij")
        self._block_entries = ((k * n + j) * (H * n) + k * n + l).ravel()

    def compile_in_background(self) -> None:
        """Build the per-solve function and the value-only one as C in a background thread
        (:func:`compile_in_background`, 3–17 s for the point-mass presets, cached on disk); :meth:`evaluate`
        switches to them once built (the same numbers; an evaluation 5–8 times faster, a value 2–3 times).
        Nothing happens if they are compiled or being compiled."""
        if self._compiling is None and not _is_compiled(self._terms.function):
            self._compiling = compile_in_background(self, lambda curvature: [curvature._terms.function,
                                                                             curvature._value.function], self._tag)

    def _use_compiled_when_built(self) -> None:
        """Swap in the background build's function once it is ready (a failed build warns and keeps the
        virtual machine)."""
        future, self._compiling = self._compiling, None
        if future.exception() is not None:
            warnings.warn(f"compiling the planner's terms failed ({future.exception()}); going on uncompiled",
                          RuntimeWarning, stacklevel=3)
        elif future.result() is not None:
            self._terms, self._value = (BufferedFunction(function) for function in future.result())

    # -- evaluation ----------------------------------------------------------------------------------
    def normaliser(self, width: float) -> float:
        """|J_best(w)|: the objective is divided by it."""
        return self.problem.normaliser(width)

    def evaluate(self, x: np.ndarray, params: ReachParameters) -> Evaluation[ReachTerms]:
        """f, grad f (H·n,) and the data for :meth:`hessian` at torques x (H·n,) and parameters p."""
        if self._compiling is not None and self._compiling.done():
            self._use_compiled_when_built()
        out = self._terms.vector(x, params.vector)
        ends, (hessians, gradients) = self._term_ends, self._reduced_shapes
        return Evaluation(float(out[0]), out[1:ends[0]], ReachTerms(x, params.width, out[ends[0]:ends[1]].reshape(hessians),
                                                                    out[ends[1]:ends[2]].reshape(gradients)))

    def value(self, x: np.ndarray, params: ReachParameters) -> float:
        """f at torques x (H·n,) alone."""
        return float(self._value.vector(x, params.vector)[0])

    def value_and_data(self, x: np.ndarray, params: ReachParameters) -> Evaluation[None]:
        """f at torques x, without data: a point mass has no path limits, so a line-search trial needs none."""
        return Evaluation(self.value(x, params), None, None)

    def final_position_change(self, torque_change: np.ndarray) -> np.ndarray:
        """How far (d,) m the mean end-effector position at step H moves for a change of the torques (H, n) (exact:
        for a linear body the mean is affine in the torques)."""
        return self._mean_rows[-1].reshape(self.model.d, -1) @ np.ravel(torque_change)

    def hessian(self, data: ReachTerms) -> np.ndarray:
        """∇²f (H·n, H·n) from the data :meth:`evaluate` returned."""
        model = self.model
        n, d, H = model.n, model.d, model.H
        rank = self._U.shape[2]
        Z = self._reduced_rows(data)
        QZ = np.matmul(data.phi_hess, Z)
        hessian = _causal_gram(Z.reshape(-1, H * n), QZ.reshape(-1, H * n), d + rank, n)
        # ∇²_tau Σ_i Σ_v (dphi_i/dvech_v) Sigma_x,i[v]: the noise's own curvature, block-diagonal in k, from the
        # gradient's covariance coordinates U_iᵀ ∇_vech phi_i
        blocks = data.phi_grad[:, d:].ravel() @ self._K.reshape((H + 1) * rank, H * n * n)
        hessian.ravel()[self._block_entries] += blocks
        hessian.ravel()[::H * n + 1] += self._effort / self.normaliser(data.width)
        if self._velocity_hessian is not None:  # the speed cost is scaled by |J_best| already
            hessian += self._velocity_hessian
        return hessian

    def goal_derivatives(self, data: ReachTerms) -> GoalDerivatives:
        """∂f/∂g (d,), ∂²f/∂x∂g (H·n, d) and ∂²f/∂g² (d, d) from the data :meth:`evaluate` returned, exact.

        phi_i depends on the goal only through mu_x,i - g (the reward is a density of their difference), so
        ∂phi_i/∂g = -∂phi_i/∂mu_x,i, ∂²phi_i/∂z_i∂g = -∂²phi_i/∂z_i∂mu_x,i and ∂²phi_i/∂g² = ∂²phi_i/∂mu_x,i²:
        columns of the per-step derivatives the Hessian uses anyway. Then ∂f/∂g = Σ_i ∂phi_i/∂g,
        ∂²f/∂x∂g = Σ_i Z_iᵀ ∂²phi_i/∂z_i∂g and ∂²f/∂g² = Σ_i ∂²phi_i/∂g² (the effort does not depend on g).
        """
        d = self.model.d
        return GoalDerivatives(-data.phi_grad[:, :d].sum(axis=0), self.goal_cross_derivative(data),
                               data.phi_hess[:, :d, :d].sum(axis=0))

    def goal_cross_derivative(self, data: ReachTerms) -> np.ndarray:
        """∂²f/∂x∂g (H·n, d) of :meth:`goal_derivatives` alone (what the tangential predictor needs)."""
        d = self.model.d
        Z = self._reduced_rows(data)
        # ∂²phi_i/∂z~_i∂g = -∂²phi_i/∂z~_i∂mu_x,i: the first d columns of the reduced Hessian (T_i is the identity there)
        goal_columns = data.phi_hess[:, :, :d].reshape(-1, d)  # ((H+1)·(d + r), d)
        return -(Z.reshape(-1, Z.shape[2]).T @ goal_columns)

    def _reduced_rows(self, data: ReachTerms) -> np.ndarray:
        """Z~_i = dz~_i/dx stacked (H+1, d + r, H·n) at the data's torques: mean rows fixed, covariance rows linear
        in tau. The array is the curvature's own, its mean rows written once: valid until the next call."""
        model = self.model
        n, d, H = model.n, model.d, model.H
        tau = np.asarray(data.x).reshape(H, n)
        Z = self._rows
        if self._K_diagonal is not None:
            np.multiply(self._K_diagonal, tau, out=Z[:, d:])
        else:
            np.einsum("irkjl,kl->irkj", self._K, tau, out=Z[:, d:])
        return Z.reshape(H + 1, d + self._U.shape[2], H * n)


def _is_compiled(function: ca.Function) -> bool:
    """True for a function loaded from a compiled library (:func:`compiled`), False for CasADi's SX one."""
    return function.class_name() != "SXFunction"


def _reward_derivatives_function(model) -> ca.Function:
    """``(mu_x (d,), vech Sigma_x, goal, width, weight) -> (∇²phi, ∇phi)`` w.r.t. z = (mu_x, vech Sigma_x),
    phi = -weight R(mu_x, Sigma_x)."""
    d = model.d
    mu_x = ca.SX.sym("mu_x", d)
    triangle = [(a, b) for b in range(d) for a in range(b + 1)]
    vech = ca.SX.sym("vech", len(triangle))
    Sigma_x = ca.SX(d, d)
    for e, (a, b) in enumerate(triangle):
        Sigma_x[a, b] = Sigma_x[b, a] = vech[e]
    goal, width, weight = ca.SX.sym("goal", d), ca.SX.sym("width"), ca.SX.sym("weight")
    phi = -weight * GoalReward.of(model).expected(mu_x, Sigma_x, goal, width)
    z = ca.vertcat(mu_x, vech)
    hess, grad = ca.hessian(phi, z)
    return ca.Function("reward_derivatives", [mu_x, vech, goal, width, weight], [hess, grad])


def _noise_second_derivatives(model) -> np.ndarray:
    """D[j, l] = ∂²N/∂tau_j ∂tau_l (n, n, n, n): constant, since N(tau) is quadratic in tau."""
    n = model.n
    tau = ca.SX.sym("tau", n)
    N = noise_covariance(tau, model.kappa, model.noise)
    D = np.zeros((n, n, n, n))
    for a in range(n):
        for b in range(n):
            D[:, :, a, b] = np.asarray(ca.evalf(ca.substitute(ca.hessian(N[a, b], tau)[0], tau, ca.DM.zeros(n))))
    return D


def _velocity_cost_hessian(problem: ReachProblem) -> np.ndarray | None:
    """∇² of the speed cost (stop_weight, joint_velocity_weight) over |J_best| (H·n, H·n), constant for a linear
    body (it is quadratic in tau); None without one."""
    model = problem.model
    if not model.has_velocity_cost:
        return None
    n = model.n
    x = ca.vec(problem.tau)
    cost = velocity_cost([m[n:2 * n] for m in problem.means[1:]], [S[n:2 * n, n:2 * n] for S in problem.covs[1:]],
                         model.stop_weight, model.joint_velocity_weight)
    hessian = ca.Function("velocity_hessian", [x, problem.s0], [ca.hessian(cost, x)[0]])
    return np.asarray(hessian(np.zeros(x.numel()), np.zeros(problem.s0.numel())))


def _constant_sensitivities(model) -> np.ndarray:
    """G[i, k] = d mu_x,i / d tau_k (H+1, H, d, n) of a linear body (the same at every torque)."""
    body, n, H = model.body, model.n, model.H
    nx = model.state_size
    s, tau = ca.SX.sym("s", nx), ca.SX.sym("tau", n)
    step = body.discrete_step(s, tau, model.h)
    A = np.asarray(ca.evalf(ca.jacobian(step, s)))
    B = np.asarray(ca.evalf(ca.jacobian(step, tau)))
    J = np.asarray(body.kinematics_function(np.zeros(n))[1])
    state_sensitivity = np.zeros((H + 1, H, nx, n))  # d s_i / d tau_k
    for i in range(H):
        state_sensitivity[i + 1, :i] = A @ state_sensitivity[i, :i]
        state_sensitivity[i + 1, i] = B
    return np.einsum("ar,ikrb->ikab", J, state_sensitivity[:, :, :n, :])


def _causal_gram(Z: np.ndarray, QZ: np.ndarray, rows_per_step: int, n: int) -> np.ndarray:
    """Σ_i Z_iᵀ QZ_i for Z, QZ ((H+1)·nz, H·n) stacking per-step blocks of ``rows_per_step`` rows, where
    step i's block is zero beyond column n·i (causality).

    Steps are taken in chunks so the products skip most of the zero upper part; the 2-D slices are views, which
    BLAS reads in place. A chunk per 30 unknowns, at most 4: each product costs a few microseconds of its own,
    more than the zeros it skips in a small problem.
    """
    steps = Z.shape[0] // rows_per_step
    chunks = min(4, max(1, Z.shape[1] // 30))
    bounds = [steps * k // chunks for k in range(chunks + 1)]
    last = slice(bounds[-2] * rows_per_step, None)
    out = Z[last].T @ QZ[last]  # the last chunk reaches every column: it makes the matrix the others add to
    for lo, hi in zip(bounds[:-2], bounds[1:-1]):
        cols = n * (hi - 1)
        if cols > 0:
            rows = slice(lo * rows_per_step, hi * rows_per_step)
            out[:cols, :cols] += Z[rows, :cols].T @ QZ[rows, :cols]
    return out
