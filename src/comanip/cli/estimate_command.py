"""``comanip estimate``: estimate a reach's goal from a state observed on the way (and, given candidate
goals, the posterior over them); write the estimate and its predicted trajectory as JSON and CSV.

The observation comes from arguments (``--observed`` and ``--t-obs``) or from a CSV of timestamped states
with a header ``t_s, q0.., qdot0..`` (the columns of a plan CSV, so ``comanip plan`` output can be read back)
or from a ROS 2 bag or a Vicon Nexus trajectories export of the hand's position (its velocity smoothed from the
positions, times from the onset):
its last row at or before ``--t-obs`` is the observation, a row at t = 0 is the start, and every row up
to the horizon feeds the posterior.

With ``--online`` every row of ``--observations`` is streamed, as a tracker delivers it, through the online estimator
over a stream of reaches (:class:`~comanip.ReachStream`: each reach found in the motion, its goal revised with every
sample, its forecast of the hand), described by ``--estimator`` (a shipped description or a YAML file,
:mod:`comanip.estimation.streaming.online_settings`; ``--preset``, ``--width``, ``--prior-std``,
``--forecast-horizon`` and ``--leads`` replace its settings): one row per sample with the goal, its spread and where
the hand will be ``--leads`` seconds on; the last estimate (its path ``--forecast-horizon`` seconds ahead) as JSON.
"""

from __future__ import annotations

import argparse
import dataclasses
import json

import numpy as np

from comanip.arguments import as_optional_positive, as_vector
from comanip.cli.command_help import command_help
from comanip.cli.options import (add_bag_arguments, add_marker_arguments, add_model_arguments, add_reach_arguments,
                                 add_unit_check_argument, input_file_or_bag, load_model, vector)
from comanip.cli.outputs import output_dir, point_text, report, warn, write_manifest, write_table
from comanip.estimation import GoalEstimator, goal_posterior
from comanip.estimation.one_shot.goal_estimator import METHODS, check_method
from comanip.estimation.goal_prior import PAPER_PRIOR, prior_covariance
from comanip.estimation.streaming import online_settings
from comanip.estimation.observation import observation_step, observed_state
from comanip.planning.planner import reach_inputs
from comanip.plausibility import human_plausibility
from comanip.recordings.hand_states import read_hand_states


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser("estimate", help=command_help("estimate"), description=__doc__)
    add_model_arguments(parser)
    add_reach_arguments(parser, "the CSV's t = 0 row, else at rest at the body's home position", "out/estimate", "figures")
    parser.add_argument("--observed", type=vector, help="observed state [q; qdot], comma-separated")
    parser.add_argument("--observations", type=input_file_or_bag, help="CSV of timestamped states (header t_s, q0.., qdot0..), "
                        "a ROS 2 bag of the hand's position (MCAP or sqlite3) or a Vicon Nexus trajectories export (a bag's or "
                        "an export's times from the movement's onset)")
    add_bag_arguments(parser, "--observations")
    add_marker_arguments(parser, "--observations")
    add_unit_check_argument(parser, "--observations")
    parser.add_argument("--t-obs", type=float, default=0.2, help="time of the observation after the start, s (default: %(default)s, "
                        "the paper's); before the model's step h it says nothing about the goal and needs --prior")
    parser.add_argument("--prior", type=vector, help="prior goal g_bar (m), comma-separated (default: no regulariser)")
    parser.add_argument("--prior-std", type=prior_std, default=None,
                        help="how uncertain --prior is (m): one number or one per axis, comma-separated, or 'width' for the "
                             "paper's W from the goal width (default: 10 m, a weak prior)")
    parser.add_argument("--method", choices=METHODS, default="regret", help="'regret' (default) or 'paper' (eq. 11 as printed)")
    parser.add_argument("--candidates", type=candidate_list, help="candidate goals for a posterior, e.g. '0.3,0;0.2,0.2' (m)")
    parser.add_argument("--online", action="store_true", help="stream every row of --observations through the online "
                        "estimator (reaches found in the motion, a forecast of the hand) instead of estimating once at --t-obs")
    parser.add_argument("--estimator", default="recorded",
                        help=f"with --online: the online estimator, one of {', '.join(online_settings.names())} or a YAML "
                             "file of the same shape (default: %(default)s, a person who may not move as the model does)")
    parser.add_argument("--forecast-horizon", type=float, default=None,
                        help="with --online: how far ahead (s) each estimate's path reaches (default: the estimator's; "
                             "to where the hand stops)")
    parser.add_argument("--leads", type=vector, default=None,
                        help="with --online: how far ahead (s) the forecast columns look, comma-separated (default: the "
                             "estimator's, 0.1,0.2,0.3)")
    parser.set_defaults(func=run)


def prior_std(text: str):
    """Parse '0.05', '0.05,0.05,0.1' (m) or 'width'; an argparse type."""
    if text.strip() == PAPER_PRIOR:
        return PAPER_PRIOR
    values = vector(text)
    return float(values[0]) if values.size == 1 else values


def candidate_list(text: str) -> np.ndarray:
    """Parse '0.3,0; 0.2,0.2' into an array (C, d); an argparse type."""
    rows = [vector(part) for part in text.split(";") if part.strip()]
    if not rows or len({len(r) for r in rows}) != 1:
        raise argparse.ArgumentTypeError(f"expected goals of equal length (m) separated by ';', e.g. '0.3,0;0.2,0.2', got {text!r}")
    return np.array(rows)


def check_inputs(args, model, start, observed, t_obs) -> None:
    """Every input of the estimate and of the posterior, checked as the estimator checks them (a one-line
    ValueError naming the argument) before it is built."""
    width = reach_inputs(model, start, np.zeros(model.d), args.width)[2]     # the start and the width
    observed_state(model, observed)
    observation_step(model, t_obs)
    prior_covariance(args.prior_std, model, width)
    if args.prior is not None:
        as_vector("prior_goal", args.prior, model.d, "task-space position, m")
    as_optional_positive("max_wall_time", args.max_wall_time, "s")
    check_method(model, args.method)
    if args.candidates is not None and args.candidates.shape[1] != model.d:
        raise ValueError(f"--candidates must be goals of {model.d} coordinates (m) for the {model.name!r} model, "
                         f"got {args.candidates.shape[1]}")


def observation_of(args, model):
    """The start, the observed state and its time (s) from ``--observed`` or ``--observations`` (with every row's
    times (K,) s and states (K, 2n), None for ``--observed``); a one-line ValueError without one."""
    body, n = model.body, model.n
    at_rest = np.r_[body.home_position, np.zeros(n)]
    if args.observations is not None:
        times, states = read_hand_states(args.observations, n, check_units=args.check_units, joint_angles=not body.is_linear,
                                         name="--observations", topic=args.topic, frame=args.frame, marker=args.marker,
                                         max_gap=args.max_gap)
        before = np.flatnonzero((times > 0) & (times <= args.t_obs))
        if before.size == 0:
            raise ValueError(f"--observations has no row with 0 < t_s ≤ --t-obs = {args.t_obs:g} s")
        start = args.start if args.start is not None else (states[0] if times[0] == 0 else at_rest)
        return start, states[before[-1]], times[before[-1]], times, states
    if args.observed is not None:
        return (args.start if args.start is not None else at_rest), args.observed, args.t_obs, None, None
    raise ValueError("give the observation: --observed (with --t-obs) or --observations CSV")


def run(args) -> int:
    model = load_model(args)
    if args.online:
        return run_online(args, model)
    body, n = model.body, model.n
    start, observed, t_obs, times, states = observation_of(args, model)
    check_inputs(args, model, start, observed, t_obs)
    out = output_dir(args.out, "estimate", args.force, create=False)
    estimator = GoalEstimator(model)   # built (and compiled on first use) only once every input is checked
    estimate = estimator.estimate(start, observed, t_obs, args.prior, args.width, prior_std=args.prior_std, method=args.method,
                                  max_wall_time=args.max_wall_time)
    out.mkdir(parents=True, exist_ok=True)
    written = [estimate.save_json(out / "estimate.json"), estimate.save_csv(out / "estimate.csv")]
    summary = {"model": model.name, "estimated_goal": estimate.goal.tolist(), "prior_goal": None if args.prior is None else args.prior.tolist(),
               "prior_std": args.prior_std if args.prior_std is None or isinstance(args.prior_std, (str, float)) else args.prior_std.tolist(),
               "goal_covariance": estimate.goal_covariance.tolist(),
               "t_obs_s": float(t_obs), "observed_step": estimate.observed_step, "method": args.method,
               "width": estimate.width, "success": estimate.success, "status": estimate.status, "message": estimate.message,
               "solve_time_s": estimate.solve_time, "iterations": estimate.iterations, "regret": estimate.regret}
    posterior = None
    if args.candidates is not None:
        if times is None:
            times, states = np.array([t_obs]), np.atleast_2d(observed)
        usable = times <= model.duration
        posterior = goal_posterior(estimator, estimate.start, states[usable], times[usable], args.candidates, args.width)
        path = out / "posterior.json"
        path.write_text(json.dumps(posterior.to_dict(), indent=1))
        written.append(path)
        summary["posterior"] = {"candidates": posterior.candidates.tolist(), "probabilities": posterior.probabilities[-1].tolist(),
                                "most_likely": int(posterior.most_likely[-1]),
                                "entropy_nats_first_last": [float(posterior.entropy[0]), float(posterior.entropy[-1])]}
    if args.png:
        from comanip.plots.estimate_figure import plot_estimate, plot_posterior

        points = None if states is None else np.array([np.asarray(body.kinematics_function(s[:n])[0]).ravel() for s in states])
        written.append(plot_estimate(estimate, out / "estimate.png", observed_points=points, observed_times=times))
        if posterior is not None:
            written.append(plot_posterior(posterior, out / "posterior.png"))
    summary["files"] = [str(p) for p in written]
    write_manifest(out, "estimate", written)
    warn("estimate", human_plausibility(model, estimate))  # of the estimated goal and the predicted reach
    lines = [f"estimate ({model.name}, {args.method}): {estimate.status}, goal {point_text(estimate.goal)} m from the state at "
             f"t = {float(t_obs):.3g} s"]
    if posterior is not None:
        lines.append(f"most likely candidate: {int(posterior.most_likely[-1])} (p = {posterior.probabilities[-1].max():.3g})")
    report(args, lines, summary, out, written)
    return 0 if estimate.success else 1


def online_description(args):
    """The online estimation ``--online`` runs: ``--estimator`` with the settings the other arguments give; a one-line
    ValueError naming the argument."""
    try:
        settings = online_settings.load(args.estimator)
    except ValueError as error:
        raise ValueError(f"--estimator: {error}") from None
    changes = {"model": args.preset}
    for name, value in (("width", args.width), ("prior_std", args.prior_std)):
        if value is not None:
            changes[name] = value
    if args.leads is not None:
        leads = np.atleast_1d(args.leads)
        if not (np.all(np.isfinite(leads)) and np.all(leads > 0)):
            raise ValueError(f"--leads must be times ahead > 0 s, comma-separated, got {args.leads.tolist()}")
        changes["forecast_leads"] = tuple(leads.tolist())
    if args.forecast_horizon is not None:
        if not (np.isfinite(args.forecast_horizon) and args.forecast_horizon > 0):
            raise ValueError(f"--forecast-horizon must be a time ahead > 0 s, got {args.forecast_horizon!r}")
        changes["options"] = dataclasses.replace(settings.options, forecast_horizon=args.forecast_horizon)
    return settings.replace(**changes)


def run_online(args, model) -> int:
    """``--online`` (module docstring): every row of ``--observations`` through a :class:`~comanip.ReachStream`."""
    from comanip.estimation.streaming.reach_stream import ReachStream

    if args.observations is None:
        raise ValueError("--online streams --observations: give a CSV of timestamped states, a ROS 2 bag or a Nexus export")
    for name, value in (("--observed", args.observed), ("--candidates", args.candidates), ("--start", args.start)):
        if value is not None:
            raise ValueError(f"{name} does not go with --online (each reach starts where the stream finds it)")
    settings = online_description(args)
    leads = np.array(settings.forecast_leads)
    n = model.n
    times, states = read_hand_states(args.observations, n, check_units=args.check_units, joint_angles=not model.body.is_linear,
                                     name="--observations", topic=args.topic, frame=args.frame, marker=args.marker,
                                     max_gap=args.max_gap)
    if args.prior is not None:
        as_vector("prior_goal", args.prior, model.d, "task-space position, m")
    out = output_dir(args.out, "estimate", args.force, create=False)
    stream = ReachStream(model, settings, prior_goal=args.prior)   # refuses an arm
    axes = "xyz"[: model.d]
    header = ["t_s", "reach", "moving", "status", *(f"goal_{a}_m" for a in axes), *(f"goal_std_{a}_m" for a in axes),
              *(f"forecast_{lead:g}s_{a}_m" for lead in leads for a in axes)]
    rows, goals, latest = [], np.full((len(times), model.d), np.nan), None
    for k, (t, state) in enumerate(zip(times, states)):
        latest = stream.update(float(t), state[:n], state[n:2 * n])
        estimate = latest.estimate
        if estimate is None:
            rows.append([t, latest.reach, int(latest.moving), ""] + [np.nan] * (2 + len(leads)) * model.d)
            continue
        goals[k] = estimate.goal
        ahead = (np.full((len(leads), model.d), np.nan) if estimate.forecast is None
                 else estimate.forecast.at(estimate.t_obs + leads).position)
        rows.append([t, latest.reach, int(latest.moving), str(estimate.status), *estimate.goal,
                     *np.sqrt(np.diag(estimate.goal_covariance)), *ahead.ravel()])
    out.mkdir(parents=True, exist_ok=True)
    written = [write_table(out / "online.csv", header, rows)]
    final = latest.estimate if latest is not None else None
    if final is not None:
        written.append(final.save_json(out / "estimate.json"))
    if args.png:
        from comanip.plots.streamed_estimates_figure import plot_streamed_estimates

        written.append(plot_streamed_estimates(times, states[:, :n], goals, out / "online.png",
                                               f"{model.name}: the online estimate of every sample"))
    write_manifest(out, "estimate", written)
    summary = {"model": model.name, "samples": len(rows), "reaches": 0 if latest is None else latest.reach,
               "final_goal": None if final is None else final.goal.tolist(),
               "final_status": None if final is None else str(final.status), "leads_s": leads.tolist(),
               "files": [str(p) for p in written]}
    lines = [f"estimate --online ({model.name}): {len(rows)} samples, {summary['reaches']} reach(es) found"
             + ("" if final is None else f", last goal {point_text(final.goal)} m ({final.status})")]
    report(args, lines, summary, out, written)
    return 0 if final is not None else 1
