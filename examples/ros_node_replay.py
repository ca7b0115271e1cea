"""Replay a recorded hand through the comanip ROS 2 goal node, in-process and in lock step (no robot and no
ROS installation: rclpy comes as a wheel with the `ros` extra), and draw what the node published: its goal
estimates over time and the equilibrium pose and stiffness it commanded an impedance controller.

    pip install -e ".[ros]"
    python examples/ros_node_replay.py         # writes out/examples/ros_node_replay.png

Inputs: examples/data/node.yaml (the node's parameters, as `comanip ros --params` reads them) and
examples/data/hand.csv (hand states at 100 Hz: t_s, q0..q2 in m, qdot0..qdot2 in m/s; a Cartesian reach
toward [0.35, 0.1, 0.05] m). The same from the command line:
`comanip ros --params examples/data/node.yaml --replay examples/data/hand.csv --out out/ros`.
"""

import matplotlib.pyplot as plt
import numpy as np

from comanip.extras import exit_without

exit_without("ros")  # without the 'ros' extra: one line saying how to install it, no traceback

from comanip.ros.replay import BASE_STAMP, replay_csv  # noqa: E402
from comanip.ros.node_settings import NodeSettings  # noqa: E402
from _common import DATA, figure_path  # noqa: E402

settings = NodeSettings.from_yaml(DATA / "node.yaml")
recording, files = replay_csv(settings, DATA / "hand.csv", figure_path("ros_node_replay").parent / "ros_node_replay")
print(f"{len(recording.goals)} estimates published; files: {', '.join(path.name for path in files)}")

times = np.array([stamp - BASE_STAMP for stamp, *_ in recording.goals])       # s since the reach started
goals = np.array([goal for _, goal, *_ in recording.goals])                   # (E, 3) m
stds = np.array([np.sqrt(np.diag(cov)) for _, _, cov, _ in recording.goals])  # (E, 3) m
latencies = np.array([latency for *_, latency in recording.goals])            # s
print(f"last estimate {np.round(goals[-1], 3)} m; median latency {np.median(latencies) * 1000:.1f} ms")
command_times = np.array([stamp - BASE_STAMP for stamp, _, _ in recording.commands])
stiffness = np.array([k[0] for _, _, k in recording.commands])                # translational x, N/m

fig, (goal_ax, stiffness_ax) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
for axis, (name, true) in enumerate(zip("xyz", (0.35, 0.1, 0.05))):
    line, = goal_ax.plot(times, goals[:, axis], ".-", label=f"goal {name}")
    goal_ax.fill_between(times, goals[:, axis] - 2 * stds[:, axis], goals[:, axis] + 2 * stds[:, axis],
                         color=line.get_color(), alpha=0.2)
    goal_ax.axhline(true, color=line.get_color(), ls=":", lw=0.8)
goal_ax.set(ylabel="estimated goal (m), ±2 SD", ylim=(-0.3, 0.7), title="what the node published (dotted: the true goal)")
goal_ax.legend(fontsize=8)
stiffness_ax.plot(command_times, stiffness)
stiffness_ax.set(xlabel="t (s)", ylabel="commanded stiffness (N/m)")
fig.tight_layout()
fig.savefig(figure_path("ros_node_replay"), dpi=120)
print("wrote", figure_path("ros_node_replay"))
