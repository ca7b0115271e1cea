"""Objective, exact gradient and a structured approximate Hessian for nonlinear bodies (the Panda).

Notation as in :mod:`comanip.planning.curvature`: x = tau flattened (H·n,), z_i = (mu_x,i, vech Sigma_x,i),
phi_i = -w_i R / |J_best|, T_ik = d mu_q,i / d tau_k (n, n), G_ik = J_i T_ik. For a nonlinear body A_i,
B_i and J_i depend on the mean path, and the exact Hessian needs third derivatives of the rigid-body
dynamics along all of it (far too slow to evaluate for an arm in a Newton loop). The Hessian here keeps

- Z_i's mean rows exactly (G_ik, by the chain rule along the mean: T_{i+1,k} = A_i T_ik, T_{k+1,k} = B_k);
- Z_i's covariance rows from the noise injected at each step (A, B held fixed) and from J_i's dependence
  on q_i (d vech(J Sigma_qq Jᵀ)/dq_i · T_i);
- the curvature of the kinematics, Σ_i T_iᵀ ∇²_q [∇_mu phi_i · x_ee(q) + <Λ_i, J(q) Sigma_qq J(q)ᵀ>] T_i;
- the noise's own curvature and the effort, as for linear bodies;
- the model's speed cost (``stop_weight``, ``joint_velocity_weight``) in the same way: its mean part
  Σ_i c_i ||mu_qdot,i||² through the joint-velocity rows of T_i (Gauss–Newton), its covariance part
  Σ_i c_i tr Sigma_qdot,i through the noise injected at each step (A, B held);

and leaves out the curvature of the dynamics and the dependence of A_i, B_i on the mean path. Along the
eigenvectors of the exact Hessian it agrees closely except in a few directions of negative curvature; the
Newton method's secant corrections learn those. The gradient is exact, so the optimum is that of the docs/formulation.md §4 objective.

The objective and gradient come from one CasADi function, the per-step pieces of the Hessian from a second one
evaluated on the first one's rollout only when a Hessian is assembled (with ``hessian_refresh`` about one
iteration in three on the Panda, where the pieces cost about half as much as the gradient). Both are
MX graphs over per-step SX functions (belief step, reward, kinematics), compiled to C on first use
(:mod:`comanip.caching.compiled`); generating C for the expanded problem instead gives hundreds of megabytes
that do not compile in minutes.
"""

from __future__ import annotations

import copy

import casadi as ca
import numpy as np

from comanip.belief.propagation import belief_step_function, linearised_step_function
from comanip.objectives.reach_objective import velocity_cost
from comanip.objectives.reward import GoalReward
from comanip.model import model_key
from comanip.caching.buffered_function import BufferedFunction
from comanip.caching.compiled import compiled_or_cached
from comanip.planning.curvature import _noise_second_derivatives, _reward_derivatives_function
from comanip.optim import Evaluation
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.reach_problem import ReachProblem
from comanip.planning.terms import ArmPieces, ArmTerms, GoalDerivatives, Rollout, StateBelief


class LinearisedCurvature:
    """f, its exact gradient and an approximate Hessian for a nonlinear body; a
    :class:`~comanip.planning.terms.Curvature`, like :class:`comanip.planning.curvature.ReachCurvature`.

    Args:
        problem: the model's :class:`ReachProblem` (its weights and normaliser are used).
        compile: build the per-solve functions as C for this processor (recommended: about ten times faster than
            CasADi's virtual machine for the Panda, with the same numbers up to rounding; the first build takes a
            minute or two and is cached on disk, :func:`~comanip.caching.compiled.compiled`).
    """

    exact = False
    """The Hessian is an approximation (the solver adds secant corrections)."""
    carries_belief = True
    """The data holds the mean path, its sensitivities and the covariances."""

    def __init__(self, problem: ReachProblem, compile: bool = True):
        model = self.model = problem.model
        self.problem = problem
        d = model.d
        self._triangle = np.array([(a, b) for b in range(d) for a in range(b + 1)])
        tag = model_key(model)  # a model built before loads its C functions without generating their source (~1 s)
        self._gradient, self._pieces, self._value = (BufferedFunction(compiled_or_cached(function, tag, for_this_processor=True) if compile else function)
                                                     for function in self._functions(problem))
        self._noise_hessian = _noise_second_derivatives(model)
        # D[j, l, r, s] as a matrix ((r, s), (j, l)): <S, ∂²N/∂tau_j ∂tau_l> for every (j, l) is S.ravel() @ it
        self._noise_hessian_matrix = self._noise_hessian.reshape(model.n ** 2, model.n ** 2).T.copy()
        # Λ from d phi / d vech Sigma_x: an off-diagonal vech entry stands for Λ_ab and Λ_ba, each getting half
        self._vech_weights = np.where(self._triangle[:, 0] == self._triangle[:, 1], 1.0, 0.5)
        # the speed cost's weights enter the compiled functions as an input, so every weight shares one build
        self._speed_weights = ((np.array([model.stop_weight, model.joint_velocity_weight]),)
                               if model.has_velocity_cost else ())

    def _functions(self, problem: ReachProblem) -> tuple[ca.Function, ca.Function, ca.Function]:
        """The per-solve functions, with per-step outputs stacked horizontally:

        - gradient: ``(x, s0, goal, width) -> (f, grad, mean, cov)``;
        - pieces: ``(x, goal, width, mean, cov) -> (A, B, J, phi_hess, phi_grad, W, dvech/dq)``, the fields of
          :class:`~comanip.planning.terms.ArmPieces` (W its ``kinematic_hessian``), from the gradient's rollout;
        - value: ``(x, s0, goal, width) -> (f, mean)``, the forward rollout alone (a fraction of the gradient's
          cost), for line-search trials and comparisons of initial guesses.

        A model with a speed cost adds a fifth input to gradient and value, its weights [stop_weight,
        joint_velocity_weight] (2,).
        """
        model, body = problem.model, problem.model.body
        n, d, H = model.n, model.d, model.H
        x = ca.MX.sym("x", n * H)
        s0, goal, width = ca.MX.sym("s0", 2 * n), ca.MX.sym("goal", d), ca.MX.sym("width")
        scale = problem.normaliser_function(width)
        weights = ca.DM(problem.weights).T / scale
        tau = ca.reshape(x, n, H)
        step = belief_step_function(body, model.h, model.kappa, model.noise)
        cost = _stage_cost_function(model)
        mean, cov = [s0], [ca.MX.zeros(2 * n, 2 * n)]
        for i in range(H):
            mu, Sigma = step(mean[-1], cov[-1], tau[:, i])
            mean.append(mu)
            cov.append(Sigma)
        means, covs = ca.horzcat(*mean), ca.horzcat(*cov)
        f = ca.sum2(cost.map(H + 1)(means, covs, goal, width, weights)) + model.nu * ca.sumsqr(x) / scale
        inputs, input_names = [x, s0, goal, width], ["x", "s0", "goal", "width"]
        if model.has_velocity_cost:  # scaled by |J_best| in J, so unscaled in f = J / |J_best|
            speed_weights = ca.MX.sym("speed_weights", 2)
            f += velocity_cost([m[n:] for m in mean[1:]], [S[n:, n:] for S in cov[1:]], speed_weights[0], speed_weights[1])
            inputs, input_names = inputs + [speed_weights], input_names + ["speed_weights"]
        gradient = ca.Function("arm_reach_gradient", inputs, [f, ca.gradient(f, x), means, covs], input_names,
                               ["f", "grad", "mean", "cov"])
        value = ca.Function("arm_reach_value", inputs, [f, means], input_names, ["f", "mean"])
        means, covs = ca.MX.sym("mean", 2 * n, H + 1), ca.MX.sym("cov", 2 * n, 2 * n * (H + 1))
        _, A, B = linearised_step_function(body, model.h).map(H)(means[:, :H], tau)
        J, phi_hess, phi_grad, W, dvech = _stage_curvature_function(model, self._triangle).map(H + 1)(
            means, covs, goal, width, weights)
        pieces = ca.Function("arm_reach_pieces", [x, goal, width, means, covs], [A, B, J, phi_hess, phi_grad, W, dvech],
                             ["x", "goal", "width", "mean", "cov"], _PIECE_FIELDS)
        return gradient, pieces, value

    def normaliser(self, width: float) -> float:
        """|J_best(w)|: the objective is divided by it."""
        return self.problem.normaliser(width)

    def for_another_thread(self) -> "LinearisedCurvature":
        """These terms with evaluation buffers of their own, for a thread evaluating beside this one (the compiled
        functions and constants are shared; only the buffers the functions read and write are not)."""
        twin = copy.copy(self)
        twin._gradient, twin._pieces, twin._value = (BufferedFunction(buffered.function)
                                                     for buffered in (self._gradient, self._pieces, self._value))
        return twin

    def evaluate(self, x: np.ndarray, params: ReachParameters) -> Evaluation[ArmTerms]:
        """f, grad f (H·n,) and the data for :meth:`hessian` and :meth:`trajectory` at torques x and parameters p."""
        goal = params.goal
        f, grad, mean, cov = self._gradient(x, params.start, goal, params.width, *self._speed_weights)
        return Evaluation(float(f.item()), grad.ravel(), ArmTerms(np.array(x, dtype=float), goal.copy(), params.width, mean, cov))

    def pieces(self, data: ArmTerms) -> ArmPieces:
        """The Hessian's per-step pieces at the evaluation ``data``, computed on first request and kept in
        ``data.pieces``."""
        if data.pieces is None:
            data.pieces = ArmPieces(*self._pieces(data.x, data.goal, data.width, data.mean, data.cov))
        return data.pieces

    def value(self, x: np.ndarray, params: ReachParameters) -> float:
        return self.value_and_data(x, params).f

    def value_and_data(self, x: np.ndarray, params: ReachParameters) -> Evaluation[Rollout]:
        """f and the data for :meth:`mean_path` at torques x: the forward rollout alone, without derivatives."""
        f, means = self._value(x, params.start, params.goal, params.width, *self._speed_weights)
        return Evaluation(float(f.item()), None, Rollout(np.array(x, dtype=float), params.width, means))

    @staticmethod
    def mean_path(data: ArmTerms | Rollout) -> np.ndarray:
        """Mean state trajectory (H+1, 2n) from the data of :meth:`evaluate` or :meth:`value_and_data`."""
        return data.mean.T.copy()

    def mean_sensitivities(self, data: ArmTerms) -> np.ndarray:
        """T[i, :, k, :] = d mu_i / d tau_k (H+1, 2n, H, n) along the mean of the evaluated torques (exact).

        Kept in ``data.sensitivities``: the Hessian and the limits' rows ask for the same evaluation's T.
        """
        if data.sensitivities is not None:
            return data.sensitivities
        n, H = self.model.n, self.model.H
        pieces = self.pieces(data)
        A, B = _per_step(pieces.A, H), _per_step(pieces.B, H)
        T = np.zeros((H + 1, 2 * n, H * n))
        steps = np.arange(H)
        T.reshape(H + 1, 2 * n, H, n)[steps + 1, :, steps] = B  # T_{k+1,k} = B_k
        for i in range(1, H):  # T_{i+1,k} = A_i T_ik for k < i; the blocks k ≥ i+1 stay zero
            np.matmul(A[i], T[i, :, :i * n], out=T[i + 1, :, :i * n])
        data.sensitivities = T.reshape(H + 1, 2 * n, H, n)
        return data.sensitivities

    def hessian(self, data: ArmTerms) -> np.ndarray:
        """Approximate ∇²f (H·n, H·n) from the data :meth:`evaluate` returned.

        The rows of step i are Z_i = [X_i T_i; N_i] with X_i = [J_i; d vech/dq_i] acting on the joint
        sensitivities T_i and N_i the noise rows (:meth:`_noise_rows`). What acts on the mean path is condensed
        by backward recursions along the linearised dynamics (:func:`_costs_to_go`) instead of summed as Gram
        products over per-step rows:

        - the state cost M_i = X_iᵀ Q_i X_i + W_i (and the speed cost's mean part, 2 c_i I on the velocities):
          with S_i = M_i + A_iᵀ S_{i+1} A_i, block (k, l ≥ k) is T_{l+1,k}ᵀ S_{l+1} B_l (:func:`_condensed_upper`);
        - the noise rows' cross terms N_iᵀ Q_cz,i X_i T_i: with P_i = [X_iᵀ Q_zc,i N_i; 0] + A_iᵀ P_{i+1},
          column block l is P_{l+1}ᵀ B_l;
        - the noise's own curvature, blockdiag_k ∇²_tau_k <S'_k, N(tau_k)> with S'_k = Σ_i G_ikᵀ Λ_i G_ik
          (Λ_i = d phi_i / d Sigma_x,i) = B_kᵀ S'_{k+1} B_k, the cost-to-go of M'_i = J_iᵀ Λ_i J_i (and of the
          speed cost's covariance part, c_i I on the velocities: Σ_i c_i tr Sigma_qdot,i).

        The noise rows' Gram product Σ_i N_iᵀ Q_cc,i N_i is formed from their factored form
        (:meth:`_noise_row_terms`).
        """
        model = self.model
        n, d, H = model.n, model.d, model.H
        size = H * n
        tau = data.x.reshape(H, n)
        pieces = self.pieces(data)
        J, Q, W, dvech = (_per_step(v, H + 1) for v in (pieces.J, pieces.phi_hess, pieces.kinematic_hessian, pieces.dvech))
        A, B = _per_step(pieces.A, H), _per_step(pieces.B, H)
        T = self.mean_sensitivities(data)
        X = np.concatenate([J, dvech], axis=1)  # (H+1, nz, n): z_i's rows per joint position
        QX = Q @ X
        rows, scale = self._noise_rows(J @ T[:, :n].reshape(H + 1, n, size), tau)
        a, b = self._triangle.T
        Lambda = np.zeros((H + 1, d, d))
        Lambda[:, a, b] = Lambda[:, b, a] = (pieces.phi_grad[d:] * self._vech_weights[:, None]).T
        quadratic = np.zeros((H + 1, 2, 2 * n, 2 * n))  # per step: the state cost M_i and the noise's M'_i
        quadratic[:, 0, :n, :n] = np.swapaxes(X, 1, 2) @ QX + W
        quadratic[:, 1, :n, :n] = np.swapaxes(J, 1, 2) @ Lambda @ J
        speed = self._speed_weights_per_step()
        if speed is not None:
            quadratic[:, 0, n:, n:] = 2 * speed[:, None, None] * np.eye(n)
            quadratic[:, 1, n:, n:] = speed[:, None, None] * np.eye(n)
        linear = np.zeros((H + 1, 2 * n, rows.shape[2]))
        linear[:, :n] = np.swapaxes(QX[:, d:], 1, 2) @ rows
        _costs_to_go(quadratic, linear, A)
        SB = quadratic[1:] @ B[:, None]  # (H, 2, 2n, n): S_{l+1} B_l and S'_{l+1} B_l
        cross = (np.swapaxes(linear[1:], 1, 2) @ B).transpose(1, 0, 2).reshape(-1, size)  # Σ_i N_iᵀ Q_cz,i X_i T_i
        half = _condensed_upper(T, SB[:, 0])
        half += self._noise_row_terms(rows, scale, Q[:, d:, d:], cross)
        hessian = half + half.T
        noise_curvature = (np.swapaxes(B, 1, 2) @ SB[:, 1]).reshape(H, n * n) @ self._noise_hessian_matrix
        diagonal = np.arange(H)
        hessian.reshape(H, n, H, n)[diagonal, :, diagonal, :] += noise_curvature.reshape(H, n, n)
        hessian[np.diag_indices(size)] += 2 * model.nu / self.normaliser(data.width)
        return hessian

    def _speed_weights_per_step(self) -> np.ndarray | None:
        """c_i (H+1,) of the speed cost Σ_i c_i E||qdot_i||² (c_0 = 0: the start is given); None without one."""
        if not self._speed_weights:
            return None
        stop, running = self._speed_weights[0]
        H = self.model.H
        c = np.full(H + 1, running / H)
        c[0] = 0.0
        c[-1] += stop
        return c

    def goal_derivatives(self, data: ArmTerms) -> GoalDerivatives:
        """∂f/∂g (d,), ∂²f/∂x∂g (H·n, d) and ∂²f/∂g² (d, d) from the data :meth:`evaluate` returned.

        phi_i depends on the goal only through x_ee(q_i) - g, so ∂phi_i/∂g = -∂phi_i/∂mu_x,i and
        ∂²phi_i/∂z_i∂g = -∂²phi_i/∂z_i∂mu_x,i (columns of the per-step derivatives), and
        ∂²f/∂x∂g = Σ_i Z_iᵀ ∂²phi_i/∂z_i∂g with the rows Z_i of :meth:`hessian`, contracted here without
        forming them. ∂f/∂g, ∂²f/∂g² and the mean rows' part of ∂²f/∂x∂g are exact; the covariance rows'
        part carries the Hessian's approximation (A_i, B_i held along the path).
        """
        pieces = self.pieces(data)
        x, phi_grad = data.x, pieces.phi_grad
        model = self.model
        n, d, H = model.n, model.d, model.H
        a, b = self._triangle.T
        J, Q, dvech = (_per_step(v, H + 1) for v in (pieces.J, pieces.phi_hess, pieces.dvech))
        c_mean, c_vech = -Q[:, :d, :d], -Q[:, d:, :d]  # ∂²phi_i/∂mu_x∂g (H+1, d, d), ∂²phi_i/∂vech∂g (H+1, nv, d)
        Tq = self.mean_sensitivities(data)[:, :n].reshape(H + 1, n, H * n)
        # mean rows J_i T_i and the rows of J(q_i)'s effect on Sigma_x, d vech/dq_i T_i, share T_i
        per_q = np.swapaxes(J, 1, 2) @ c_mean + np.swapaxes(dvech, 1, 2) @ c_vech  # (H+1, n, d)
        cross = Tq.reshape(-1, H * n).T @ per_q.reshape(-1, d)
        # rows of the noise injected at step k, vech(G_ik E_kj G_ikᵀ), contracted with column m of c_vech as
        # <C_im, G_ik E_kj G_ikᵀ> = <S_km, E_kj>, S_km = Σ_i G_ikᵀ C_im G_ik (n, n), C_im symmetric from vech
        C = np.zeros((H + 1, d, d, d))  # (i, a, b, m)
        C[:, a, b] = C[:, b, a] = c_vech * np.where(a == b, 1.0, 0.5)[None, :, None]
        G = (J @ Tq).reshape(H + 1, d, H, n)
        CG = np.einsum("iabm,ibks->kiams", C, G, optimize=True).reshape(H, (H + 1) * d, d * n)
        S = np.swapaxes(G.transpose(2, 0, 1, 3).reshape(H, (H + 1) * d, n), 1, 2) @ CG  # (k, r, (m, s))
        S = S.reshape(H, n, d, n).transpose(0, 1, 3, 2).reshape(H, n * n, d)
        E = np.einsum("jlrs,kl->kjrs", self._noise_hessian, x.reshape(H, n)).reshape(H, n, n * n)
        cross += (E @ S).reshape(H * n, d)
        return GoalDerivatives(-phi_grad[:d].sum(axis=1), cross, Q[:, :d, :d].sum(axis=0))

    def _noise_rows(self, G: np.ndarray, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
        """The noise rows N_i = d vech Sigma_x,i / d tau through the noise injected at each step (A, B held), in
        factored form (rows (H+1, nv, c), scale): N_i = rows_i (c = H·n) when scale is None, otherwise
        N_i[:, (k, j)] = rows_i[:, k] scale[k, j] (c = H, scale (H, n)).

        G (H+1, d, H·n) = d mu_x,i / d tau, zero for k ≥ i. With E_kj = dN/dtau_j at tau_k, column (k, j) of N_i
        is vech(G_ik E_kj G_ikᵀ). For isotropic noise E_kj = 2 kappa tau_kj I, so the column is
        2 kappa tau_kj v_ik with v_ik = vech(G_ik G_ikᵀ): n times fewer columns.
        """
        a, b = self._triangle.T
        H, n = tau.shape
        G = G.reshape(H + 1, -1, H, n)
        if self.model.noise == "isotropic":
            v = np.empty((H + 1, len(a), H))
            for entry, (r, c) in enumerate(self._triangle):  # one einsum per entry: 3× faster than all at once
                np.einsum("ikj,ikj->ik", G[:, r], G[:, c], out=v[:, entry])
            return v, 2 * self.model.kappa * tau
        E = np.einsum("jlrs,kl->kjrs", self._noise_hessian, tau)
        N = np.einsum("iakr,kjrs,ibks->iabkj", G, E, G, optimize=True)[:, a, b]
        return N.reshape(H + 1, len(a), H * n), None

    @staticmethod
    def _noise_row_terms(rows: np.ndarray, scale: np.ndarray | None, Q_cc: np.ndarray, cross: np.ndarray) -> np.ndarray:
        """P (H·n, H·n) with P + Pᵀ = Σ_i N_iᵀ Q_cc,i N_i + N_iᵀ R_i + R_iᵀ N_i, the Hessian's terms in the noise
        rows N_i (:meth:`_noise_rows`' factored form: rows (H+1, nv, c), scale (H, n) or None).

        Q_cc (H+1, nv, nv) the reward's curvature in vech Sigma_x; cross (c, H·n) = Σ_i rows_iᵀ R_i, R_i =
        Q_cz,i X_i T_i the mean rows' cross terms. With scale, P = diag(scale) (cross + ½ s diag(scale)),
        s = Σ_i rows_iᵀ Q_cc,i rows_i (c, c).
        """
        c = rows.shape[2]
        gram = rows.reshape(-1, c).T @ (Q_cc @ rows).reshape(-1, c)
        if scale is None:
            return cross + 0.5 * gram
        H, n = scale.shape
        half = cross + 0.5 * (gram[:, :, None] * scale).reshape(H, H * n)
        return (scale[:, :, None] * half[:, None, :]).reshape(H * n, H * n)

    def trajectory(self, data: ArmTerms) -> StateBelief:
        """The belief along the evaluated torques: mean (H+1, 2n) and covariance (H+1, 2n, 2n)."""
        n2, H = 2 * self.model.n, self.model.H
        return StateBelief(data.mean.T.copy(), data.cov.reshape(n2, H + 1, n2).transpose(1, 0, 2).copy())


_PIECE_FIELDS = ["A", "B", "J", "phi_hess", "phi_grad", "kinematic_hessian", "dvech"]
"""The pieces function's outputs, in order, named as the fields of :class:`~comanip.planning.terms.ArmPieces`."""


def _per_step(stacked: np.ndarray, steps: int) -> np.ndarray:
    """A CasADi output stacked horizontally per step (rows, steps·cols) as blocks (steps, rows, cols) (a view)."""
    return stacked.reshape(stacked.shape[0], steps, -1).transpose(1, 0, 2)


def _costs_to_go(quadratic: np.ndarray, linear: np.ndarray, A: np.ndarray) -> None:
    """Quadratic and linear costs on the states summed backwards along the linearised dynamics, in place:
    S_i = M_i + A_iᵀ S_{i+1} A_i and P_i = L_i + A_iᵀ P_{i+1} for i = H-1, ..., 1 (S_H = M_H, P_H = L_H; S_0 and
    P_0 are left as they are).

    quadratic M (H+1, m, 2n, 2n) (m costs at once); linear L (H+1, 2n, c) (c costs); A (H, 2n, 2n).
    """
    for i in range(len(A) - 1, 0, -1):
        quadratic[i] += A[i].T @ quadratic[i + 1] @ A[i]
        linear[i] += A[i].T @ linear[i + 1]


def _condensed_upper(T: np.ndarray, SB: np.ndarray) -> np.ndarray:
    """U (H·n, H·n) with U + Uᵀ = Σ_i T_iᵀ M_i T_i, the Hessian of the state cost ½ Σ_i δmu_iᵀ M_i δmu_i along the
    linearised dynamics.

    T (H+1, 2n, H, n) the sensitivities; SB (H, 2n, n) = S_{l+1} B_l with S the cost-to-go of M
    (:func:`_costs_to_go`). U's block (k, l) is T_{l+1,k}ᵀ SB_l above the diagonal, half of it on the diagonal
    (B_kᵀ S_{k+1} B_k) and zero below (T_{l+1,k} = 0 for k > l).
    """
    H, n2, n = SB.shape
    T = T.reshape(H + 1, n2, H * n)
    upper = np.zeros((H * n, H * n))
    for l in range(H):
        np.matmul(T[l + 1, :, :(l + 1) * n].T, SB[l], out=upper[:(l + 1) * n, l * n:(l + 1) * n])
    diagonal = np.arange(H)
    upper.reshape(H, n, H, n)[diagonal, :, diagonal, :] *= 0.5
    return upper


def _stage_cost_function(model) -> ca.Function:
    """``(mu (2n,), Sigma (2n, 2n), goal, width, weight) -> -weight R(x_ee(mu_q), J Sigma_qq Jᵀ)``."""
    body, n, d = model.body, model.n, model.d
    mu, Sigma = ca.SX.sym("mu", 2 * n), ca.SX.sym("Sigma", 2 * n, 2 * n)
    goal, width, weight = ca.SX.sym("goal", d), ca.SX.sym("width"), ca.SX.sym("weight")
    q = mu[:n]
    J = body.jacobian(q)
    R = GoalReward.of(model).expected(body.end_effector(q), ca.mtimes([J, Sigma[:n, :n], J.T]), goal, width)
    return ca.Function("stage_cost", [mu, Sigma, goal, width, weight], [-weight * R])


def _stage_curvature_function(model, triangle: np.ndarray) -> ca.Function:
    """``(mu, Sigma, goal, width, weight) -> (J, ∇²phi, ∇phi, W, d vech Sigma_x / dq)`` at one step.

    phi's derivatives are w.r.t. z = (mu_x, vech Sigma_x); W = ∇²_q [λ·x_ee(q) + <Λ, J(q) Sigma_qq J(q)ᵀ>]
    with λ = ∇_mu_x phi and Λ = ∇_Sigma_x phi held at their values.
    """
    body, n, d = model.body, model.n, model.d
    mu, Sigma = ca.SX.sym("mu", 2 * n), ca.SX.sym("Sigma", 2 * n, 2 * n)
    goal, width, weight = ca.SX.sym("goal", d), ca.SX.sym("width"), ca.SX.sym("weight")
    q = mu[:n]
    J = body.jacobian(q)
    Sigma_x = ca.mtimes([J, Sigma[:n, :n], J.T])
    vech = ca.vertcat(*[Sigma_x[a, b] for a, b in triangle])
    phi_hess, phi_grad = _reward_derivatives_function(model)(body.end_effector(q), vech, goal, width, weight)
    lam, vech_weights = ca.SX.sym("lambda", d), ca.SX.sym("vech_weights", len(triangle))
    kinematic_value = ca.dot(lam, body.end_effector(q)) + ca.dot(vech_weights, vech)
    W = ca.Function("W", [mu, Sigma, lam, vech_weights], [ca.hessian(kinematic_value, mu)[0][:n, :n]])
    return ca.Function("stage_curvature", [mu, Sigma, goal, width, weight],
                       [J, phi_hess, phi_grad, W(mu, Sigma, phi_grad[:d], phi_grad[d:]), ca.jacobian(vech, mu)[:, :n]])
