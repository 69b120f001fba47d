"""Random parameter sets: does the sign of the simulated growth rate agree with each model? (docs/validation.md)

`verdict_sweep` draws `count` parameter sets from a seeded Latin hypercube
(`sampling.latin_hypercube`: the draws of SciPy's `qmc.LatinHypercube`) over
`SWEEP_RANGES` — V, τ, T, k, f and
the geometry (corridor half-width L or wall angle α) — with W = 0.8 m and
n = 2 (CARMEL, KB §4). Members take the geometries and the sampled structures
in turn: member i is a corridor when ⌊i/4⌋ is even and a wall otherwise,
with (hold, compute_delay) = `STRUCTURES`[i mod 4], so every combination is
covered equally. Each geometry is simulated in one batch (`simulate_members`),
starting `offset` from equilibrium for long enough to measure σ (8 periods
of the sampled model's boundary oscillation, 20–150 s, at most 4000 samples).

Each member's NV comes from its own scenario (`Scenario.effective_law`,
`Scenario.analysis`: the grid's law and the L actually drawn in the grid), and
each model is asked through `predict.model_answer` (the validation's one path
to the models; a verdict within `UNDECIDED_RTOL` of a boundary is "undecided").
Members within `exclude` (3 %) of the `sampled` model's boundary in NV,
|NV/NV* − 1| < `exclude`, are excluded: there σ is too small to tell from
zero. On the rest, the simulated verdict (sign of σ, `pfm_stability.sim.verdict.simulated_verdict`)
is compared with every model's verdict: the agreement with ``sampled`` is
the validation, the other models' wrong-verdict rates say how misleading
they are for a sampled robot (KB's ``kb_first_order`` eq 20, the delay
equation ``exact_delay`` eq 18, …).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..checks import check_choice, check_integer, check_number
from ..models import MODEL_NAMES, Loop, make_model
from ..parameters import CARMEL, Controller, Robot
from ..numerics.sampling import latin_hypercube
from ..io.serialize import json_number, json_ready
from ..sim.api import batch_scenarios
from ..sim.engine import run_batch
from ..sim.verdict import simulated_verdict
from .common import SCENARIOS, parameter_domain, scenario_law
from .predict import environment_gain, model_answer

__all__ = [
    "STRUCTURES",
    "SWEEP_RANGES",
    "MemberVerdict",
    "SweepPoint",
    "SweepResult",
    "simulate_members",
    "simulation_duration",
    "sweep_parameters",
    "verdict_sweep",
]

SWEEP_RANGES = {
    "V": (0.3, 1.5),
    "tau": (0.05, 0.8),
    "T": (0.01, 0.2),
    "k": (0.5, 6.0),
    "f": (0.3, 3.0),
    "L": (0.5, 2.5),
    "alpha_deg": (10.0, 80.0),
}
"""Sweep ranges (uniform): V m/s, τ s, T s, k 1/s, f, L m, α deg.

Mobile robots of CARMEL's class and the loops KB discuss (§3: "sampling
times of up to 3 seconds are reported" — kept to 0.2 s here, where a VFF
controller is still usable): V around KB's 0.8 m/s, τ around 0.3 s, T around
0.065 s, k around the assumed 2 1/s, f around KB's 0.8. L from just wider
than the robot (W/2 = 0.4 m) to a hall; α over the wall angles of KB Fig 5.
In the grid, L and α are further limited per member to where the walls (the
equilibrium) lie inside the active window, L <= 1.55 m for CARMEL's 33
cells of 0.1 m, and the robot clears the wall (`common.parameter_domain`):
beyond the window's reach the grid wall exerts no force at all."""

STRUCTURES = (("command", 0), ("command", 1), ("reference", 0), ("reference", 1))
"""The sampled structures of docs/models.md, in the order members take them."""

_DIMENSIONS = ("V", "tau", "T", "k", "f", "geometry")

COMPARED_MODELS = MODEL_NAMES
"""Models whose verdicts are compared with the simulation."""


@dataclass(frozen=True)
class SweepPoint:
    """One random parameter set, its predictions and its simulated verdict.

    Attributes
    ----------
    index : int
    scenario : {"corridor", "wall"}
    V, tau, T, k, f : float
        m/s, s, s, 1/s, –.
    hold : str
    compute_delay : int
    geometry : float
        L (m) or α (deg), as simulated (grid corridors: snapped to c/2).
    NV : float
        Loop NV of the member's law, 1/s.
    NV_critical : float
        `sampled` NV*, 1/s.
    verdicts : dict
        Model name → "stable", "unstable" or "undecided".
    model_NV_critical : dict
        Model name → its NV*, 1/s (``inf``: never unstable).
    simulated : str
        "stable" or "unstable".
    basis : str
        "growth_rate", "collision" or "metrics".
    growth_rate : float or None
        Measured σ, 1/s.
    predicted_growth_rate : float
        `sampled` dominant root σ = ln|z|/T, 1/s.
    method : str
        Estimator of σ ("linear_prediction", "peaks", "none").
    excluded : bool
        Within `exclude` of the sampled boundary.
    """

    index: int
    scenario: str
    V: float
    tau: float
    T: float
    k: float
    f: float
    hold: str
    compute_delay: int
    geometry: float
    NV: float
    NV_critical: float
    verdicts: dict
    model_NV_critical: dict
    simulated: str
    basis: str
    growth_rate: float | None
    predicted_growth_rate: float
    method: str
    excluded: bool

    @property
    def gain_ratio(self) -> float:
        """NV/NV* of the sampled model (> 1: unstable; ``inf`` when NV* = 0: the sampled
        steering loop is unstable on its own, e.g. command hold with kT > 1 and a compute delay)."""
        return self.NV / self.NV_critical if self.NV_critical > 0 else math.inf

    @property
    def geometry_name(self) -> str:
        """"L (m)" or "alpha (deg)"."""
        return "L (m)" if self.scenario == "corridor" else "alpha (deg)"

    def describe(self) -> str:
        """One line for a report of disagreements."""
        sigma = "undefined" if self.growth_rate is None else f"{self.growth_rate:+.4f}"
        g = f"L = {self.geometry:.3f} m" if self.scenario == "corridor" else f"alpha = {self.geometry:.2f} deg"
        return (
            f"#{self.index} {self.scenario} {g}, V = {self.V:.3f}, tau = {self.tau:.3f}, T = {self.T:.3f}, k = {self.k:.3f}, "
            f"f = {self.f:.3f}, {self.hold}/cd={self.compute_delay}: NV/NV* = {self.gain_ratio:.4f}, sampled "
            f"{self.verdicts['sampled']} (sigma {self.predicted_growth_rate:+.4f}), simulated {self.simulated} "
            f"(sigma {sigma} by {self.method}, {self.basis})"
        )

    def to_dict(self) -> dict:
        """Plain JSON form with ``gain_ratio``; numbers by `serialize.json_number` (infinite NV* → ``"inf"``)."""
        out = json_ready(dict(self.__dict__))
        out["model_NV_critical"] = {k: json_number(v) for k, v in self.model_NV_critical.items()}
        out["gain_ratio"] = json_number(self.gain_ratio)
        return out


@dataclass(frozen=True)
class SweepResult:
    """Agreement of the simulated verdicts with every model over a random sweep.

    Attributes
    ----------
    count : int
        Parameter sets drawn.
    seed : int
    env : {"analytic", "grid"}
    exclude : float
        Relative band around the sampled boundary (in NV) left out.
    included : int
        Parameter sets compared.
    agreement : float
        Fraction of the included sets where the simulated verdict equals ``sampled``'s.
    disagreements : tuple of SweepPoint
        The included sets where it does not.
    wrong_verdict_rate : dict
        Model name → fraction of the included sets where that model's verdict
        differs from the simulation's (``sampled``: 1 − agreement).
    wrong_verdicts : dict
        Model name → how many: ``{"stable_but_unstable": …, "unstable_but_stable": …}``
        (the model says stable and the robot oscillates, and the reverse).
    points : tuple of SweepPoint
        Every set, excluded ones included.
    ranges : dict
    seconds : float
    """

    count: int
    seed: int
    env: str
    exclude: float
    included: int
    agreement: float
    disagreements: tuple
    wrong_verdict_rate: dict
    wrong_verdicts: dict
    points: tuple
    ranges: dict
    seconds: float

    def plot(self, axes=None):
        """`plots.validation.plot_sweep`: σ against NV/NV* of ``sampled``, and the other models' view; returns the figure."""
        from ..plots.validation import plot_sweep

        return plot_sweep(self, axes=axes)

    def to_dict(self, points: bool = False) -> dict:
        """Plain JSON form; every point only with ``points=True`` (the disagreements always).

        ``agreement`` and ``wrong_verdict_rate`` are null (undefined) when no
        set was included; wall-clock ``seconds`` is under ``timing``.

        Parameters
        ----------
        points : bool
            Every point, not only the disagreements.
        """
        out = {
            "count": int(self.count),
            "seed": int(self.seed),
            "env": self.env,
            "exclude": json_number(self.exclude),
            "included": int(self.included),
            "agreement": json_number(self.agreement),
            "disagreements": [p.to_dict() for p in self.disagreements],
            "wrong_verdict_rate": {k: json_number(v) for k, v in self.wrong_verdict_rate.items()},
            "wrong_verdicts": json_ready(self.wrong_verdicts),
            "ranges": json_ready(self.ranges),
            "timing": {"seconds": json_number(self.seconds)},
        }
        if points:
            out["points"] = [p.to_dict() for p in self.points]
        return out


def sweep_parameters(count: int, seed: int = 0, ranges: dict | None = None) -> dict:
    """The Latin-hypercube samples: arrays V, tau, T, k, f and geometry fraction u ∈ [0, 1), plus scenario and structure per member.

    Parameters
    ----------
    count : int
        Samples.
    seed : int
        Seed of the generator.
    ranges : dict, optional
        Overrides of `SWEEP_RANGES` (same keys).

    Returns
    -------
    dict
        ``V, tau, T, k, f, u`` (arrays), ``scenario`` (list of str),
        ``hold`` (list), ``compute_delay`` (array).
    """
    ranges = dict(SWEEP_RANGES if ranges is None else ranges)
    sample = latin_hypercube(count, len(_DIMENSIONS), seed)
    out = {}
    for j, name in enumerate(_DIMENSIONS[:-1]):
        lo, hi = ranges[name]
        out[name] = lo + (hi - lo) * sample[:, j]
    out["u"] = sample[:, -1]
    index = np.arange(count)
    out["scenario"] = [SCENARIOS[(i // len(STRUCTURES)) % 2] for i in index]
    out["hold"] = [STRUCTURES[i % len(STRUCTURES)][0] for i in index]
    out["compute_delay"] = np.array([STRUCTURES[i % len(STRUCTURES)][1] for i in index])
    return out


_MAX_SAMPLES = 4000
"""A batch steps until its longest member: cap each member's samples (T = 0.01 s: 40 s)."""


def simulation_duration(loop: Loop, hold: str, delay: int, env: str) -> float:
    """How long to simulate a member to measure its σ, s.

    8 periods of the sampled model's boundary oscillation (hold, compute
    delay), in [20 s (grid 30 s), 150 s], and at most `_MAX_SAMPLES` samples.

    Parameters
    ----------
    loop : Loop
        τ (s), T (s), k (1/s).
    hold : str
        The sampled model's hold.
    delay : int
        Its compute delay.
    env : {"grid", "analytic"}
        The environment's kind.
    """
    b = make_model("sampled", hold=hold, compute_delay=delay).boundary(loop)
    period = 2 * math.pi / b.omega_critical if b.omega_critical else 0.0
    shortest = 20.0 if env == "analytic" else 30.0
    return min(150.0, max(shortest, 8 * period), max(shortest, _MAX_SAMPLES * loop.T))


def verdict_sweep(
    count: int = 200,
    *,
    seed: int = 0,
    env: str = "analytic",
    exclude: float = 0.03,
    ranges: dict | None = None,
    robot: Robot | None = None,
    controller: Controller | None = None,
    offset: float | None = None,
    pade_order: int = 3,
    law: str | None = None,
    progress=None,
) -> SweepResult:
    """Simulate a Latin hypercube of parameter sets and compare each model's verdict.

    Parameters
    ----------
    count : int
        Parameter sets, >= 8.
    seed : int
        Seed of the Latin hypercube.
    env : {"analytic", "grid"}
    exclude : float
        Leave out sets with |NV/NV* − 1| < `exclude` (`sampled` NV*), in [0, 0.5).
    ranges : dict, optional
        Overrides of `SWEEP_RANGES` (same keys).
    robot, controller : Robot, Controller
        Base values of W, n and the steering-rate limit (default CARMEL); the
        swept fields are replaced per member.
    offset : float, optional
        Start offset, m (default 1e-7 analytic, 0.01 grid: `boundary.DEFAULT_OFFSET`).
    pade_order : int
    law : {"power", "grid"}, optional
        ``env="analytic"``: the walls' lateral law (`sim.scenario_law`; default
        KB's power law); ``"grid"``: the grid's effective law, its cell ratio
        calibrated to each member's f.
    progress : callable, optional
        Called with one line of text per batch.

    Returns
    -------
    SweepResult
    """
    from .boundary import DEFAULT_OFFSET

    started = time.perf_counter()
    count = check_integer("count", count, 8, 100_000)
    check_choice("env", env, ("analytic", "grid"))
    exclude = check_number("exclude", exclude, 0.0, 0.5, low_open=False)
    seed = check_integer("seed", seed, 0, 2**63 - 1)
    ranges = {**SWEEP_RANGES, **(ranges or {})}
    for name, (lo, hi) in ranges.items():
        if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
            raise ValueError(f"ranges[{name!r}] must be (low, high) with low < high; got {(lo, hi)!r}")
    robot = robot if robot is not None else CARMEL.robot
    controller = controller if controller is not None else CARMEL.controller
    offset = check_number("offset", offset if offset is not None else DEFAULT_OFFSET[env], unit="m")
    if law is not None:
        if env == "grid":
            raise ValueError(f"law applies to env=analytic only (the grid's law is its cells); got law={law!r} with env=grid")
        scenario_law(env, robot, controller, law=law)  # checks the name
    s = sweep_parameters(count, seed, ranges)
    laws = {} if law is None else {"law": law}
    bounded = env == "grid" or law == "grid"  # the grid's law acts inside the active window only

    # per member: robot, controller, geometry, duration
    members = []
    for i in range(count):
        r = robot.replace(V=float(s["V"][i]), tau=float(s["tau"][i]), k=float(s["k"][i]))
        c = controller.replace(f=float(s["f"][i]), T=float(s["T"][i]), hold=s["hold"][i], compute_delay=int(s["compute_delay"][i]))
        u = float(s["u"][i])
        if s["scenario"][i] == "corridor":
            lo, hi = ranges["L"]
            if bounded:
                dom = parameter_domain("L", "corridor", env, r, c, scenario_law(env, r, c, **laws), None)
                lo, hi = max(lo, dom[0]), min(hi, dom[1])
            geometry = lo + (hi - lo) * u
        else:
            lo, hi = ranges["alpha_deg"]
            if bounded:
                dom = parameter_domain("alpha", "wall", env, r, c, scenario_law(env, r, c, **laws), None)
                lo, hi = max(lo, dom[0]), min(hi, dom[1])
            geometry = lo + (hi - lo) * u
        loop = Loop.of(r, c)
        members.append((i, s["scenario"][i], r, c, geometry, simulation_duration(loop, c.hold, c.compute_delay, env)))

    models = {name: make_model(name, pade_order=pade_order) for name in COMPARED_MODELS if name != "sampled"}
    points = []
    for kind in ("corridor", "wall"):
        group = [m for m in members if m[1] == kind]
        if not group:
            continue
        arrays = {
            "V": [m[2].V for m in group], "tau": [m[2].tau for m in group], "k": [m[2].k for m in group],
            "f": [m[3].f for m in group], "T": [m[3].T for m in group],
            "hold": [m[3].hold for m in group], "compute_delay": [m[3].compute_delay for m in group],
            "duration": [m[5] for m in group],
        }
        geometry = np.array([m[4] for m in group])
        arrays["L" if kind == "corridor" else "alpha"] = geometry if kind == "corridor" else np.radians(geometry)
        runs = simulate_members(kind, env=env, robot=robot, controller=controller, offset=offset, **laws, **arrays)
        if progress:
            progress(f"sweep: simulated {len(group)} {kind} members ({env})")
        for (i, _, r, c, _, _), member in zip(group, runs):
            if member.run is None:  # the members are drawn inside the simulator's domain
                raise ValueError(f"sweep member {i}: {member.reason}")
            points.append(_assess(i, kind, r, c, member.run, models, exclude))
    points.sort(key=lambda p: p.index)

    included = [p for p in points if not p.excluded]
    n = len(included)
    agree = [p for p in included if p.simulated == p.verdicts["sampled"]]
    rates, wrong = {}, {}
    for name in COMPARED_MODELS:
        miss_stable = sum(p.verdicts[name] == "stable" and p.simulated == "unstable" for p in included)
        miss_unstable = sum(p.verdicts[name] != "stable" and p.simulated == "stable" for p in included)
        rates[name] = (miss_stable + miss_unstable) / n if n else math.nan
        wrong[name] = {"stable_but_unstable": miss_stable, "unstable_but_stable": miss_unstable}
    return SweepResult(
        count=count,
        seed=seed,
        env=env,
        exclude=exclude,
        included=n,
        agreement=len(agree) / n if n else math.nan,
        disagreements=tuple(p for p in included if p.simulated != p.verdicts["sampled"]),
        wrong_verdict_rate=rates,
        wrong_verdicts=wrong,
        points=tuple(points),
        ranges={k: tuple(v) for k, v in ranges.items()},
        seconds=time.perf_counter() - started,
    )


def _assess(index, kind, robot, controller, run, models, exclude) -> SweepPoint:
    """Predictions at the member's own operating point, and its simulated verdict."""
    s = run.scenario
    operating = s.analysis["L"] if kind == "corridor" else s.analysis["alpha"]
    geometry = float(operating) if kind == "corridor" else math.degrees(operating)
    NV = environment_gain(kind, s.effective_law(), operating) * robot.V
    loop = Loop.of(robot, controller)
    sampled = make_model("sampled", hold=controller.hold, compute_delay=controller.compute_delay)
    answers = {
        name: model_answer(sampled if name == "sampled" else models[name], loop, NV, root=name == "sampled")
        for name in COMPARED_MODELS
    }
    NV_star = answers["sampled"].NV_critical
    verdicts = {name: a.verdict for name, a in answers.items()}
    critical = {name: a.NV_critical for name, a in answers.items()}
    simulated, basis = simulated_verdict(run)
    m = run.metrics
    return SweepPoint(
        index=index,
        scenario=kind,
        V=robot.V,
        tau=robot.tau,
        T=controller.T,
        k=robot.k,
        f=controller.f,
        hold=controller.hold,
        compute_delay=controller.compute_delay,
        geometry=geometry,
        NV=NV,
        NV_critical=NV_star,
        verdicts=verdicts,
        model_NV_critical=critical,
        simulated=simulated,
        basis=basis,
        growth_rate=m.growth_rate,
        predicted_growth_rate=answers["sampled"].root.real,
        method=m.method,
        excluded=bool(math.isfinite(NV_star) and NV_star > 0 and abs(NV / NV_star - 1) < exclude),
    )


@dataclass(frozen=True)
class MemberVerdict:
    """The simulated answer for one member of a batch (`simulate_members`).

    Attributes
    ----------
    verdict : str or None
        "stable" or "unstable" in the linear sense (`sim.verdict.simulated_verdict`);
        None when the member could not be simulated (`reason`).
    basis : str
        "growth_rate", "collision", "metrics", or "not simulated".
    growth_rate : float or None
        Measured σ, 1/s (None: undefined, see `basis` and `method`).
    method : str
        Estimator of σ ("linear_prediction", "peaks", "none"), or "none".
    collided : bool
    reason : str or None
        Why the member was not simulated (the scenario's error message).
    run : RunResult or None
        The run itself.
    """

    verdict: str | None
    basis: str
    growth_rate: float | None
    method: str
    collided: bool
    reason: str | None = None
    run: object = None


def simulate_members(kind: str, *, env: str, robot: Robot, controller: Controller, offset: float, progress=None, **members) -> list:
    """Simulate one batch of corridor or wall members and give each one's verdict (the per-point step of every sweep).

    Each member's scenario is built on its own (`sim.api.batch_scenarios`)
    so that one impossible member (a robot that does not fit, a wall angle
    beyond the grid's reach) is reported with its reason instead of failing
    the batch; the others are simulated together (`sim.engine.run_batch`,
    record="offset", metrics on) and judged by `simulated_verdict`.

    Parameters
    ----------
    kind : {"corridor", "wall"}
    env : {"analytic", "grid"}
    robot, controller : Robot, Controller
        Base values; the members override any field.
    offset : float
        Start offset, m.
    progress : callable, optional
        ``progress(step, total)`` of the batch (`run_batch`).
    **members
        Equal-length 1-D arrays (or scalars) of `simulate_batch`'s parameters:
        ``V, tau, k, W, f, n, T, hold, compute_delay``, ``L`` or ``alpha``
        (rad), ``duration``, ``law``, ….

    Returns
    -------
    list of MemberVerdict
        In member order.
    """
    check_choice("kind", kind, SCENARIOS)
    sizes = {np.size(v) for v in members.values() if np.ndim(v) > 0}
    if len(sizes) > 1:
        raise ValueError(f"member arrays must have one length; got {sorted(sizes)}")
    count = sizes.pop() if sizes else 1
    scenarios, reasons = [], []
    for m in range(count):
        one = {name: (v[m] if np.ndim(v) > 0 else v) for name, v in members.items()}
        try:
            scenarios.append(batch_scenarios(kind, env=env, robot=robot, controller=controller, offset=offset, **one)[0])
            reasons.append(None)
        except ValueError as exc:
            scenarios.append(None)
            reasons.append(str(exc))
    valid = [s for s in scenarios if s is not None]
    runs = iter(run_batch(valid, record="offset", metrics=True, progress=progress).runs if valid else ())
    out = []
    for scenario, reason in zip(scenarios, reasons):
        if scenario is None:
            out.append(MemberVerdict(None, "not simulated", None, "none", False, reason))
            continue
        run = next(runs)
        verdict, basis = simulated_verdict(run)
        m = run.metrics
        out.append(MemberVerdict(verdict, basis, m.growth_rate, m.method, bool(run.collided), None, run))
    return out
