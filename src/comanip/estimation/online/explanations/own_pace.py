"""The reaching model at its own pace: the MAP goal of a reach that started at t = 0 as the model plans it.

    g_hat = argmin_g  ½ |L^-1 (y - mu(g))|² + ½ (g - g_bar)^T P0^-1 (g - g_bar)

where mu(g) stacks the plan's predicted mean [q; qdot] at the observation times (linearly interpolated
between grid steps), L is the factor of the observations' joint covariance under the plan's open-loop belief
(or that of a person who corrects deviations, ``OnlineOptions.correction_time``:
:mod:`comanip.estimation.online.corrected_deviation`) plus the observation noise R
(:mod:`comanip.estimation.online.observation_whitening`), and (g_bar, P0) the prior. Every observation so far enters,
averaged per grid step. The observations' covariance is that of the plan to a goal within
``OnlineOptions.covariance_tolerance`` of the distance of the estimate (its dependence on g is left out of the
objective, as in iteratively reweighted least squares: an exact observation of a plan then gives back its
goal). The minimum is found by Newton's method (:class:`~comanip.estimation.online.map_goal.MapNewton`), warm-started
from the previous estimate; the first starts from the best family member along the observed directions. The
goal's covariance is the Laplace approximation with a 1-D quadrature along the reach where the distance is
still poorly known (:meth:`~comanip.estimation.online.map_goal.MapProblem.distance_spread`). Axes someone else moves
(``OnlineOptions.led_axes``) count for less while they move.

Once an observation shows movement it explains the hand, and says how well: its misfit is the mean squared
whitened residual per observed number (before, it cannot tell: verdict UNDECIDED, and the next explanation is
asked). A Newton iteration that fails keeps its previous estimate with status FAILED: that is its account, and the
chain's veto of its infinite misfit rules it out where another explanation can answer. The estimator's default chain rules it out for the rest of the reach once that misfit exceeds
``OnlineOptions.mismatch_threshold`` or its reach at the person's pace contradicts its timing
(:mod:`comanip.estimation.online.explanations.vetoed`). Beyond the reach family's distances or a person's hand speeds
no other explanation does better, so there its account cannot be contested.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from comanip.belief.propagation import linearised_step_function
from comanip.estimation.online.corrected_deviation import corrected_covariance, corrected_powers, correction_factor
from comanip.estimation.online.explanations.base import Explained, HandTrace, Reach, Verdict, grid_position
from comanip.estimation.online.online_estimate import OnlineEstimate
from comanip.estimation.online.map_goal import MapNewton, MapProblem
from comanip.estimation.observation import observation_covariance
from comanip.estimation.online.observation_whitening import ObservationWhitening
from comanip.estimation.online.online_options import OnlineOptions
from comanip.model import ReachingModel
from comanip.optim import Status
from comanip.plausibility import MAX_HUMAN_HAND_SPEED_M_S

COVARIANCE_ROUNDS = 3
"""Whitenings rebuilt per update at most (each at the goal the previous round ended at)."""
GIVE_UP_FACTOR = 2.0
"""The default chain's model at its own pace misfits without a solve where its misfit at the goal the solve would
start from exceeds this many times the veto's threshold: a solve lowers the misfit from its starting goal by far
less (docs/results/real_people.md, the update stages), so the veto would rule it out after the solve all the same."""


class ModelAtOwnPace:
    """The reaching model at its own pace (module docstring).

    Args:
        model: the point-mass model of the reach family.
        options: the estimator's options.
        give_up_above: a misfit above which, at the goal its solve would start from, it does not solve and says it
            misfits (verdict MISFITS), as it does where that goal lies at the family's shortest distance behind the
            hand, while the hand stays within the reach family's distances and a person's hand speeds; None: it
            always solves and explains.
    """

    def __init__(self, model: ReachingModel, options: OnlineOptions, give_up_above: float | None = None):
        self.model, self.options, self.give_up_above = model, options, give_up_above
        n = model.n
        _, A, _ = linearised_step_function(model.body, model.h)(np.zeros(model.state_size), np.zeros(n))
        self._A = np.asarray(A)
        correction_time = options.correction_time
        self._rho = 1.0 if correction_time is None else correction_factor(correction_time, model.h)
        self._powers = corrected_powers(self._A, self._rho, model.H)
        self._R = observation_covariance(options.observation_std, n)
        # sigma_t of each step's increment (H, n): led axes stray more from the step that ends after led_from on
        self._deviation_times = np.full((model.H, n), options.deviation_time)
        led_steps = model.h * np.arange(1, model.H + 1) > options.led_from
        self._deviation_times[np.ix_(led_steps, list(options.led_axes))] = options.led_deviation_time

    def reset(self, reach: Reach) -> None:
        """Start a new reach."""
        H, n = self.model.H, self.model.n
        self.reach = reach
        self._counts = np.zeros(H + 1)
        self._fractions = np.zeros(H + 1)          # per step: summed fractions of a step of its observations
        self._sums = np.zeros((H + 1, 2 * n))
        self._weights = np.zeros((H + 1, H + 1))
        self._added = 0                             # observations of the trace averaged into the steps
        self._whitening: ObservationWhitening | None = None
        self._whitening_goal = np.zeros(self.model.d)
        self._whitened = 0                          # observations the whitening holds
        self._last: Explained | None = None         # the last estimate this explanation gave

    def explain(self, hand: HandTrace, latest: OnlineEstimate | None) -> Explained:
        self._add(hand)
        humanlike = self._humanlike(hand)
        self._last = estimate = self._estimate(hand, self.give_up_above if humanlike else None)
        return estimate if humanlike else replace(estimate, contestable=False)

    def _add(self, hand: HandTrace) -> None:
        """Average the observations not yet added into their grid steps."""
        model = self.model
        new = slice(self._added, hand.count)
        for time_s, position, velocity in zip(hand.t[new], hand.position[new], hand.velocity[new]):
            observation = np.concatenate([position, velocity])
            before, fraction = grid_position(time_s, model.h, model.H)
            self._counts[before] += 1
            self._sums[before] += observation
            self._fractions[before] += fraction
            self._weights[before, before] += 1.0 - fraction
            if fraction > 0:
                self._weights[before, before + 1] += fraction
        self._added = hand.count

    def _humanlike(self, hand: HandTrace) -> bool:
        """Whether the observed hand stays within the reach family's distances and a person's hand speeds."""
        offset = hand.position - self.reach.start_position
        velocity = hand.velocity
        return bool(np.sqrt((offset * offset).sum(axis=1)).max() <= self.reach.family.distances[-1]
                    and np.sqrt((velocity * velocity).sum(axis=1)).max() <= MAX_HUMAN_HAND_SPEED_M_S)

    def _estimate(self, hand: HandTrace, give_up_above: float | None) -> Explained:
        """The MAP estimate (module docstring) with its misfit (mean squared whitened residual per observed
        number; None when nothing was fitted or the timing is the model's); given ``give_up_above``, the starting
        goal unsolved with verdict MISFITS where the misfit there exceeds it or the goal lies behind the hand
        (:meth:`_behind_the_hand`)."""
        reach, options = self.reach, self.options
        steps = np.flatnonzero(self._counts)
        counts = self._counts[steps]
        problem = MapProblem(reach.family, lambda goal: reach.prediction(goal, order=2, covariance=False),
                             reach.start_position, reach.prior_mean, reach.prior_precision, steps,
                             self._sums[steps] / counts[:, None], self._weights[steps] / counts[:, None])
        previous = self._last
        try:
            if previous is None or previous.verdict is Verdict.UNDECIDED or previous.status == Status.FAILED:
                goal = problem.cold_goal(hand.last_observation, options.observation_std, self._R[None] / counts[:, None, None])
                if goal is None:
                    return Explained.not_explaining(reach, Verdict.UNDECIDED, "no observation shows movement yet")
            else:
                goal = previous.goal
            if give_up_above is not None and self._behind_the_hand(goal, hand):
                return Explained.not_explaining(reach, Verdict.MISFITS, "the model at its own pace misfits the hand (its "
                                                "best reach is shorter than the family's shortest, the hand beyond it)",
                                                goal=goal, misfit=math.inf)
            iterations = 0
            for round_ in range(COVARIANCE_ROUNDS):
                whitening = self._whitening_at(goal, hand.count)
                if round_ == 0 and give_up_above is not None and (start := problem.misfit(whitening, goal)) > give_up_above:
                    return Explained.not_explaining(reach, Verdict.MISFITS, f"the model at its own pace misfits the hand "
                                                    f"(misfit {start:.3g} per observed number before its solve)",
                                                    goal=goal, misfit=start)
                solved = MapNewton(problem, whitening, options.tolerance, options.step_fraction,
                                   reach.family.width).solve(goal, options.max_iterations)
                goal, covariance = solved.x, solved.local_model.covariance()
                iterations += solved.nit
                if not self._stale(goal, hand.count):
                    break
            covariance = options.covariance_scale * problem.distance_spread(goal, covariance, whitening)
            if not (np.all(np.isfinite(goal)) and np.all(np.isfinite(covariance))):
                raise np.linalg.LinAlgError("non-finite estimate")
            misfit = problem.misfit(whitening, goal) if options.timing != "model" else None
        except np.linalg.LinAlgError as error:
            self._whitening = None
            goal, covariance = (reach.prior_mean, reach.prior_cov) if previous is None else (previous.goal, previous.covariance)
            return Explained.explaining(goal, covariance, Status.FAILED, f"the Newton iteration failed ({error}); "
                                        "the previous estimate is kept", misfit=math.inf)
        return Explained.explaining(goal, 0.5 * (covariance + covariance.T), solved.status, solved.message,
                                    iterations=iterations, misfit=misfit)

    def _behind_the_hand(self, goal: np.ndarray, hand: HandTrace) -> bool:
        """Whether ``goal`` sits at the reach family's smallest distance with the hand farther from the start than it:
        the observations' best reach at the model's pace is shorter than any the family plans, yet the hand has gone
        past it (a hand that set off later than the model's reach from t = 0 would)."""
        start, shortest = self.reach.start_position, self.reach.family.distances[0]
        offset = hand.position[-1] - start
        return bool(np.linalg.norm(goal - start) <= shortest * (1 + 1e-6) and math.sqrt(float(offset @ offset)) > shortest)

    def _stale(self, goal: np.ndarray, observations: int) -> bool:
        """True when the whitening was made for a goal farther from ``goal`` than the covariance tolerance, or
        misses more than the newest observation."""
        if self._whitening is None or self._whitened < observations - 1:
            return True
        distance = np.linalg.norm(goal - self.reach.start_position)
        tolerance = self.options.covariance_tolerance * max(distance, self.reach.family.width)
        return bool(np.linalg.norm(goal - self._whitening_goal) > tolerance)

    def _whitening_at(self, goal: np.ndarray, observations: int) -> ObservationWhitening:
        """The whitening of the observations so far under the belief of the plan to a goal near ``goal``: the
        current one extended by the new observation, or rebuilt at ``goal`` when it is stale."""
        model = self.model
        steps = np.flatnonzero(self._counts)
        whitening = self._whitening
        if self._stale(goal, observations):
            prediction = self.reach.prediction(goal, order=0)
            cov = prediction.cov
            if self._rho < 1.0:
                cov = corrected_covariance(cov, self._A, self._rho, prediction.mean, self._deviation_times, model.h, model.n)
            whitening = ObservationWhitening(cov, self._powers, 2 * model.n, steps,
                                             np.array([self._step_noise(i, cov) for i in steps]),
                                             self._fractions[steps] / self._counts[steps])
            self._whitening, self._whitening_goal = whitening, np.array(goal, dtype=float)
        else:
            last = steps[-1]
            noise, fraction = self._step_noise(last, whitening.cov), self._fractions[last] / self._counts[last]
            if len(whitening.steps) == len(steps):
                whitening.redo_last(noise, fraction)
            else:
                whitening.append(last, noise, fraction)
        self._whitened = observations
        return whitening

    def _step_noise(self, i: int, cov: np.ndarray) -> np.ndarray:
        """Noise covariance (2n, 2n) of the averaged observation of step i: R / m_i + f̄² Q_i, f̄ the mean
        fraction of a step its observations come after t_i, Q_i = Sigma_{i+1} - A Sigma_i A^T the motor noise
        of step i (:mod:`comanip.estimation.online.observation_whitening`)."""
        m, count = 2 * self.model.n, self._counts[i]
        mean_fraction = self._fractions[i] / count
        noise = self._R / count
        if mean_fraction > 0 and i < self.model.H:
            A = self._powers[1]
            noise = noise + mean_fraction**2 * (cov[i + 1] - A @ cov[i] @ A.T)[:m, :m]
        return noise

