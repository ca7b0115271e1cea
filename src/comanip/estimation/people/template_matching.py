"""Kinematic template matching (Pasqual & Wobbrock 2014): a movement's endpoint from recorded movements
whose speed profile began like it.

Templates are recorded movements' speed profiles from their onset (m/s on a grid of step h s) and the
distances they covered. A movement observed for tau seconds since its onset is compared with every template
over the same tau seconds (a template that ended earlier is at rest, speed 0, after its end) by the mean
squared difference of the speeds; the ``neighbours`` closest templates give the distance the hand still
covers after tau, averaged, and the endpoint lies that far beyond the hand along the direction from the start
to the hand.
"""

from __future__ import annotations

import numpy as np

from comanip.arguments import as_count, as_positive
from comanip.estimation.people.endpoint_baselines import MOVING_SPEED, EndpointPrediction, PrefixPredictor
from comanip.estimation.model_reaches.profile_fit import detected_onset


class TemplateLibrary:
    """Speed profiles and distances of recorded movements (:class:`comanip.recordings.Recording`).

    Args:
        recordings: the template movements.
        step: grid step of the profiles (s).
    """

    def __init__(self, recordings, step: float = 0.01):
        self.step = as_positive("step", step, "s")
        if not recordings:
            raise ValueError("a template library needs at least one recording")
        profiles = []
        for recording in recordings:
            grid = np.arange(recording.onset, recording.end_time + 1e-9, self.step)
            speed = np.interp(grid, recording.t, np.linalg.norm(recording.velocity, axis=1))
            along = np.interp(grid, recording.t, np.linalg.norm(recording.position - recording.start, axis=1))
            profiles.append((speed, along))
        length = max(len(speed) for speed, _ in profiles)
        self.speed = np.zeros((len(profiles), length))
        """Speeds (N, L), m/s, from each template's onset; 0 after its end."""
        self.covered = np.zeros((len(profiles), length))
        """Distance from the start (N, L), m; the final distance after the end."""
        for k, (speed, along) in enumerate(profiles):
            self.speed[k, :len(speed)] = speed
            self.covered[k, :len(along)] = along
            self.covered[k, len(along):] = along[-1]
        self.names = [recording.name for recording in recordings]

    def remaining(self, speed: np.ndarray, neighbours: int, exclude: str | None = None) -> float:
        """Mean distance (m) the ``neighbours`` best-matching templates still cover after len(speed) steps,
        for speeds (S,) m/s on the library's grid from the onset; ``exclude``: a template name to leave out."""
        S = min(len(speed), self.speed.shape[1])
        error = np.mean((self.speed[:, :S] - speed[:S]) ** 2, axis=1)
        if exclude is not None and exclude in self.names:
            error[self.names.index(exclude)] = np.inf
        best = np.argsort(error)[:neighbours]
        return float(np.mean(self.covered[best, -1] - self.covered[best, S - 1]))


class TemplateMatching(PrefixPredictor):
    """Kinematic template matching (module docstring).

    Args:
        start: rest position (d,), m.
        library: the templates.
        neighbours: how many best-matching templates are averaged.
        exclude: a template to leave out (the movement itself, when it is in the library).
    """

    name = "template matching"

    def __init__(self, start, library: TemplateLibrary, neighbours: int = 5, exclude: str | None = None):
        super().__init__(start)
        self.library = library
        self.neighbours = as_count("neighbours", neighbours)
        self.exclude = exclude

    def predict(self, t, position, velocity):
        speed = np.linalg.norm(velocity, axis=1)
        onset = detected_onset(t, speed, MOVING_SPEED)
        offset = position[-1] - self.start
        distance = float(np.linalg.norm(offset))
        if onset is None or distance == 0:
            return EndpointPrediction(position[-1].copy())
        grid = np.arange(onset, t[-1] + 1e-9, self.library.step)
        remaining = self.library.remaining(np.interp(grid, t, speed), self.neighbours, self.exclude)
        return EndpointPrediction(position[-1] + max(remaining, 0.0) * offset / distance)
