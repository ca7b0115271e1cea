"""CasADi's structure-exploiting solvers on the Franka reach, multiple shooting over the belief state .

    nice .venv/bin/python -m studies.are_structured_solvers_faster_on_the_arm_reach.compare_structured_solvers [--repeats 10] [--only fatrop,sqp_hpipm,ipopt]

Notation (docs/formulation.md §2–4): stage state y_k = (mu_k (2n,), vech Sigma_k (n2(n2+1)/2,)), n2 = 2n, control tau_k (n,),
k = 0..H. The OCP, in the planner's normalised units (J / |J_best(w)|, same minimiser):

    min  Σ_{k=0..H} -(w_k / |J_best|) R(mu_k, Sigma_k) + (nu / |J_best|) Σ_{k<H} ||tau_k||²
    s.t. y_0 = (s_0, 0);  y_{k+1} = belief_step(y_k, tau_k);  |tau_k| <= tau_max;
         q_min <= mu_q,k <= q_max, |mu_qdot,k| <= qdot_max (k >= 1).

Variables are ordered [y_0 tau_0 y_1 tau_1 ... y_H] and constraints [gap_0 lincon_0 gap_1 ...], the layout
fatrop's and HPIPM's structure detection expect. Each solver's NLP is built once (build time reported
apart); then one untimed warm-up solve from the package planner's plan to the base goal, then `repeats`
timed solves to goals within ±5 cm of home EE + [0.15, 0.1, -0.1] m (the franka case of solve_times.py),
each warm-started from that solver's previous primal and dual solution. The package planner solves the
same goal sequence (warm from its previous plan) for the objective comparison; J is recomputed for every
solver by single shooting of its torques (so multiple-shooting defects cannot flatter it).
Results are printed and written to studies/are_structured_solvers_faster_on_the_arm_reach/structured_solvers.json.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import casadi as ca
import numpy as np
from tqdm import tqdm

import comanip
from comanip.belief.propagation import belief_step_function
from comanip.planning.linearised_curvature import _stage_cost_function
from comanip.planning.reach_problem import ReachProblem

REACH = np.array([0.15, 0.1, -0.1])
"""Base goal offset (m) from the home end-effector position, as solve_times.py's franka case."""


class BeliefOCP:
    """The multiple-shooting NLP ``{x, p, f, g}`` with bounds, p = (s0 (2n,), goal (d,)), width = model.width.

    gap_sign: +1 writes gap_k = y_{k+1} - F(y_k, tau_k) (fatrop's structure detection insists on it), -1 writes
    F(y_k, tau_k) - y_{k+1} (HPIPM's documented layout A_k x_k + B_k u_k - x_{k+1}).
    """

    def __init__(self, model, gap_sign: int = 1):
        self.model, body = model, model.body
        n, n2, H = model.n, 2 * model.n, model.H
        self.n, self.n2, self.H = n, n2, H
        self.lower = np.array([(a, b) for b in range(n2) for a in range(b, n2)])  # vech: lower triangle by columns
        self.ny = n2 + len(self.lower)
        problem = ReachProblem(model)
        self.problem = problem
        scale = float(ca.Function("normaliser", [problem.width], [-problem.best_objective])(model.width))  # |J_best(w)|
        step = belief_step_function(body, model.h, model.kappa, model.noise)
        cost = _stage_cost_function(model)

        y, tau = ca.SX.sym("y", self.ny), ca.SX.sym("tau", n)
        goal, weight = ca.SX.sym("goal", model.d), ca.SX.sym("weight")
        mu, Sigma = y[:n2], self.unvech(y[n2:])
        mu_next, Sigma_next = step(mu, Sigma, tau)
        F = ca.Function("F", [y, tau], [ca.vertcat(mu_next, self.vech(Sigma_next))])
        L = ca.Function("L", [y, goal, weight], [cost(mu, Sigma, goal, model.width, weight)])

        Y = [ca.MX.sym(f"y{k}", self.ny) for k in range(H + 1)]
        U = [ca.MX.sym(f"tau{k}", n) for k in range(H)]
        s0, g = ca.MX.sym("s0", n2), ca.MX.sym("goal", model.d)
        x, lbx, ubx, G, lbg = [], [], [], [], []
        state_lo = np.concatenate([body.q_min, -body.qdot_max, np.full(len(self.lower), -np.inf)])
        state_hi = np.concatenate([body.q_max, body.qdot_max, np.full(len(self.lower), np.inf)])
        f = 0
        for k in range(H + 1):
            x.append(Y[k])
            lbx.append(np.full(self.ny, -np.inf) if k == 0 else state_lo)
            ubx.append(np.full(self.ny, np.inf) if k == 0 else state_hi)
            f += L(Y[k], g, problem.weights[k] / scale)
            if k == H:
                break
            x.append(U[k])
            lbx.append(-body.tau_max)
            ubx.append(body.tau_max)
            f += model.nu / scale * ca.sumsqr(U[k])
            G.append(gap_sign * (Y[k + 1] - F(Y[k], U[k])))  # gap_k
            lbg.append(np.zeros(self.ny))
            if k == 0:  # lincon_0: the initial belief
                G.append(Y[0] - ca.vertcat(s0, ca.DM.zeros(self.ny - n2)))
                lbg.append(np.zeros(self.ny))
        self.nlp = {"x": ca.vertcat(*x), "p": ca.vertcat(s0, g), "f": f, "g": ca.vertcat(*G)}
        self.lbx, self.ubx = np.concatenate(lbx), np.concatenate(ubx)
        self.lbg = self.ubg = np.concatenate(lbg)
        self.stride = self.ny + n  # one (y_k, tau_k) block

    def vech(self, S):
        return ca.vertcat(*[S[a, b] for a, b in self.lower])

    def unvech(self, v):
        S = ca.SX.zeros(self.n2, self.n2)
        for i, (a, b) in enumerate(self.lower):
            S[a, b] = v[i]
            S[b, a] = v[i]
        return S

    def pack(self, mean: np.ndarray, cov: np.ndarray, torque: np.ndarray) -> np.ndarray:
        """Decision vector from a belief trajectory mean (H+1, 2n), cov (H+1, 2n, 2n) and torques (H, n)."""
        blocks = []
        for k in range(self.H + 1):
            blocks.append(np.concatenate([mean[k], cov[k][self.lower[:, 0], self.lower[:, 1]]]))
            if k < self.H:
                blocks.append(torque[k])
        return np.concatenate(blocks)

    def torques(self, x: np.ndarray) -> np.ndarray:
        """Torques (H, n) from a decision vector."""
        return np.array([x[k * self.stride + self.ny:(k + 1) * self.stride] for k in range(self.H)])

    def covariances(self, x: np.ndarray) -> np.ndarray:
        """Sigma_k (H+1, 2n, 2n) from a decision vector (the iterate's, not the rollout's)."""
        out = np.zeros((self.H + 1, self.n2, self.n2))
        for k in range(self.H + 1):
            v = x[k * self.stride + self.n2:k * self.stride + self.ny]
            out[k][self.lower[:, 0], self.lower[:, 1]] = v
            out[k][self.lower[:, 1], self.lower[:, 0]] = v
        return out


SOLVERS = {
    "fatrop": ("fatrop", {"structure_detection": "auto", "expand": True, "print_time": False,
                          "fatrop": {"print_level": 0, "max_iter": 500, "mu_init": 1e-4}}),
    "sqp_hpipm": ("sqpmethod", {"qpsol": "hpipm", "expand": True, "convexify_strategy": "regularize",
                                "print_time": False, "print_header": False, "print_iteration": False,
                                "max_iter": 50, "qpsol_options": {"error_on_fail": False}}),
    "ipopt": ("ipopt", {"expand": True, "print_time": False,
                        "ipopt": {"print_level": 0, "max_iter": 500, "warm_start_init_point": "yes",
                                  "warm_start_bound_push": 1e-6, "warm_start_mult_bound_push": 1e-6,
                                  "mu_init": 1e-4}}),
}
"""name -> (nlpsol plugin, options): exact Hessian of the Lagrangian in every case.

fatrop in this wheel has no warm-start or quasi-Newton option (its options: tolerances, barrier and filter
parameters, linear-solver switches); it takes the primal initial guess and, warm, a small initial barrier
parameter. sqpmethod + HPIPM needs a convex QP, and the exact Hessian is indefinite (without convexification
the iterates reach an indefinite Sigma and NaN, SPEC §9); of its convexifications, 'eigen-clip' and
'eigen-reflect' end every solve at iteration 0 with a zero step here, 'regularize' runs; its quasi-Newton
('limited-memory') Hessian is dense, which HPIPM's interface rejects at build."""


def run_solver(name: str, ocp: BeliefOCP, start, goals, first_plan, repeats: int) -> dict:
    plugin, options = SOLVERS[name]
    if plugin == "fatrop":  # its structure detection asks which rows of g are equalities (all are, here)
        options = {**options, "equality": [True] * len(ocp.lbg)}
    t0 = time.perf_counter()
    solver = ca.nlpsol(name, plugin, ocp.nlp, options)
    build = time.perf_counter() - t0
    x0 = ocp.pack(first_plan.mean, first_plan.cov, first_plan.torque)
    lam_g = np.zeros(len(ocp.lbg))
    lam_x = np.zeros(len(ocp.lbx))
    rows = []
    for k, goal in enumerate(tqdm(goals[:repeats + 1], desc=name)):
        t = time.perf_counter()
        try:
            sol = solver(x0=x0, lam_x0=lam_x, lam_g0=lam_g, p=np.concatenate([start, goal]), lbx=ocp.lbx,
                         ubx=ocp.ubx, lbg=ocp.lbg, ubg=ocp.ubg)
            error = ""
        except RuntimeError as exc:  # a solver that raises (e.g. structure detection) is a finding, not a crash
            rows.append({"goal": k, "seconds": time.perf_counter() - t, "success": False, "error": str(exc)[:300]})
            break
        seconds = time.perf_counter() - t
        try:
            stats = solver.stats()
        except RuntimeError as exc:  # casadi 3.8.2's sqpmethod fails to report a status after a zero step
            stats, error = {"success": False, "return_status": "stats unavailable", "iter_count": -1}, str(exc)[-80:]
        x = np.asarray(sol["x"]).ravel()
        torque = ocp.torques(x)
        J = ocp.problem.objective_value(torque, start, goal, ocp.model.width)
        cov = ocp.covariances(x)
        min_eig = float(min(np.linalg.eigvalsh(c).min() for c in cov))
        rows.append({"goal": k, "seconds": seconds, "success": bool(stats["success"]),
                     "status": str(stats["return_status"]), "iterations": int(stats.get("iter_count", -1)),
                     "evaluation_s": sum(v for key, v in stats.items() if key.startswith("t_wall_nlp_")),
                     "hessian_evaluations": int(stats.get("n_call_nlp_hess_l", 0)),
                     "stats_hess_s": float(stats.get("t_wall_nlp_hess_l", 0.0)),
                     "J": J, "defect": float(np.abs(np.asarray(sol["g"])).max()), "min_eig_sigma": min_eig,
                     "error": error})
        if np.all(np.isfinite(x)):
            x0, lam_x, lam_g = x, np.asarray(sol["lam_x"]).ravel(), np.asarray(sol["lam_g"]).ravel()
    return {"build_s": build, "rows": rows}


def run_planner(model, start, goals, repeats: int):
    planner = comanip.Planner(model)
    first = planner.solve(start, goals[0], model.width)
    rows, previous = [], first
    for goal in tqdm(goals[1:repeats + 1], desc="planner"):
        plan = planner.solve(start, goal, model.width, warm_start=previous)
        rows.append({"seconds": plan.solve_time, "success": plan.success, "iterations": plan.iterations,
                     "J": plan.objective})
        previous = plan
    return first, rows


def summary(rows: list[dict], planner_rows: list[dict] | None) -> dict:
    timed = rows[1:]  # the first solve, from the planner's plan, is a warm-up
    if not timed:
        return {"ok": 0, "n": 0}
    ms = np.array([r["seconds"] for r in timed]) * 1e3
    out = {"median_ms": float(np.median(ms)), "p90_ms": float(np.percentile(ms, 90)),
           "ok": sum(r["success"] for r in timed), "n": len(timed),
           "iterations": [r.get("iterations") for r in timed]}
    if planner_rows is not None and "J" in timed[0]:
        rel = [(r["J"] - p["J"]) / abs(p["J"]) for r, p in zip(timed, planner_rows)]
        out["rel_J_vs_planner"] = [float(v) for v in rel]
        out["min_eig_sigma"] = float(min(r["min_eig_sigma"] for r in timed))
        out["max_defect"] = float(max(r["defect"] for r in timed))
        # what the solver itself spends (linear algebra, line search), apart from CasADi's function evaluations
        out["median_own_ms"] = float(np.median([1e3 * (r["seconds"] - r["evaluation_s"]) for r in timed]))
        out["median_hessian_ms"] = float(np.median([1e3 * r["stats_hess_s"] / max(r["hessian_evaluations"], 1)
                                                    for r in timed]))
    return out


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=10)
    parser.add_argument("--only", default=",".join(SOLVERS))
    parser.add_argument("--out", default=str(Path(__file__).resolve().parent / "structured_solvers.json"))
    args = parser.parse_args(argv)
    print("casadi", ca.__version__, {s: ca.has_nlpsol(s) for s in ("fatrop", "ipopt", "sqpmethod")},
          {s: ca.has_conic(s) for s in ("hpipm", "fatrop")}, flush=True)

    model = comanip.presets.load("franka")
    home = model.body.home_position
    start = np.concatenate([home, np.zeros(model.n)])
    base = np.asarray(model.body.kinematics_function(home)[0]).ravel() + REACH
    rng = np.random.default_rng(0)
    goals = [base] + [base + rng.uniform(-0.05, 0.05, model.d) for _ in range(args.repeats)]

    first, planner_rows = run_planner(model, start, goals, args.repeats)
    ms = np.array([r["seconds"] for r in planner_rows]) * 1e3
    results = {"planner": {"median_ms": float(np.median(ms)), "p90_ms": float(np.percentile(ms, 90)),
                           "ok": sum(r["success"] for r in planner_rows), "n": len(planner_rows),
                           "iterations": [r["iterations"] for r in planner_rows], "rows": planner_rows}}
    print("planner", {k: v for k, v in results["planner"].items() if k != "rows"}, flush=True)

    for name in [s for s in args.only.split(",") if s]:
        t0 = time.perf_counter()
        ocp = BeliefOCP(model, gap_sign=-1 if SOLVERS[name][1].get("qpsol") == "hpipm" else 1)
        print(f"OCP expressions: {time.perf_counter() - t0:.1f} s, {ocp.nlp['x'].numel()} variables, "
              f"{ocp.nlp['g'].numel()} constraints", flush=True)
        result = run_solver(name, ocp, start, goals, first, args.repeats)
        result["summary"] = summary(result["rows"], planner_rows)
        results[name] = result
        print(name, f"build {result['build_s']:.1f} s", result["summary"],
              [r.get("status", r.get("error")) for r in result["rows"]], flush=True)
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
