"""Whether a planned reach of a point-mass model is one a person could make.

The point-mass presets (planar, human, cartesian, human_cartesian) stand for a person's hand. The optimiser
plans any reach it is given, so a goal 2 m away gives a 'solved' plan at 8 m/s, and a goal given in mm (300
for 0.3 m) a plan that cannot reach it. :func:`human_plausibility` names such plans in words;
:func:`with_plausibility_warnings` adds the words to the plan's message and to ``extras['warnings']``,
leaving its status and success as the solver made them. Arm bodies (the Panda) are robots: their limits are
the planner's joint limits and reachability, not these.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from comanip.units import MAX_REACH_SPAN_M

MAX_HUMAN_REACH_M = 1.0
"""Longest hand displacement (m) of one reach without a step: an arm of about 0.7 m swung from near the
chest to full extension, helped by the shoulder and trunk."""
MAX_HUMAN_HAND_SPEED_M_S = 5.0
"""Peak hand speed (m/s) above which a plan is no person's reach: fast aimed reaches peak at a few m/s."""


def human_plausibility(model, plan) -> list[str]:
    """Warnings (one line each) about a plan of a point-mass ``model`` (a :class:`comanip.ReachingModel`) that
    no person would make: a goal farther than MAX_HUMAN_REACH_M from the start's hand (with a hint when the
    distance looks like mm), a peak hand speed above MAX_HUMAN_HAND_SPEED_M_S. Empty for arm bodies."""
    if not model.body.is_linear:
        return []
    warnings = []
    distance = float(np.linalg.norm(np.asarray(plan.goal, float) - np.asarray(plan.ee_mean[0], float)))
    if distance > MAX_HUMAN_REACH_M:
        hint = " (is it in mm? comanip takes m)" if distance > MAX_REACH_SPAN_M else ""
        warnings.append(f"the goal is {distance:.3g} m from the start, beyond a person's reach of about "
                        f"{MAX_HUMAN_REACH_M:g} m{hint}")
    speed = np.asarray(plan.ee_speed, float)
    peak = float(np.max(speed)) if speed.size and np.all(np.isfinite(speed)) else 0.0
    if peak > MAX_HUMAN_HAND_SPEED_M_S:
        warnings.append(f"the plan's peak hand speed {peak:.3g} m/s is faster than a person reaches "
                        f"(at most about {MAX_HUMAN_HAND_SPEED_M_S:g} m/s)")
    return warnings


def with_plausibility_warnings(model, plan):
    """The plan, or a copy whose message ends with the :func:`human_plausibility` warnings ('; warning: ...')
    and whose ``extras['warnings']`` lists them."""
    warnings = human_plausibility(model, plan)
    if not warnings:
        return plan
    message = "; ".join([plan.message] + [f"warning: {text}" for text in warnings])
    return replace(plan, message=message, extras={**plan.extras, "warnings": warnings})
