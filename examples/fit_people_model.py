"""Fit the people model to your own lab's arm reaches, then let it say where new reaches will stop.

    python examples/fit_people_model.py       # writes out/examples/fit_people_model.png and the model, .npz

Input: examples/data/arm_reaches/tathum/ (ten reaches of one person from TAT-HUM's 3-D demo data, MIT licence: a
finger marker tracked at 250 Hz, streamed at 125 Hz as a live tracker delivers it). The people model is fitted on
seven of them, saved and loaded back, and the online estimator, given it, follows the other three sample by sample:
the predicted endpoint's distance from where each reach stopped, over the share of the movement seen, beside the
distance of the hand itself, and the radius of the estimate's 95 % region. Seven reaches make a small model; a lab
fits it on all its people's reaches. Method and file format: docs/guide/goal_estimation.md, docs/data_formats.md.
"""

import matplotlib.pyplot as plt
import numpy as np
from scipy.stats import chi2

import comanip
from comanip.estimation import OnlineOptions
from comanip.estimation.people.people_model import PeopleModel
from comanip.recordings import load_tathum
from _common import DATA, SMALL, figure_path

# ## 1. Recorded reaches, as a tracker delivers them
reaches = [trial.streamed_recording() for trial in load_tathum(DATA / "arm_reaches" / "tathum" / "data_3d")]
fitting, new = reaches[:7], reaches[7:8] if SMALL else reaches[7:]

# ## 2. Fit, save, load
# An arm model reads only numbers without units of the movement so far (so it carries to other distances and paces)
# and scales its 95 % region in phases of the movement; the file names both.
fitted = PeopleModel.fit(fitting, kind="arm", trained_on=f"{len(fitting)} example reaches")
people = PeopleModel.load(fitted.save(figure_path("fit_people_model").with_suffix(".npz")))
print(f"fitted on {len(fitting)} reaches; reads {', '.join(people.features)}; "
      f"coverage factor per phase {np.round(people.phase_factors, 2)}")

# ## 3. The online estimator with the fitted model, sample by sample
model = comanip.presets.arm()
fig, (ax_error, ax_region) = plt.subplots(1, 2, figsize=(10, 4), sharex=True)
for r in new:
    estimator = comanip.OnlineGoalEstimator(model, np.r_[r.position[0], np.zeros(model.state_size - model.n)],
                                            options=OnlineOptions(people_model=people))
    seen, goal_error, hand_error, radius = [], [], [], []
    for k in range(len(r.t)):
        estimate = estimator.update(float(r.t[k]), r.position[k], r.velocity[k])
        if r.t[k] < r.onset:
            continue
        seen.append(100 * min((r.t[k] - r.onset) / r.movement_time, 1.2))
        goal_error.append(100 * np.linalg.norm(estimate.goal - r.end))
        hand_error.append(100 * np.linalg.norm(r.position[k] - r.end))
        radius.append(100 * np.sqrt(chi2.ppf(0.95, 3) * np.linalg.eigvalsh(estimate.goal_covariance).max()))
    line, = ax_error.plot(seen, goal_error, label=f"{r.name}: the estimate")
    ax_error.plot(seen, hand_error, "--", color=line.get_color(), lw=0.8, label=f"{r.name}: the hand")
    ax_region.plot(seen, radius, color=line.get_color(), label=r.name)
    print(f"{r.name}: {r.distance:.2f} m; at half of the movement the estimate is "
          f"{goal_error[int(np.searchsorted(seen, 50))]:.1f} cm from where it stopped, the hand "
          f"{hand_error[int(np.searchsorted(seen, 50))]:.1f} cm")

# ## 4. How near, and how sure
# Fitted on so few reaches, the model's spread can leap for a sample where the movement looks like an earlier
# phase of the ones it saw; fitted on a lab's people, such leaps are rarer.
ax_error.set(xlabel="movement seen (%)", ylabel="distance from where the hand stopped (cm)",
             title="the fitted people model's endpoint")
ax_region.set(xlabel="movement seen (%)", ylabel="95 % region's largest radius (cm)", yscale="log",
              title="its uncertainty (the prior's before the onset)")
ax_error.legend(fontsize=7)
ax_region.legend(fontsize=7)
fig.tight_layout()
fig.savefig(figure_path("fit_people_model"), dpi=110)
