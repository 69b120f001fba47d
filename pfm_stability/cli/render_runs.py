"""Text renderings of simulated runs: ``simulate`` (one run and its prediction) and ``validate`` (a simulated
boundary against every model, the oscillation near it, a random sweep of verdicts)."""

from __future__ import annotations

import math

__all__ = ["render_simulation_text", "render_validation_text", "render_sweep_text"]


# ------------------------------------------------------------------ simulate
def _quantity(value, unit="", digits=4):
    return "undefined" if value is None else f"{value:+.{digits}g}{' ' + unit if unit else ''}"


def render_simulation_text(result, prediction, plot_path=None) -> str:
    """The human-readable report of one run.

    Parameters
    ----------
    result : RunResult
        The run.
    prediction : dict
        The models' answers for its scenario.
    plot_path : str, optional
        Path of the figure written, if any.
    """
    s, m = result.scenario, result.metrics
    r, c = s.robot, s.controller
    simulated = f"{s.duration:g} s simulated"
    if result.events:  # stopped early: the time really simulated (to the event: a contact between samples), and why
        e = result.events[0]
        simulated = f"{e.t:.4g} s simulated of the {s.duration:g} s asked (stopped by the {e.type.replace('_', ' ')} event)"
    why = {
        "collision": "the robot disc touched an obstacle",
        "target_reached": "the target was reached",
        "trapped": f"less than {s.trap_distance:g} m of progress towards the target in {s.trap_time:g} s",
    }
    lines = [
        f"scenario {s.name} ({s.env}), {simulated}, {result.steps} samples of T = {c.T:g} s",
        f"  robot: V = {r.V:g} m/s, tau = {r.tau:g} s, k = {r.k:g} 1/s, W = {r.W:g} m; "
        f"controller: f = {c.f:g}, n = {c.n:g}, hold = {c.hold}, compute_delay = {c.compute_delay}",
        "events:",
    ]
    lines += [f"  {e.type} at t = {e.t:.3f} s (x = {e.x:.3f} m, y = {e.y:.3f} m): {why[e.type]}" for e in result.events] or [
        f"  none (ran {result.t_end:.3f} s)"
    ]
    if result.min_clearance is not None:
        lines.append(f"  closest approach: {result.min_clearance * 100:.3g} cm between the robot disc and an obstacle")
    lines += [
        f"metrics ({m.turning_points} turning points, method {m.method}):",
        f"  growth rate sigma = {_quantity(m.growth_rate, '1/s')}, angular frequency omega = {_quantity(m.angular_frequency, 'rad/s')}",
        f"  oscillating: {'yes' if m.oscillating else 'no'}; stable: {'yes' if m.stable else ('no (collision)' if result.collided else 'no')}; "
        f"limit cycle: {'amplitude %.3g m' % m.amplitude if m.limit_cycle else 'no'}",
    ]
    if m.reason:
        lines.append(f"  ({m.reason})")
    if prediction is not None:
        unit = "m" if prediction.kind == "corridor" else "deg"
        label = "L" if prediction.kind == "corridor" else "alpha"
        lines.append(f"prediction ({prediction.kind}, {label} = {prediction.value:g} {unit}):")
        for p in (prediction.matching, prediction.kb):
            lines.append(
                f"  {p.model:15s} {p.verdict:9s} sigma = {p.growth_rate:+.4g} 1/s, omega = {p.angular_frequency:.4g} rad/s, "
                f"{label}* = {p.critical:.4g} {unit}  [{p.law}]"
            )
    lines.append("notes:")
    lines += [f"  {key}: {value}" for key, value in s.notes.items()]
    if plot_path:
        lines.append(f"plot: {plot_path}")
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------ validate
def _digits(value, digits=5):
    if value is None or not math.isfinite(value):
        return "none" if value is None or value > 0 else "0"
    return f"{value:.{digits}g}"


def _pct(value):
    return "      -" if value is None else f"{100 * value:+7.2f} %"


def render_validation_text(v, sweep=None, sources=None, plot=None, sweep_plot=None) -> str:
    """Human-readable validation report: boundaries, errors, oscillation checks, sweep.

    Parameters
    ----------
    v : Validation
        The simulated boundary against every model.
    sweep : SweepResult, optional
        A random sweep run with it.
    sources : dict, optional
        Parameter → provenance (``ASSUMED …`` ones are listed).
    plot, sweep_plot : str, optional
        Paths of the figures written, if any.
    """
    i = v.inputs
    unit = f" {v.unit}" if v.unit else ""
    name = {"L": "L*", "alpha": "alpha*", "V": "V*", "f": "f*"}[v.parameter]
    head = f"{name} ({v.unit})" if v.unit else name
    assumed = [k for k, s in (sources or {}).items() if str(s).startswith("ASSUMED")]
    fixed = f", L = {i['L']:g} m" if i.get("L") is not None else (f", alpha = {i['alpha_deg']:g} deg" if i.get("alpha_deg") is not None else "")
    lines = [
        f"validate {v.scenario} ({v.env}{fixed}): bisecting {v.parameter}",
        f"  robot: V = {i['V']:g} m/s, tau = {i['tau']:g} s, k = {i['k']:g} 1/s, W = {i['W']:g} m; controller: f = {i['f']:g}, "
        f"n = {i['n']:g}, T = {i['T']:g} s, hold = {i['hold']}, compute_delay = {i['compute_delay']}",
    ]
    if assumed:
        lines.append(f"  assumed by the preset: {', '.join(assumed)} (see --format json inputs.sources)")
    lines += [
        f"simulated boundary: {name} = {_digits(v.simulated_boundary, 6)}{unit} (stable {'above' if v.stable_above else 'below'}; "
        f"bracket [{_digits(v.bracket[0], 6)}, {_digits(v.bracket[1], 6)}]{unit}; {v.runs} runs in {v.seconds:.1f} s)",
        f"predicted boundary, law: {v.law}" + (f"   | KB's lumped law, f_av = {i['f_av']:.4g}" if v.lumped_predicted_boundary else ""),
        f"  {'model':16s} {head:>12s} {'rel. error':>10s}" + (f"   | {head:>12s} {'rel. error':>10s}" if v.lumped_predicted_boundary else ""),
    ]
    for model, value in v.predicted_boundary.items():
        row = f"  {model:16s} {_digits(value):>12s} {_pct(v.relative_error[model]):>10s}"
        if v.lumped_predicted_boundary:
            row += f"   | {_digits(v.lumped_predicted_boundary[model]):>12s} {_pct(v.lumped_relative_error[model]):>10s}"
        lines.append(row)
    lines.append("oscillation near the boundary (measured vs the sampled model's dominant root):")
    for c in v.oscillation:
        s = "undefined" if c.growth_rate is None else f"{c.growth_rate:+.4f}"
        w = "undefined" if c.angular_frequency is None else f"{c.angular_frequency:.4f}"
        fe = "" if c.frequency_error is None else f", {100 * c.frequency_error:+.3f} %"
        lines.append(
            f"  {v.parameter} = {c.value:.6g}{unit}: sigma = {s} 1/s (model {c.predicted_growth_rate:+.4f}), "
            f"omega = {w} rad/s (model {c.predicted_angular_frequency:.4f}{fe}) [{c.method}]"
        )
    if sweep is not None:
        lines += render_sweep_text(sweep).splitlines()
    lines.append("notes:")
    lines += [f"  {key}: {value}" for key, value in v.notes.items()]
    if plot:
        lines.append(f"plot: {plot}")
    if sweep_plot:
        lines.append(f"sweep plot: {sweep_plot}")
    return "\n".join(lines) + "\n"


def render_sweep_text(sweep) -> str:
    """The sweep's agreement, each model's wrong-verdict rate, and every disagreement.

    Parameters
    ----------
    sweep : SweepResult
        The random sweep.
    """
    lines = [
        f"random sweep: {sweep.count} Latin-hypercube sets ({sweep.env}, seed {sweep.seed}), {sweep.included} outside "
        f"+-{100 * sweep.exclude:g} % of the sampled boundary (in NV), {sweep.seconds:.1f} s",
        f"  simulated sign of sigma agrees with sampled on {100 * sweep.agreement:.2f} % ({len(sweep.disagreements)} disagreements)",
        "  wrong verdicts for the sampled robot (model stable but robot oscillates / model unstable but robot stable):",
    ]
    for model, rate in sweep.wrong_verdict_rate.items():
        w = sweep.wrong_verdicts[model]
        lines.append(f"    {model:16s} {100 * rate:6.2f} %  ({w['stable_but_unstable']} / {w['unstable_but_stable']})")
    if sweep.disagreements:
        lines.append("  disagreements:")
        lines += [f"    {p.describe()}" for p in sweep.disagreements]
    return "\n".join(lines) + "\n"
