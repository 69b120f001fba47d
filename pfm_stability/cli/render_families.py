"""Text of the report's robot families and velocity/fuzzy laws (docs/velocity_and_fuzzy.md): holonomic
verdicts, the non-smooth verdict and its cycle, the fuzzy law's frozen gains and bracket, target tracking.

`cli.render` calls these for the parts of a `report.stability.StabilityReport` that KB's report does not have: the
sections of a `HolonomicScene` and a `NonSmoothScene` (chosen by the result's type), the fuzzy law's notes and the tail.
"""

from __future__ import annotations

from ..report.families import HolonomicScene, NonSmoothScene
from .formatting import number, percent

__all__ = ["FAMILY_LABELS", "HOLONOMIC_FOOTNOTE", "SECTIONS", "holonomic_sections", "non_smooth_sections", "equilibrium_notes", "family_tail"]

FAMILY_LABELS = {
    "robot": "robot family",
    "mass": "mass (robot mass)",
    "alpha_p": "alpha_p (position gain)",
    "alpha_v": "alpha_v (velocity gain)",
    "velocity_exponent": "n (velocity exponent)",
    "a_max": "a_max (braking deceleration)",
    "side": "wall side (fuzzy tables)",
    "symmetrize": "symmetrize (fuzzy tables mirrored)",
    "variant": "variant (gated repulsion magnitude)",
}
"""Labels of the inputs that only the families and the new laws have."""

HOLONOMIC_FOOTNOTE = (
    "margin = relative distance in kappa to the nearest stability boundary (kappa*/kappa - 1; > 0 stable). "
    "kappa* and omega*: the stiffness at which this loop (T, c_h fixed) loses stability and the frequency there (stable below kappa*); "
    "T*: the largest stable loop delay at this kappa and c_h (stable below T*); c_h range: the damping values stable at this kappa and T; "
    "inf = no limit; - = undefined."
)
"""The footnote of a holonomic robot's report (docs/models.md, "Robot loop families")."""

_CYCLE = (("mean_distance", "mean distance", "m"), ("peak_to_peak", "peak-to-peak", "m"), ("heading_amplitude", "heading amplitude", "rad"),
          ("period", "period", "s"), ("min_distance", "closest", "m"), ("duration", "measured over", "s"))


def holonomic_sections(scene, env: dict, verdicts: dict, report):
    """Yield the (title, header, rows, remedies, notes) of a holonomic robot's geometry (`report.families.HolonomicScene`).

    Parameters
    ----------
    scene : HolonomicScene
        The geometry's result.
    env : dict
        Its environment entry of the report's JSON.
    verdicts : dict
        Model name → its verdict entry of the report's JSON.
    report : StabilityReport
        The whole report.
    """
    scenario = scene.geometry
    where = f"alpha = {number(env['alpha_deg'])} deg" if scenario == "wall" else f"L = {number(env['L'])} m"
    name = "Wall" if scenario == "wall" else "Corridor"
    x = "d0" if scenario == "wall" else "x0"
    first = env["equilibria"][scene.main]
    title = f"{name}, {where}, holonomic robot: {x} = {number(first[x])} m, kappa = {number(env['kappa'])} 1/s^2, c_h = {number(env['c_h'])} 1/s"
    header = ["model", "verdict", "margin", "kappa* 1/s^2", "omega* rad/s", "T* s", "c_h range 1/s"]
    rows, fixes = [], {}
    for model, v in verdicts.items():
        ranges = ", ".join(f"({number(lo)}, {number(hi)})" for lo, hi in v["damping_range"]) or "none"
        rows.append([model, v["verdict"] if v["verdict"] == "stable" else v["verdict"].upper(), percent(v["margin"]),
                     number(v["kappa_critical"]), number(v["omega_critical"]), number(v["T_critical"]), ranges])
        if v["verdict"] != "stable" and v["to_stabilize"]:
            fixes[model] = v["to_stabilize"]
    others = [e for e in env["equilibria"] if e is not first]
    notes = ["  other equilibria: " + "; ".join(f"{x} = {number(e[x])} m, kappa = {number(e['kappa'])} 1/s^2" for e in others)] if others else []
    yield title, header, rows, fixes, notes


def non_smooth_sections(scene, env: dict, verdicts: None, report):
    """Yield the section of a non-smooth geometry (`report.families.NonSmoothScene`): the rest band and the simulated cycle.

    Parameters
    ----------
    scene : NonSmoothScene
        The geometry's result.
    env : dict
        Its environment entry of the report's JSON.
    verdicts : None
        A non-smooth geometry has no model verdicts.
    report : StabilityReport
        The whole report.
    """
    scenario = scene.geometry
    where = f"alpha = {number(env['alpha_deg'])} deg" if scenario == "wall" else f"L = {number(env['L'])} m"
    name = "Wall" if scenario == "wall" else "Corridor"
    yield (f"{name}, {where}: NON-SMOOTH (velocity-gated repulsion: no smooth equilibrium, no N, no linear verdict)",
           *_non_smooth_table(scenario, env))


SECTIONS = {HolonomicScene: holonomic_sections, NonSmoothScene: non_smooth_sections}
"""The families' result types → the function yielding their sections (`cli.render` dispatches on the result's type)."""


def _non_smooth_table(scenario: str, env: dict):
    """(header, rows, remedies, notes) of a non-smooth geometry: the rest band and the simulated cycle."""
    if scenario == "wall":
        rows = [["rest band of a holonomic robot (Filippov)", f"d <= {number(env['d_s'])} m"],
                ["pull F_a cos(alpha) the repulsion at rest must match", f"{number(env['friction'])} N"]]
        notes = []
    else:
        mid = env["offsets"].index(min(env["offsets"], key=abs))
        rows = [["lateral position", "neutral (both walls act as Coulomb friction)"],
                ["friction in the middle, left / right", f"{number(env['friction_left'][mid])} / {number(env['friction_right'][mid])} N"]]
        notes = ["  no cycle is simulated in a corridor"]
    cycle = env.get("cycle")
    if cycle is None:
        if scenario == "wall":
            notes.append("  simulated cycle: not run (--no-simulate, or no planar simulator)")
        return ["quantity", "value"], rows, {}, notes
    rows += [[f"simulated cycle: {label}", f"{number(cycle[key])} {unit}"] for key, label, unit in _CYCLE]
    rows += [["simulated cycle: at rest", "yes" if cycle["at_rest"] else "no"], ["simulated cycle: touches the wall", "yes" if cycle["touches_wall"] else "no"]]
    return ["quantity", "value"], rows, {}, notes


def equilibrium_notes(e: dict) -> list[str]:
    """The fuzzy law's frozen-gain N and the one-sided heading gains at one equilibrium (its JSON form).

    Parameters
    ----------
    e : dict
        One equilibrium's JSON entry.
    """
    line = f"  fuzzy-scheduled gains: N total {number(e['N'])} 1/m (used), N frozen {number(e['N_frozen'])} 1/m"
    if "c_plus" in e:
        line += f"; c = {number(e['c'])} (c- {number(e['c_minus'])}, c+ {number(e['c_plus'])}); eta = {number(e['eta'])}, d eta/dd = {number(e['eta_d'])} 1/m"
    return [line]


def family_tail(report, data: dict) -> list[str]:
    """Lines after the geometries: the fuzzy law's robust bracket and the tracking error's dynamics (values from the JSON `data`).

    Parameters
    ----------
    report : StabilityReport
        The report.
    data : dict
        Its JSON form.
    """
    lines = []
    if report.schedule is not None and report.schedule.bracket is not None:
        bracket = data["environment"]["wall"]["robust_bracket"]
        lines += ["", f"Robust bracket (eta in [{number(bracket['eta'][0])}, {number(bracket['eta'][1])}], frozen): "
                      f"N in [{number(bracket['N'][0])}, {number(bracket['N'][1])}] 1/m, d0 in [{number(bracket['d0'][0])}, {number(bracket['d0'][1])}] m"]
    if report.tracking is not None:
        t = data["tracking"]
        lines += ["", f"Target tracking (Ge & Cui 2002 eq 34-36): zeta = {number(t['damping_ratio'])}, "
                      f"omega_n = {number(t['natural_frequency'])} rad/s ({t['regime']})"]
    return lines
