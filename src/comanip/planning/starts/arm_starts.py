"""The start policy of an arm (:class:`ArmStarts`): from its ready pose, the nearest plans of its
:class:`~comanip.planning.starts.arm_reach_library.ArmReachLibrary` moved onto the goal; elsewhere its minimum-jerk
guesses, all of them or all but the one of highest objective.
"""

from __future__ import annotations

import numpy as np

from comanip.model import ReachingModel
from comanip.planning.reach_parameters import ReachParameters
from comanip.planning.reach_problem import ReachProblem
from comanip.planning.reach_solver import ReachSolver
from comanip.planning.solver_options import SolverOptions
from comanip.planning.starts.arm_reach_library import CANDIDATE_ENTRIES, WARM_CANDIDATE_ENTRIES, ArmReachLibrary, bundled_library
from comanip.planning.starts.initial_guess import brake_durations, braked_torques
from comanip.planning.starts.start_policy import StartPolicy


class ArmStarts(StartPolicy):
    """Where an arm's solves start (:class:`~comanip.planning.starts.start_policy.StartPolicy`, whose arguments it
    takes)."""

    def __init__(self, model: ReachingModel, options: SolverOptions, problem: ReachProblem, solver: ReachSolver):
        super().__init__(model, options, problem, solver)
        self.arm_library = self._arm_reach_library() if options.cold_search == "ranked" else None

    def _arm_reach_library(self) -> ArmReachLibrary | None:
        """The arm's reach library: ``options.arm_library`` (it must be this model's) or the shipped one."""
        if self.options.arm_library is None:
            return bundled_library(self.model)
        library = ArmReachLibrary.load(self.options.arm_library)
        if not library.is_for(self.model):
            raise ValueError(f"arm_library {self.options.arm_library!r} was solved for another model; a library applies "
                             f"to the model it was made for (comanip library --preset <this model's YAML>)")
        return library

    def from_arm_library(self, start) -> bool:
        """Whether a cold solve from ``start`` (nx,) starts from the arm reach library (its ready pose)."""
        return self.arm_library is not None and self.arm_library.serves(start)

    def joint_shift(self, mean: np.ndarray | None, goal_move: np.ndarray) -> np.ndarray:
        """The least-squares joint move (n,) under the Jacobian at the end of the mean path (H+1, nx)."""
        J = np.asarray(self.model.body.kinematics_function(mean[-1, : self.model.n])[1])
        return np.linalg.lstsq(J, goal_move, rcond=None)[0]

    def mean_path(self, torque: np.ndarray, params: ReachParameters) -> np.ndarray:
        """The mean path (H+1, nx) of torques (H, n), from the Newton terms' value-only rollout."""
        return self.curvature.mean_path(self.curvature.value_and_data(np.ravel(torque), params).data)

    def warm_candidates(self, params: ReachParameters) -> list[np.ndarray]:
        """From the library's ready pose, its plan nearest to the goal moved onto it: on 50 chained warm franka_rest
        solves to goals moved by up to 5 cm per axis it was the best start 48 times (15 → 10 Newton iterations, J
        within 3e-9)."""
        return self.library_candidates(params, WARM_CANDIDATE_ENTRIES) if self.from_arm_library(params.start) else []

    def cold_starts(self, params: ReachParameters, goal_q: np.ndarray | None = None) -> list[np.ndarray]:
        """At the ready pose of its reach library: :meth:`arm_library_starts`; elsewhere, or with 'all':
        :meth:`searched_guesses`."""
        if self.from_arm_library(params.start):
            return self.arm_library_starts(params, goal_q)
        return self.searched_guesses(params, goal_q)

    def arm_library_starts(self, params: ReachParameters, goal_q: np.ndarray | None = None) -> list[np.ndarray]:
        """An arm's cold starts from its ready pose (:mod:`comanip.planning.starts.arm_reach_library`): first the
        lowest-objective torques (H, n) among the minimum-jerk guesses and the plans of the nearest library
        entries, each as solved and moved onto the goal; then the minimum-jerk guesses, which the planner runs
        only if no start before them converged."""
        guesses = self.cold_guesses(params, self.options.n_starts, goal_q)
        candidates = guesses + self.library_candidates(params, CANDIDATE_ENTRIES)
        return [self.lowest_objective(candidates, params)] + guesses

    def library_candidates(self, params: ReachParameters, entries: int) -> list[np.ndarray]:
        """The plans (H, n) of the arm reach library's ``entries`` entries nearest to ``goal`` (d,), each as solved
        and moved onto the goal (:meth:`retargeted`); the start has the library's joint positions, and if it
        moves, each candidate gets the braking moves of :func:`braked_torques` instead."""
        library, model, candidates, goal = self.arm_library, self.model, [], params.goal
        velocity = params.start[model.n:2 * model.n]
        for entry_goal, torque in library.nearest(goal, entries):
            entry_params = ReachParameters(library.start, entry_goal, library.width)
            mean = self.mean_path(torque, entry_params)
            moved = self.retargeted(torque, mean, entry_goal, goal)
            if np.any(velocity):
                moved = [braked for candidate in moved for braked in
                         braked_torques(model.body, model.h, model.H, candidate, velocity, brake_durations(model.duration), mean)]
            candidates += moved
        return candidates

    def searched_guesses(self, params: ReachParameters, goal_q: np.ndarray | None = None) -> list[np.ndarray]:
        """The minimum-jerk guesses a cold solve without a reach library runs: all for 'all', from a moving start and
        for a goal within ``arm_narrow_ratio`` widths; otherwise all but the one of highest objective."""
        guesses = self.cold_guesses(params, self.options.n_starts, goal_q)
        if self.options.cold_search == "all" or len(guesses) == 1 or np.any(params.start[self.model.n:]) \
                or not self.narrow(params, self.options.arm_narrow_ratio):
            return guesses
        return sorted(guesses, key=lambda guess: self.objective(guess, params))[:-1]
