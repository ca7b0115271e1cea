"""Tutorial: predict where real people are reaching, from the first part of their movement.

The `cursory` data (the `data` extra) are mouse movements recorded from people, each with the target they
aimed at. This script reads some of them as recordings, feeds each to comanip's online goal estimator sample by
sample as the movement happens, and compares the predicted goal with the target, against the simplest guess
(the goal is where the hand is now). It ends in a figure of the errors over the movement.

    pip install -e ".[data]"
    python examples/predict_recorded_reaches.py     # writes out/examples/predict_recorded_reaches.png

Read it top to bottom; the same text is the "Tutorial: recorded reaches" page of the documentation.
"""

# ## 1. Recorded reaches
# `load_cursory` reads the movements as `Recording`s: positions in m (pixels times a scale that makes the median
# movement an arm's 0.33 m), resampled every 10 ms, velocities smoothed from the positions, with the movement's
# onset and end found from its speed. The held-out split is kept for reporting; a tutorial may look at it.
from comanip.extras import exit_without

exit_without("data")  # without the 'data' extra: one line saying how to install it, no traceback

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import comanip  # noqa: E402
from comanip.recordings import load_cursory  # noqa: E402
from _common import SMALL, figure_path  # noqa: E402

recordings = [r for r in load_cursory("held_out", limit=40) if 0.15 <= r.distance <= 0.45][: 3 if SMALL else 12]
first = recordings[0]
print(f"{len(recordings)} recordings; the first, {first.name}: {first.distance:.2f} m in {first.movement_time:.2f} s, "
      f"sampled every {first.step * 1e3:.0f} ms, target {np.round(first.target, 3)} m")

# ## 2. The model of the person
# The paper's planar point mass predicts a reach from its start state and goal. The online estimator inverts it:
# given the hand's state so far, which goal makes the observed movement the model's best reach? Each recording
# is shifted so that its movement starts at the origin, where the estimator's hand starts at rest.
model = comanip.presets.planar()

# ## 3. Online prediction, sample by sample
# `update(t, position, velocity)` takes the time since the movement began (s), the hand's position (m) and
# velocity (m/s), and returns the estimate so far: `goal` (m), `goal_covariance` (m²) and a `status`.
fractions = np.linspace(0.1, 1.0, 10)
model_error = np.full((len(recordings), len(fractions)), np.nan)
hand_error = np.full_like(model_error, np.nan)
for i, recording in enumerate(recordings):
    origin, target = recording.start, recording.target - recording.start
    estimator = comanip.OnlineGoalEstimator(model, np.zeros(4))
    steps = np.flatnonzero((recording.t > recording.onset) & (recording.t <= recording.end_time + 1e-9))
    seen = (recording.t[steps] - recording.onset) / recording.movement_time       # fraction of the movement seen
    goals = []
    for k in steps:
        estimate = estimator.update(recording.t[k] - recording.onset, recording.position[k] - origin, recording.velocity[k])
        goals.append(estimate.goal)
    goals, hands = np.array(goals), recording.position[steps] - origin
    for j, fraction in enumerate(fractions):
        last = np.searchsorted(seen, fraction + 1e-9, side="right") - 1
        if last >= 0:
            model_error[i, j] = np.linalg.norm(goals[last] - target)
            hand_error[i, j] = np.linalg.norm(hands[last] - target)

# ## 4. How far off, and when
# The median error over the recordings at each fraction of the movement: the model's prediction against the
# hand's own position. Early on, a prediction that looks ahead of the hand is what lets a robot move with the
# person instead of after them.
median_model, median_hand = np.nanmedian(model_error, axis=0), np.nanmedian(hand_error, axis=0)
for fraction, m, h in zip(fractions, median_model, median_hand):
    print(f"{fraction:4.0%} of the movement seen: predicted goal {100 * m:5.1f} cm off, the hand {100 * h:5.1f} cm")

fig, ax = plt.subplots(figsize=(6.5, 4))
ax.plot(100 * fractions, 100 * median_model, "o-", label="online estimate of the goal")
ax.plot(100 * fractions, 100 * median_hand, "s--", label="where the hand is now")
ax.set(xlabel="movement seen (%)", ylabel="median distance from the target (cm)",
       title=f"predicting {len(recordings)} recorded reaches of people (cursory, held out)")
ax.legend()
fig.tight_layout()
fig.savefig(figure_path("predict_recorded_reaches"), dpi=110)
