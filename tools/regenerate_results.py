"""Rewrite the measured blocks of the results pages (docs/results/*.md), so that no number in them is typed by hand.

    PYTHONPATH=src python -m tools.regenerate_results [NAME ...] [--list]

Each block between ``<!-- NAME:begin -->`` and ``<!-- NAME:end -->`` has one page and one script below that
measures it and prints the block's markdown on stdout; this runs the scripts of the blocks named (default: all,
in order; the slow ones take minutes), each as a module from the repository root (``python -m studies.<question>.<script>``,
so that a study imports the benchmarks' problem sets as ``benchmarks.<script>``), and replaces each block's text in
its page with the output.
``tests/project/test_docs.py`` checks that every table of numbers on a results page sits in such a block and that
every block has its script here.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

from tools.result_blocks import block_names, replace_block

ROOT = Path(__file__).resolve().parents[1]

#: block name: (what it shows, the script that prints it and its arguments, run from the repository root)
BLOCKS: dict[str, tuple[str, list[str]]] = {
    "calibration-study": ("the calibration study of the planar preset's family (about 10 min)",
                          ["studies/does_any_paper_configuration_peak_early/print_calibration_study.py"]),
    "goal-calibration": ("coverage of the online goal estimate's 95 % ellipsoid (open-loop belief, and the sync robot's) and exact-observation errors (about 10 min)",
                         ["studies/is_the_goal_covariance_calibrated/measure_goal_estimation.py", "--markdown", "--reaches", "200"]),
    "human-targets": ("the human-likeness targets, paper preset beside the human one and its variants (about 30 min)",
                      ["studies/which_model_options_make_reaching_human_like/make_calibration_table.py", "planar", "human",
                       *(f"studies/which_model_options_make_reaching_human_like/variants/human_{name}.yaml"
                         for name in ("paper_damping", "hit_reward", "effective_width", "stopping", "hyperbolic")),
                       "--trials", "20"]),
    "feedback-cost": ("closed-loop reaches from the exact state against noisy, delayed observation (seconds)",
                      ["studies/what_does_noisy_delayed_feedback_cost/measure_feedback.py", "--markdown"]),
    "online-estimation-speed": ("one-shot against online goal estimates, cold and warm (about 2 min)",
                                ["benchmarks/goal_estimation_times.py", "--markdown", "--reaches", "20"]),
    "policy-comparison": ("robot policies compared on the sync scenario, 20 trials × 4 goals (about 10 min idle, an hour loaded)",
                          ["studies/which_robot_policy_helps_the_person_in_sync/make_policy_comparison.py", "--trials", "20"]),
    "policy-people": ("robot policies on the sync scenario with people who are not the model: off-pace, recorded mouse movements and recorded arm reaches, the forecast policy's errors and the person's efforts against every baseline's, 10 trials × 4 goals × 7 people (about 40 min in one process; --people, --save and --load split it)",
                      ["studies/which_robot_policy_helps_the_person_in_sync/make_people_comparison.py", "--trials", "10"]),
    "sync-task": ("the paper's synchronisation task: every robot policy with the model's person at four paces and recorded arm reaches (TAT-HUM's and UE_ADL's ten people) at their speed and slower, each robot carrying its calibration of the person, the task's targets met or missed, 10 trials × 4 goals × 26 people (about 70 min in one process; --people, --save and --load split it)",
                  ["studies/which_robot_policy_helps_the_person_in_sync/make_sync_task_targets.py", "--trials", "10"]),
    "sync-task-variant": ("the same with a person who intends the height too, 5 trials × 4 goals × 26 people (about 35 min)",
                          ["studies/which_robot_policy_helps_the_person_in_sync/make_sync_task_targets.py", "--trials", "5", "--variant"]),
    "speed": ("solve times of every preset, warm and cold (several minutes; the machine's load moves them)",
              ["benchmarks/solve_times.py", "--markdown", "--repeats", "20", "--only",
               "planar,planar_cold,cartesian,cartesian_cold,planar_uncompiled,planar_cold_uncompiled,cartesian_uncompiled,"
               "cartesian_cold_uncompiled,human,human_cold,human_cartesian,human_cartesian_cold,planar_cold_moving,"
               "cartesian_cold_moving,franka,franka_cold,franka_rest,franka_rest_cold,franka_rest_cold_moving,franka_replan"]),
    "speed-workspace": ("solve times over the sampled workspace sets, this code beside the code before them, taking turns (about 5 min on a quiet machine)",
                        ["benchmarks/solve_times.py", "--markdown", "--repeats", "100", "--compare", "323f41c", "--only",
                         "planar_workspace_cold,planar_workspace_cold_moving,planar_workspace_warm,planar_workspace_warm_moving,cartesian_workspace_cold,cartesian_workspace_cold_moving,cartesian_workspace_warm,cartesian_workspace_warm_moving,human_workspace_cold,human_workspace_cold_moving,human_workspace_warm,human_workspace_warm_moving,human_cartesian_workspace_cold,human_cartesian_workspace_cold_moving,human_cartesian_workspace_warm,human_cartesian_workspace_warm_moving,franka_workspace_cold,franka_workspace_cold_moving,franka_workspace_warm,franka_workspace_warm_moving,franka_rest_workspace_cold,franka_rest_workspace_cold_moving,franka_rest_workspace_warm,franka_rest_workspace_warm_moving"]),
    "realtime-loops": ("closed loops at 100 Hz replanned on a per-cycle budget against the same loops replanned to convergence, over the workspace sets, beside the code before the next cycle was prepared after the command (a few minutes to half an hour by the machine, the two on a core each)",
                       ["benchmarks/realtime_loops.py", "--markdown", "--presets", "franka_rest,planar,cartesian",
                        "--problems", "12", "--compare", "c8f8e2f"]),
    "realtime-loops-step": ("the same loops at each preset's own step h (a few minutes to a quarter of an hour)",
                            ["benchmarks/realtime_loops.py", "--markdown", "--presets", "franka_rest,planar,cartesian",
                             "--problems", "12", "--rate", "step"]),
    "panda-breakdown": ("where a Panda solve spends its time, piece by piece, beside the code before its functions were built for the processor (about 10 min)",
                        ["studies/where_does_a_panda_solve_spend_its_time/measure_breakdown.py", "--markdown", "--compare", "2400645"]),
    "moving-cold-starts-workspace": ("point-mass cold solves from moving starts over the sampled workspace sets: where the iterations go, and cheaper choices of starts (a minute)",
                                     ["benchmarks/drifting_starts.py", "--workspace", "--presets", "planar,cartesian,human,human_cartesian"]),
    "moving-cold-starts": ("the same on the cold-quality benchmark's random problems (a minute)",
                           ["benchmarks/drifting_starts.py", "--presets", "planar,cartesian,human,human_cartesian"]),
    "real-people-development": ("goal prediction on recorded people, development split, 400 movements (about 20 min)",
                                ["benchmarks/real_people.py", "--markdown", "--limit", "400", "--figure",
                                 "docs/figures/real_people_development.png"]),
    "real-people-held-out": ("goal prediction on recorded people, the held-out split: run once per claimed improvement (about 25 min)",
                             ["benchmarks/real_people.py", "--markdown", "--split", "held_out", "--figure",
                              "docs/figures/real_people_held_out.png"]),
    "real-people-simulated": ("the same predictors on reaches sampled from the planar preset's own noise (about 5 min)",
                              ["benchmarks/real_people.py", "--markdown", "--source", "simulated", "--count", "100"]),
    "real-people-arms": ("goal prediction on motion-capture arm reaches streamed at 125 Hz, development split (about 10 min)",
                         ["benchmarks/real_people.py", "--markdown", "--source", "arms", "--models", "arm", "--figure",
                          "docs/figures/real_people_arms.png"]),
    "person-calibration": ("calibration over a person's successive reaches, people made from the arm reaches and the model's own (about 10 min)",
                           ["benchmarks/person_calibration.py", "--markdown", "--figure", "docs/figures/person_calibration.png"]),
    "person-calibration-people": ("calibration over each recorded arm person's reaches, the people model fitted on the other people (about 3 min)",
                                  ["benchmarks/person_calibration.py", "--markdown", "--sources", "people", "--out",
                                   "benchmarks/results/person_calibration_people", "--figure",
                                   "docs/figures/person_calibration_people.png"]),
    "reach-stream": ("update times over a 60 s stream of successive reaches at 250 Hz, with no reset, beside the code before a reach's lead was observed in one batch (about 3 min)",
                     ["benchmarks/reach_stream_times.py", "--compare", "1f01975"]),
    "reach-loop": ("recorded arm reaches back to back through ReachStream, the goal node's replay and, for the first minute, the node live in its own process at 250 Hz; no reset (about 15 min)",
                   ["benchmarks/reach_loop.py", "--node", "--live", "60", "--live-rate", "250",
                    "--live-tracker-rate", "250"]),
    "node-at-tracker-rate": ("the ROS 2 node live in its own process for 10 minutes, fed the recorded arm reaches' poses at 250 Hz by another process (about 11 min on a quiet machine)",
                             ["benchmarks/node_at_tracker_rate.py", "--minutes", "10", "--markdown"]),
    "node-at-tracker-rate-compare": ("the same with poses and twists, this node and the node before its speed-ups taking turns minute by minute (about 5 min)",
                                     ["benchmarks/node_at_tracker_rate.py", "--minutes", "2", "--turn", "1", "--compare",
                                      "9416333", "--markdown"]),
    "arm-explanations": ("each explanation of the online estimator alone on the arm reaches (a few minutes)",
                         ["studies/why_does_the_reaching_model_not_explain_arm_reaches/measure_explanations.py"]),
    "arm-model-share": ("shapes fitted at the person's pace, and the people model with the reaching model's fit, on the arm reaches (a few minutes)",
                        ["studies/does_the_reaching_model_add_to_the_arm_estimate/measure_model_share.py"]),
    "arm-goal-smoothing": ("the people model's goal smoothed over time on the arm reaches: error against jumps (a few minutes)",
                           ["studies/what_does_a_smoother_arm_goal_cost/measure_smoothing.py"]),
    "arm-goal-smoothing-people": ("the same rules on the eleven arm people, each scored with the people model fitted on the other people and given the rule chosen on the other people (about 3 min)",
                                  ["studies/what_does_a_smoother_arm_goal_cost/measure_smoothing.py", "--people"]),
    "arm-people-features": ("the people model's goal on the eleven arm people for each set of the movement's features it could read, each person scored with the people model fitted on the other people (about 15 min)",
                            ["studies/which_movement_features_carry_across_people/compare_features.py"]),
    "arm-people-phases": ("the arm people model's 95 % region on the eleven arm people with a coverage factor for each of 1, 3, 5 or 10 phases of the movement, each person scored with the model fitted on the other people (about 10 min)",
                          ["studies/does_a_region_per_phase_hold_for_new_people/compare_phases.py"]),
    "arm-people-weighting": ("the arm people model's goal on the eleven arm people with every sample, every reach or every person weighing alike in its fit, each person scored with the model fitted on the other people (about 8 min)",
                             ["studies/should_every_reach_weigh_alike/compare_weightings.py"]),
    "update-stages": ("the online estimator's update times with the forecast, and where an update spends them, on the arm and planar presets' own reaches, the recorded arm reaches and mouse movements, beside the code at 9416333 (about 10 min)",
                      ["benchmarks/forecast_times.py", "--presets", "arm,planar", "--reaches", "40", "--repeats", "1", "--stages",
                       "--compare", "9416333", "--markdown"]),
    "person-pace": ("the online estimator with and without the model's reach at the person's pace, on the arm reaches, the mouse movements and the model's own reaches at other paces (about 10 min)",
                    ["studies/does_the_person_pace_explanation_earn_its_time/measure_person_pace.py"]),
    "real-people-lopo": ("goal prediction leave-one-person-out over the eleven arm people: endpoint errors against the simple rules, coverage and goal jumps, person by person (about 15 min)",
                         ["benchmarks/real_people.py", "--markdown", "--source", "people"]),
    "forecast-peers": ("where the hand will be: a learned forecaster, the kinematic forecasters and comanip's forecast, leave-one-person-out over the eleven arm people (about 10 min)",
                       ["benchmarks/forecast_peers.py", "--comanip", "--markdown"]),
    "forecast-shapes": ("the forecast's shape (open-loop plan, closed-loop reach, minimum jerk) given the recorded end, on the arm reaches (a few minutes)",
                        ["studies/does_a_closed_loop_shape_improve_the_forecast/measure_shapes.py"]),
    "arm-preset": ("the arm preset's mean reach against recorded arm reaches (a minute)",
                   ["studies/does_the_arm_preset_move_like_recorded_arms/compare.py", "--figure",
                    "docs/figures/arm_preset_speed_profiles.png"]),
    "arm-preset-people": ("the arm preset's closed-loop timing against each recorded arm person's at their median distance (about 2 min)",
                          ["studies/does_the_arm_preset_move_like_recorded_arms/compare.py", "--people", "--trials", "8"]),
    "arm-timing-fit": ("the timing fit on the model's own reaches and on the arm reaches, and what the fitted models do (about 15 min)",
                       ["studies/can_a_timing_fit_give_the_arm_preset/fit_arm_timing.py"]),
    "people-vs-presets": ("recorded people's timing and speed profiles against the presets' mean reaches (a minute)",
                          ["studies/do_the_presets_move_like_people/compare.py", "--markdown"]),
    "transition-trends": ("Peternel & Babič's trends in the shipped transition data and the fitted model (seconds)",
                          ["studies/are_the_published_transition_trends_reproduced/print_transition_trends.py"]),
}

RESULTS = ROOT / "docs" / "results"
#: block name: the pages that show it (a results page, and for the solve times benchmarks/README.md too)
PAGES: dict[str, tuple[Path, ...]] = {
    "calibration-study": (RESULTS / "calibration.md",),
    "human-targets": (RESULTS / "calibration.md",),
    "goal-calibration": (RESULTS / "calibration.md",),
    "transition-trends": (RESULTS / "calibration.md",),
    "real-people-development": (RESULTS / "real_people.md",),
    "real-people-held-out": (RESULTS / "real_people.md",),
    "real-people-simulated": (RESULTS / "real_people.md",),
    "people-vs-presets": (RESULTS / "real_people.md",),
    "real-people-arms": (RESULTS / "real_people.md",),
    "reach-loop": (RESULTS / "real_people.md",),
    "node-at-tracker-rate": (RESULTS / "real_people.md",),
    "node-at-tracker-rate-compare": (RESULTS / "real_people.md",),
    "arm-explanations": (RESULTS / "real_people.md",),
    "arm-model-share": (RESULTS / "real_people.md",),
    "arm-goal-smoothing": (RESULTS / "real_people.md",),
    "arm-goal-smoothing-people": (RESULTS / "real_people.md",),
    "person-calibration": (RESULTS / "real_people.md",),
    "person-calibration-people": (RESULTS / "real_people.md",),
    "forecast-peers": (RESULTS / "real_people.md",),
    "real-people-lopo": (RESULTS / "real_people.md",),
    "forecast-shapes": (RESULTS / "real_people.md",),
    "arm-people-features": (RESULTS / "real_people.md",),
    "arm-people-phases": (RESULTS / "real_people.md",),
    "arm-people-weighting": (RESULTS / "real_people.md",),
    "update-stages": (RESULTS / "real_people.md",),
    "person-pace": (RESULTS / "real_people.md",),
    "arm-preset": (RESULTS / "real_people.md",),
    "arm-preset-people": (RESULTS / "real_people.md",),
    "arm-timing-fit": (RESULTS / "real_people.md",),
    "reach-stream": (RESULTS / "speed.md",),
    "feedback-cost": (RESULTS / "calibration.md",),
    "policy-comparison": (RESULTS / "policy_comparison.md",),
    "policy-people": (RESULTS / "policy_comparison.md",),
    "sync-task": (RESULTS / "policy_comparison.md",),
    "sync-task-variant": (RESULTS / "policy_comparison.md",),
    "speed": (RESULTS / "speed.md", ROOT / "benchmarks" / "README.md"),
    "online-estimation-speed": (RESULTS / "speed.md",),
    "speed-workspace": (RESULTS / "speed.md",),
    "panda-breakdown": (RESULTS / "speed.md",),
    "realtime-loops": (RESULTS / "speed.md",),
    "realtime-loops-step": (RESULTS / "speed.md",),
    "moving-cold-starts-workspace": (RESULTS / "speed.md",),
    "moving-cold-starts": (RESULTS / "speed.md",),
}


def module_command(script_and_arguments: list[str]) -> list[str]:
    """The command that runs a block's script (a path from the repository root, ``studies/x/y.py``) as the module
    ``studies.x.y``, with its arguments."""
    script, *arguments = script_and_arguments
    return [sys.executable, "-m", ".".join(Path(script).with_suffix("").parts), *arguments]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("names", nargs="*", help=f"blocks to rewrite (default: all): {', '.join(BLOCKS)}")
    parser.add_argument("--list", action="store_true", help="list the blocks and their commands, and stop")
    args = parser.parse_args(argv)
    if args.list:
        for name, (what, command) in BLOCKS.items():
            print(f"{name}: {what}\n    python {' '.join(module_command(command)[1:])}")
        return 0
    unknown = sorted(set(args.names) - set(BLOCKS))
    if unknown:
        parser.error(f"unknown blocks {unknown}; known: {', '.join(BLOCKS)}")
    for name, pages in PAGES.items():
        for page in pages:
            if name not in block_names(page.read_text(encoding="utf-8")):
                parser.error(f"{page} lacks the block {name}")
    for name in args.names or list(BLOCKS):
        command = module_command(BLOCKS[name][1])
        began = time.perf_counter()
        print(f"{name}: python {' '.join(command[1:])} …", file=sys.stderr, flush=True)
        # the script's progress goes to stderr, shown as it runs; its stdout is the block
        block = subprocess.run(command, cwd=ROOT, check=True, stdout=subprocess.PIPE, text=True,
                               env={**os.environ, "PYTHONPATH": str(ROOT / "src")}).stdout
        for page in PAGES[name]:   # written after each block: a later failure keeps the earlier ones
            page.write_text(replace_block(page.read_text(encoding="utf-8"), name, block), encoding="utf-8")
        print(f"{name}: rewritten ({time.perf_counter() - began:.0f} s)", file=sys.stderr, flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
