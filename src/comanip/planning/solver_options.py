"""How the planner solves its problem (:class:`SolverOptions`): the method, its limits and tolerances, and how a
cold solve chooses its starts. The planner, its strategies and its start policy all read them, so they live apart
from each of them."""

from __future__ import annotations

from dataclasses import dataclass, field

from comanip.arguments import as_count, as_positive

SOLVER_METHODS = ("newton", "ipopt")
COLD_SEARCHES = ("ranked", "all")


@dataclass(frozen=True)
class SolverOptions:
    """How the planner's NLP is solved."""

    method: str = "newton"
    """'newton' (damped Newton on the structure-exploiting Hessian, fast) or 'ipopt' (IPOPT with CasADi's
    exact Hessian, the reference)."""
    max_iterations: int | None = None
    """Iteration limit per start (Newton: Hessian evaluations; IPOPT: its iterations). None:
    ``point_mass_iterations`` for point masses, ``arm_iterations`` for nonlinear bodies."""
    point_mass_iterations: int = 200
    """The iteration limit for point masses when ``max_iterations`` is None (exact Hessian: Newton converges
    quadratically)."""
    arm_iterations: int = 1000
    """The iteration limit for nonlinear bodies when ``max_iterations`` is None (approximate Hessian: linear
    convergence)."""
    tolerance: float = 1e-8
    """Convergence tolerance on the gradient of the normalised objective (J divided by the goal's peak reward
    times the sum of discount weights, so it lies in about [-1, 0]); IPOPT's ``tol``. For nonlinear bodies
    ``arm_tolerance`` applies instead, unless it is None."""
    arm_tolerance: float | None = 1e-6
    """The convergence tolerance for nonlinear bodies (None: ``tolerance``). Their approximate Hessian converges
    linearly, and the iterations from 1e-6 to 1e-8 only polish the gradient; a looser tolerance stops the paper's
    ``franka`` plans early on their flat valley (studies/which_newton_options_suit_the_arm/)."""
    hessian_refresh: int = 3
    """Nonlinear bodies: the approximate Hessian is assembled every this many Newton iterations, and after any step
    the line search shortened or taken with a limit in the working set; in between it is kept with its secant
    corrections updated (:func:`comanip.optim.active_set_newton.newton_minimize`). 1: every iteration. Point masses (exact
    Hessian) assemble theirs as before whatever this says (the trade: studies/which_newton_options_suit_the_arm/)."""
    n_starts: int = 3
    """Minimum-jerk initial guesses of a cold solve (durations spread over the horizon). A warm-started
    solve uses the warm start only."""
    cold_search: str = "ranked"
    """How a cold solve starts. 'all': from each of the ``n_starts`` minimum-jerk guesses, keeping the best
    converged plan. 'ranked': from the lowest-objective start among those guesses and, for a point mass, a solved
    reach turned to the goal (past ``narrow_ratio`` widths: the library's plans near each local optimum), for an arm
    at its ready pose, the nearest plans of its reach library
    (:meth:`StartPolicy.cold_starts <comanip.planning.starts.StartPolicy.cold_starts>`), about as fast as a warm
    solve, with every guess solved where a moving hand's local optima compete (point masses) or the guesses as
    fallbacks (arms). An arm
    without a library, or away from its ready pose, runs every guess as 'all' does, except from rest the one of
    highest objective for a goal beyond ``arm_narrow_ratio`` widths. benchmarks/cold_quality.py
    compares 'ranked' with 'all' under the cold-search rule (docs/results/speed.md)."""
    narrow_ratio: float = 20.0
    """Reach distance over goal width beyond which local optima compete in a point mass's 'ranked' cold solve: it
    starts from the reach library's plans near each of them (:meth:`ReachLibrary.local_optima
    <comanip.planning.starts.reach_library.ReachLibrary.local_optima>`) instead of the nearest solved reach, or,
    from a start whose motion carries the hand on, solves from every minimum-jerk guess. The distance counts from
    the start and from where a stop of its motion ends. Far, narrow goals of the planar preset have several local
    optima (the lowest-objective minimum-jerk start ended 0.7 % worse on 1 of 200 random problems, at 54 widths;
    none below 20 widths on any point-mass preset)."""
    arm_narrow_ratio: float = 4.0
    """Reach distance over goal width beyond which an arm's 'ranked' cold search from rest without a reach library
    leaves out its minimum-jerk guess of highest objective: there that start seldom ends best and is the slowest to
    converge (it lies near the zero-reward plateau). Nearer or wider goals, and moving starts, run every guess
    (studies/may_an_arm_cold_search_leave_out_its_worst_guess/)."""
    far_warm_start: float = 3.0
    """Goal widths: a warm start (a plan to another goal) whose final hand position is farther than this
    from the new goal lies where the goal's reward underflows, so ``n_starts`` fresh reaches compete with it. For
    a plan that carries its goal sensitivity the position is where the predicted start ends."""
    arm_library: str | None = None
    """An arm's reach library for 'ranked' cold solves from its ready pose, at rest or moving (its nearest plan
    also competes with a warm start there): a file written by ``comanip library`` (.npz) for this model. None:
    the library shipped for the model (``franka_rest``), if any (:mod:`comanip.planning.starts.arm_reach_library`)."""
    abandon_after: int = 80
    """Newton iterations after which a 'ranked' cold search that runs every start (an arm without a reach library, a
    point mass's narrow goal) abandons a start that has not converged, when a start that has converged within the
    limits by then has a lower objective than it has there: on the Panda long starts crawl along a joint limit and
    seldom end best (studies/may_an_arm_cold_search_abandon_long_starts/); 'all' runs every start to the end."""
    threads: int | None = None
    """Threads that solve a nonlinear body's cold starts side by side when every start is solved (an arm without a
    reach library, or ``cold_search="all"``): a Newton iteration on an arm spends most of its time in
    compiled code and LAPACK, which run outside Python's interpreter lock (:mod:`comanip.planning.start_threads`).
    None: one thread per start, at most one per processor the process may use; 1: one start after another (e.g.
    for sweeps that already run a process per core). The plan is the same whatever this says: each start is solved
    alone and the best is kept by the same rule."""
    ipopt: dict = field(default_factory=dict)
    """Extra IPOPT options, passed through (e.g. {"hessian_approximation": "limited-memory"})."""
    compile: bool | None = None
    """Compile the Newton method's per-solve function to C (cached on disk, see comanip.caching.compiled).
    True: when the planner is built. False: never. None: when built for nonlinear bodies, where CasADi's
    virtual machine is ten times slower (a first build takes a minute or two for the Panda); for a point mass,
    in a background thread once the planner has spent ``compile_after`` seconds solving, its solves going on
    uncompiled meanwhile: compiling costs 3–17 s for every new model, which short-lived planners (a fit's,
    one per parameter set) would not win back, while a long-lived one (a control loop, a sweep) solves
    faster afterwards (docs/results/speed.md). A model compiled before (by any planner, in any
    process, with this version of the package) is loaded compiled from the disk cache when built."""
    compile_after: float = 2.0
    """Seconds of solving (the sum of ``plan.solve_time``) after which a point-mass planner with ``compile=None``
    compiles its per-solve function in the background."""

    def __post_init__(self):
        if self.method not in SOLVER_METHODS:
            raise ValueError(f"method must be one of {SOLVER_METHODS}, got {self.method!r}")
        as_count("max_iterations", self.max_iterations, optional=True)
        as_count("threads", self.threads, optional=True)
        for name in ("n_starts", "point_mass_iterations", "arm_iterations", "hessian_refresh", "abandon_after"):
            as_count(name, getattr(self, name))
        as_positive("far_warm_start", self.far_warm_start, "goal widths")
        as_positive("narrow_ratio", self.narrow_ratio, "reach distance over goal width")
        as_positive("arm_narrow_ratio", self.arm_narrow_ratio, "reach distance over goal width")
        as_positive("compile_after", self.compile_after, "s of solving")
        if self.cold_search not in COLD_SEARCHES:
            raise ValueError(f"cold_search must be one of {COLD_SEARCHES}, got {self.cold_search!r}")
        as_positive("tolerance", self.tolerance, "gradient of the normalised objective")
        if self.arm_tolerance is not None:
            as_positive("arm_tolerance", self.arm_tolerance, "gradient of the normalised objective")
        if self.compile not in (None, True, False):
            raise ValueError(f"compile must be None, True or False, got {self.compile!r}")
