"""The synchronisation scenario (the paper's Section VI-A) in MuJoCo: a person and a Panda carry a 1.5 kg
object; the person leads in x-y toward a goal the robot does not know; at t_o = 0.2 s the robot estimates the
goal from the hand it has seen and leads the height z along its prediction. Two robots meet the same person:
one that never leads ('passive') and the paper's one-shot estimate ('one-shot').

    python examples/sync_scenario.py           # writes out/examples/sync_scenario.png

The person is chosen by name (PERSON below; comanip.simulation.people): here a recorded arm reach of
examples/data/arm_reaches played 2.5 times slower, as a person moves a heavy handle, through an 800 N/m arm
impedance; "model" is the Cartesian model with motor noise re-planning every 0.22 s, "recorded" a mouse movement.
`comanip simulate sync --person arm-x2.5` runs the same with more trials, goals and policies, and writes every
trial as CSV.
"""

import matplotlib.pyplot as plt
import numpy as np

from comanip.extras import exit_without

exit_without("sim")  # without the 'sim' extra: one line saying how to install it, no traceback

from comanip.simulation import ScenarioSetup, SyncSettings, choose_person, run_sync  # noqa: E402
from _common import SMALL, figure_path  # noqa: E402

PERSON = "arm-x2.5"      # or "model", "recorded", "arm", a folder of arm reaches; -xP plays them P times as long
person = choose_person(PERSON)
trials = 1 if SMALL else 3
runs = {}
setup = None
for policy in ("passive", "one-shot"):
    settings = SyncSettings(goal="near", trials=trials, seed=0, policy=policy, person=person.parameters)
    # the MuJoCo world, the planners and the person's recordings, built once for both runs
    setup = setup or ScenarioSetup(settings, arm_reaches=person.arm_reaches)
    runs[policy] = run_sync(settings, setup, progress=False)
    for trial in runs[policy]:
        m = trial.metrics
        print(f"{policy}: placement error {m['final_error_m'] * 1000:.1f} mm, "
              f"RMS force beyond holding the object {m['rms_force_change_N']:.1f} N")

fig, (xy_ax, z_ax) = plt.subplots(1, 2, figsize=(10, 4))
for color, (policy, trials_run) in zip(("C0", "C1"), runs.items()):
    for k, trial in enumerate(trials_run):
        record = trial.record
        label = policy if k == 0 else None
        xy_ax.plot(record.position[:, 0], record.position[:, 1], color=color, label=label)
        z_ax.plot(record.t, record.position[:, 2], color=color, label=label)
        z_ax.plot(record.t, record.rest_position[:, 2], color=color, ls=":", lw=0.8)
goal = np.asarray(runs["passive"][0].record.goal)
xy_ax.plot(goal[0], goal[1], "r*", ms=12, label="goal")
z_ax.axhline(goal[2], color="r", lw=0.8)
z_ax.axvline(settings.observation_time, color="0.5", ls="--", lw=0.8)
xy_ax.set(xlabel="x (m)", ylabel="y (m)", title=f"handle path (the person, {PERSON}, leads)", aspect="equal")
z_ax.set(xlabel="t (s)", ylabel="z (m)", title="handle height; dotted: robot rest position")
xy_ax.legend(fontsize=8)
fig.tight_layout()
fig.savefig(figure_path("sync_scenario"), dpi=120)
print("wrote", figure_path("sync_scenario"))
