"""How big is the wobble: the corridor's limit cycle past V* by harmonic balance, its criticality and a speed limit (docs/wobble.md).

Past V* KB's loop τs³ + s² + ks + kNV·e^(−sT) grows until its nonlinearities hold it.
Three are odd about the corridor's centre line and sit in the loop the simulator runs
(docs/simulator.md):

* **the field**: δ = atan2(F_x(y), F_y(y)), F_x(y) = P(L + y) − P(L − y) (the force law's
  own curvature, then the direction of the resultant), whose describing function
  N_f(A) (1/m, by quadrature: `describing.describing_function`) replaces N;
* **the heading**: ẏ = V·sin θ, whose describing function 2J₁(Θ)/Θ at the heading
  amplitude Θ replaces 1 (`describing.sine_df`);
* **the steering-rate limit**: u = sat(k(δ − θ)) at ±ω_max (the robot's
  `max_steering_rate`), whose describing function n_s replaces 1 in the steering
  gain: k → k·n_s (`describing.saturation_df`).

Harmonic balance with all three, each replaced by its describing function at the
amplitude of its own input (all signals taken as sinusoids at one ω): the quasi-linear
loop is KB's loop with k' = k·n_s and NV' = V·(2J₁(Θ)/Θ)·N_f(A), and a cycle of lateral
amplitude A is a loop on its stability boundary: NV' = NV*(k') at ω = ω*(k'), the
model's own boundary (`exact_delay` or `sampled`, any hold and compute delay). The
amplitudes are tied by the linear parts at ω: ẏ's fundamental is V·2J₁(Θ) = Aω, and the
fundamental of the applied rate is U = Θ·ω·√(1 + ω²τ²) = n_s(E)·E for the saturation's
input amplitude E. Given A, this gives the speed in closed form —
Θ = A·ω·N_f(A)/NV*(k'), V = Aω/(2J₁(Θ)) — with a fixed point in (ω, k') when the rate
limit bites: the branch of cycles is V(A) (`corridor_branch`), read at a speed by
`WobbleBranch.cycles_at`.

**Criticality.** At A → 0, N_f(A)/N = 1 + β_f·A² and 2J₁(Θ)/Θ = 1 − Θ²/8 with
Θ = Aω*/V*; the rate limit is exactly linear there. So V(A) = V*(1 − β·A²) + O(A⁴) with
β = β_f − ω*²/(8V*²), and with the loop unstable just above NV* (the first crossing),
A² = (V − V*)/(−β·V*): **supercritical** (a small cycle grows from V*) when β < 0,
**subcritical** (a cycle exists below V*, down to the fold V_fold = min V(A)) when β > 0.
For the power law, β_f = (n + 1)(n + 2)/(8L²) − N²/4 (the law stiffens, the atan of the
direction softens; docs/wobble.md derives it). The nonlinearities are odd (no quadratic
terms), so this first-harmonic coefficient is the normal form's cubic coefficient, the
first Lyapunov coefficient's sign.

**Trust.** The describing function assumes the loop filters the harmonics the
nonlinearities make. `third_harmonic` bounds the predicted third harmonic of y relative to
its fundamental: the third harmonics of the field (of δ(A sin θ)) and of the rate limit
(of sat(E sin θ)), each through the loop's filtering |L(3jω)|/|L(jω)| with
L(s) = 1/(s(τs² + s + k')), plus the heading's, J₃(Θ)/(3J₁(Θ)) (ẏ = V sin θ integrated once). Above `THIRD_HARMONIC_LIMIT`, where the rate limit holds the
cycle — `rate_harmonic`, the third harmonic the limit puts into the heading over the
fundamental, h₃(sat(E sin θ))·|P(3jω)|/|P(jω)| with P(s) = 1/(s(τs + 1)) (the rate's way to
θ), above its hold's limit (`rate_harmonic_limit`: `RATE_HARMONIC_LIMIT` for the servo,
`HELD_COMMAND_RATE_HARMONIC_LIMIT` for a held command) — between a subcritical branch's fold and V*, or where the heading
swing passes the peak of 2J₁ (Θ > 1.84 rad), a report prints no amplitude and says why (`trusted_cycle`).

With the drive's yaw acceleration limit see `limited_branch` (and `reported_cycle` where the saturation clips the
smoother's input).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field, replace

import numpy as np
from scipy import interpolate, optimize, special

from ..checks import check_choice, check_number
from ..io.serialize import json_number
from ..laws.effective_force import corridor_lateral_force
from ..laws.force_law import ForceLaw, corridor_gain, wall_equilibrium, wall_gain
from ..models import make_model
from ..models.loop import Loop
from .describing import J1_PEAK, describing_function, harmonic_content, saturation_df_for_output
from .limiter import drive_lags, lag_gain, limited_balance, loop_filtering, motor_loop

__all__ = [
    "WOBBLE_MODELS",
    "THIRD_HARMONIC_LIMIT",
    "DEFAULT_TOLERANCE_FRACTION",
    "corridor_steering",
    "field_df",
    "field_cubic",
    "WobbleBranch",
    "WobbleCycle",
    "Wobble",
    "corridor_branch",
    "corridor_wobble",
    "wall_steering",
    "wall_df",
    "wall_branch",
    "wall_wobble",
    "trusted_cycle",
    "reported_cycle",
    "RATE_HARMONIC_LIMIT",
    "HELD_COMMAND_RATE_HARMONIC_LIMIT",
    "limited_branch",
]

WOBBLE_MODELS = ("exact_delay", "sampled")
"""The loop models whose boundary closes the harmonic balance."""

THIRD_HARMONIC_LIMIT = 0.1
"""Largest predicted third-harmonic ratio of y at which the describing function's amplitude is reported."""

RATE_HARMONIC_LIMIT = 0.02
"""Largest `rate_harmonic` (the rate limit's third harmonic in the heading) at which the amplitude is reported: beyond
it the limit shapes θ into a trapezoid the first harmonic misses — with a fast motor (τ <= 0.18 s) the amplitude came
out 8–29 % low and ω 3–18 % high at 0.026–0.063 in experiments/wobble_amplitude.py, within 8 % and 3 % below 0.02."""

HELD_COMMAND_RATE_HARMONIC_LIMIT = 0.04
"""`RATE_HARMONIC_LIMIT` for a held command (``hold="command"``): there the saturation acts on the sampled command, not
inside a continuous servo: every held-command cycle measured with a `rate_harmonic` from 0.02 to 0.04 came within 11 %
in amplitude (wobble_amplitude.py's seven within 8 % and 3.7 % in ω), beyond it −5 to −21 %; the servo's
(``hold="reference"``) −10 % at 0.023, −29 % at 0.043 (docs/wobble.md, "When the describing function is not trusted")."""

DEFAULT_TOLERANCE_FRACTION = 0.1
"""`report --wobble` without a value: a tenth of the clearance L − W/2 (the play the robot has either side)."""

_BRANCH_POINTS = 240


def corridor_steering(law: ForceLaw, L: float):
    """δ(y), rad: the direction of the resultant at offset y (m) in a corridor of half-width L (KB eq 4).

    δ = atan2(F_x(y), F_y(y)), F_x = P(L + y) − P(L − y) (`corridor_lateral_force`),
    F_y = 1 + Q(L + y) + Q(L − y): odd in y, −N·y to first order.

    Parameters
    ----------
    law : ForceLaw
        The lateral law.
    L : float
        Half-width, m.
    """

    def delta(y):
        y = np.asarray(y, dtype=float)
        with np.errstate(all="ignore"):
            Fy = 1.0 + np.asarray(law.goal_force(L + y), dtype=float) + np.asarray(law.goal_force(L - y), dtype=float)
            return np.arctan2(corridor_lateral_force(law, L, y), Fy)

    return delta


def field_df(law: ForceLaw, L: float, A):
    """N_f(A) = −DF of `corridor_steering` at lateral amplitude A, 1/m (N at A → 0).

    Parameters
    ----------
    law : ForceLaw
        The lateral law.
    L : float
        Half-width, m.
    A : float or array_like
        Lateral amplitudes, m, in (0, L).
    """
    N = -np.real(describing_function(corridor_steering(law, L), A))
    return float(N) if np.ndim(N) == 0 else N


def field_cubic(law: ForceLaw, L: float) -> float:
    """β_f, 1/m²: N_f(A)/N = 1 + β_f·A² + O(A⁴) (Richardson on the quadrature at A = ℓ/100 and ℓ/200, ℓ = min(L, 1/N)).

    Parameters
    ----------
    law : ForceLaw
        The lateral law.
    L : float
        Half-width, m.
    """
    N = corridor_gain(law, L)
    return _quadratic_coefficient(lambda a: field_df(law, L, a), N, L)


def _quadratic_coefficient(df, N: float, scale: float) -> float:
    """β_f with df(A)/N = 1 + β_f·A² + O(A⁴): Richardson at A = ℓ/100 and ℓ/200, ℓ = min(scale, 1/N) (both the law's
    length scale and the direction's 1/N)."""
    a1 = min(scale, 1.0 / N) / 100.0
    r1, r2 = ((float(df(a)) / N - 1.0) / a**2 for a in (a1, a1 / 2.0))
    return float((4.0 * r2 - r1) / 3.0)


@dataclass(frozen=True)
class WobbleCycle:
    """One cycle of the branch at a given speed.

    Attributes
    ----------
    amplitude : float
        Lateral amplitude A, m.
    heading_amplitude : float
        Θ, rad.
    omega : float
        rad/s.
    stable : bool
        True when it attracts (V(A) increases through it).
    third_harmonic : float
        Predicted third-harmonic ratio of y (module docstring).
    rate_gain : float
        The rate limit's describing function n_s (1: not saturated).
    rate_harmonic : float
        The rate limit's third harmonic in the heading over the fundamental (module docstring).
    limiter_gain : float
        |N_r| of the drive's yaw acceleration limit (1: not limiting; `describing.rate_limit_df`).
    limiter_lag : float
        Its phase lag, rad (0: not limiting).
    hold : str or None
        The controller's hold (`trusted_cycle` takes its rate limit by it; None: the servo's, the stricter).
    cascade : bool
        The steering-rate saturation clips the smoother's input there: the product of their describing functions misses
        the ramps the smoother puts on the clipped command (`limited_branch`).
    """

    amplitude: float
    heading_amplitude: float
    omega: float
    stable: bool
    third_harmonic: float
    rate_gain: float
    rate_harmonic: float
    limiter_gain: float = 1.0
    limiter_lag: float = 0.0
    hold: str | None = None
    cascade: bool = False


@dataclass(frozen=True)
class WobbleBranch:
    """The branch of describing-function cycles V(A) of one corridor robot (module docstring).

    Attributes
    ----------
    model : str
        The loop model whose boundary closes the balance (`WOBBLE_MODELS`).
    amplitudes : ndarray
        Lateral amplitudes A, m, increasing, up to the clearance L − W/2.
    speeds : ndarray
        V(A), m/s (nan where no cycle of that amplitude exists: the rate limit cannot turn
        that fast, or the heading swing passes 1.84 rad).
    omegas : ndarray
        ω(A), rad/s.
    headings : ndarray
        Θ(A), rad: the course's amplitude (the heading's without a slide, `Robot.slip_lag`).
    rate_gains : ndarray
        n_s(A), the rate limit's describing function.
    third_harmonics : ndarray
        Predicted third-harmonic ratio of y.
    rate_harmonics : ndarray
        The rate limit's third harmonic in the heading (0 where it does not saturate).
    V_critical : float
        V*, m/s (the model's NV*/N).
    omega_critical : float
        ω*, rad/s.
    beta : float
        β, 1/m²: V(A) = V*(1 − βA²) + O(A⁴).
    clearance : float
        L − W/2, m: an amplitude that reaches it touches a wall.
    limiter_gains, limiter_lags : ndarray or None
        |N_r| and the phase lag (rad) of the drive's yaw acceleration limit along the branch (`limited_branch`); None
        without a limit.
    gain : float or None
        The field's gain N at the equilibrium, 1/m (V* = NV*/N).
    hold : str or None
        The controller's hold.
    cascades : ndarray of bool or None
        Where the saturation clips the smoother's input (`WobbleCycle.cascade`); None without a yaw acceleration limit.
    heading_builder : callable or None
        With such points: builds the branch with the steering-rate limit as the heading's rate limit (`limited_branch`,
        ``heading_limit=True``; `heading_limited`, computed when first read); else None.
    """

    model: str
    amplitudes: np.ndarray
    speeds: np.ndarray
    omegas: np.ndarray
    headings: np.ndarray
    rate_gains: np.ndarray
    third_harmonics: np.ndarray
    rate_harmonics: np.ndarray
    V_critical: float
    omega_critical: float
    beta: float
    clearance: float
    limiter_gains: np.ndarray | None = None
    limiter_lags: np.ndarray | None = None
    gain: float | None = None
    hold: str | None = None
    cascades: np.ndarray | None = None
    heading_builder: object = field(default=None, repr=False, compare=False)

    @functools.cached_property
    def heading_limited(self) -> "WobbleBranch | None":
        """The branch with the steering-rate limit on the heading (`heading_builder`), or None."""
        return self.heading_builder() if self.heading_builder is not None else None

    @property
    def criticality(self) -> str:
        """``"supercritical"`` (β < 0) or ``"subcritical"``."""
        return "supercritical" if self.beta < 0 else "subcritical"

    @property
    def dA2_dV(self) -> float:
        """dA²/dV at A → 0, m²/(m/s): −1/(β·V*) (> 0 supercritical)."""
        return -1.0 / (self.beta * self.V_critical)

    @property
    def fold_speed(self) -> float:
        """The slowest speed with a cycle inside the corridor (min V(A)), m/s: V* when supercritical and V(A) rises."""
        finite = self.speeds[np.isfinite(self.speeds)]
        return float(min(self.V_critical, finite.min())) if finite.size else self.V_critical

    def cycles_at(self, V: float) -> tuple:
        """Every cycle of the branch at speed V (m/s), by amplitude: linear interpolation of V(A), polished on the grid.

        Parameters
        ----------
        V : float
            Speed, m/s.
        """
        A, S = self.amplitudes, self.speeds
        out = []
        d = S - V
        for i in range(A.size - 1):
            if not (np.isfinite(d[i]) and np.isfinite(d[i + 1])) or d[i] == d[i + 1] or (d[i] > 0) == (d[i + 1] > 0):
                continue
            t = d[i] / (d[i] - d[i + 1])
            pick = lambda x: float(x[i] + t * (x[i + 1] - x[i]))
            limiter = (pick(self.limiter_gains), pick(self.limiter_lags)) if self.limiter_gains is not None else (1.0, 0.0)
            cascade = bool(self.cascades is not None and (self.cascades[i] or self.cascades[i + 1]))
            out.append(WobbleCycle(pick(A), pick(self.headings), pick(self.omegas), bool(S[i + 1] > S[i]),
                                   pick(self.third_harmonics), pick(self.rate_gains), pick(self.rate_harmonics), *limiter, self.hold, cascade))
        return tuple(out)

    def tolerance_speed(self, tolerance: float) -> float:
        """The fastest speed whose wobble stays under `tolerance` (m): min of V(A) over A >= tolerance, m/s.

        Supercritical and rising: V(tolerance). Subcritical: no more than the fold (a large start
        may find the big cycle there). Past the clearance the robot touches a wall, so a tolerance
        beyond it gives the speed at which the cycle reaches the wall.

        Parameters
        ----------
        tolerance : float
            Largest acceptable lateral amplitude, m, > 0.
        """
        tolerance = min(tolerance, self.clearance)
        A, S = self.amplitudes, self.speeds
        if tolerance < A[0]:
            return self.fold_speed
        at = float(np.interp(tolerance, A, S))
        beyond = S[(A >= tolerance) & np.isfinite(S)]
        candidates = [v for v in (at, *beyond) if math.isfinite(v)]
        return float(min(candidates)) if candidates else self.V_critical


@dataclass(frozen=True)
class Wobble:
    """The predicted wobble of one corridor robot at its speed (module docstring; JSON `corridor.wobble`).

    Attributes
    ----------
    amplitude : float or None
        Lateral amplitude, m (0: no cycle, the robot settles; None: the method cannot be trusted here, see `reason`).
    heading_amplitude : float or None
        rad.
    omega : float or None
        rad/s (None without a cycle).
    reaches_wall : bool
        The wobble grows until the robot touches a wall (no cycle inside the clearance).
    criticality : str or None
        ``"supercritical"`` or ``"subcritical"`` (None: no branch, see `reason`).
    V_tolerance : float
        The fastest speed whose wobble stays under `tolerance`, m/s (nan without a branch).
    tolerance : float or None
        m (None: the default, when no branch gave the clearance).
    V_critical : float
        V*, m/s.
    V_fold : float
        The slowest speed at which a cycle exists inside the corridor, m/s (V* when supercritical).
    third_harmonic : float or None
        The trust measure at the cycle: the predicted third harmonic of y over its fundamental.
    method : str
        How it was computed.
    reason : str or None
        Why the amplitude is null, or what to know about it.
    rate_harmonic : float or None
        The second trust measure: the rate limit's third harmonic in the heading over the fundamental.
    limiter : tuple or None
        With the drive's yaw acceleration limit: (|N_r|, lag in rad) at the cycle, (None, None) without one; None when the
        robot has no limit (JSON ``limiter_gain``, ``limiter_lag`` only then).
    """

    amplitude: float | None
    heading_amplitude: float | None
    omega: float | None
    reaches_wall: bool | None
    criticality: str | None
    V_tolerance: float
    tolerance: float | None
    V_critical: float
    V_fold: float
    third_harmonic: float | None
    method: str
    reason: str | None = None
    rate_harmonic: float | None = None
    limiter: tuple | None = None

    @classmethod
    def unavailable(cls, reason: str, tolerance: float | None) -> "Wobble":
        """No branch to read (N <= 0, no oscillatory boundary, …): every number null, with the reason.

        Parameters
        ----------
        reason : str
            Why.
        tolerance : float or None
            The tolerance asked, m (None: the default).
        """
        return cls(None, None, None, None, None, math.nan, tolerance, math.nan, math.nan, None, "none", reason)

    def to_dict(self) -> dict:
        """JSON: every field, numbers through `json_number` (nan and None as null)."""
        number = lambda x: None if x is None or (isinstance(x, float) and math.isnan(x)) else json_number(x)
        return {
            "amplitude": number(self.amplitude),
            "heading_amplitude": number(self.heading_amplitude),
            "omega": number(self.omega),
            "reaches_wall": self.reaches_wall,
            "criticality": self.criticality,
            "V_tolerance": number(self.V_tolerance),
            "tolerance": number(self.tolerance),
            "V_critical": number(self.V_critical),
            "V_fold": number(self.V_fold),
            "third_harmonic": number(self.third_harmonic),
            "rate_harmonic": number(self.rate_harmonic),
            "method": self.method,
            "reason": self.reason,
            **({"limiter_gain": number(self.limiter[0]), "limiter_lag": number(self.limiter[1])} if self.limiter is not None else {}),
        }


def reported_cycle(branch: "WobbleBranch", V: float, cycle: WobbleCycle) -> WobbleCycle | None:
    """The cycle a report gives for `cycle` of `branch` at speed V, or None when the describing function is not trusted.

    `cycle` itself when `trusted_cycle`. Where only the saturation clipping the smoother's input fails the test
    (`WobbleCycle.cascade`), the heading-limited branch's (`WobbleBranch.heading_limited`: the steering-rate limit as
    the heading's rate limit, the smoother on the unclipped command) stable cycle at V nearest in amplitude, if its own
    third harmonic passes `THIRD_HARMONIC_LIMIT` (module docstring, "Trust").

    Parameters
    ----------
    branch : WobbleBranch
        The branch `cycle` is on.
    V : float
        Speed, m/s.
    cycle : WobbleCycle
        A cycle of the branch at V.
    """
    if trusted_cycle(cycle):
        return cycle
    if not cycle.cascade or branch.heading_limited is None or not cycle.third_harmonic <= THIRD_HARMONIC_LIMIT \
            or not cycle.rate_harmonic <= rate_harmonic_limit(cycle.hold):
        return None
    shaped = [c for c in branch.heading_limited.cycles_at(V) if c.stable]
    if not shaped:
        return None
    nearest = min(shaped, key=lambda c: abs(c.amplitude - cycle.amplitude))
    return nearest if nearest.third_harmonic <= THIRD_HARMONIC_LIMIT else None


def trusted_cycle(cycle: WobbleCycle) -> bool:
    """The describing function's trust test at a cycle: `third_harmonic` <= `THIRD_HARMONIC_LIMIT`, `rate_harmonic` within its
    hold's limit (`rate_harmonic_limit`), and no saturation clipping the smoother's input (`WobbleCycle.cascade`).

    Parameters
    ----------
    cycle : WobbleCycle
        A cycle of the branch.
    """
    return cycle.third_harmonic <= THIRD_HARMONIC_LIMIT and cycle.rate_harmonic <= rate_harmonic_limit(cycle.hold) and not cycle.cascade


def rate_harmonic_limit(hold: str | None) -> float:
    """The largest `rate_harmonic` trusted: `HELD_COMMAND_RATE_HARMONIC_LIMIT` for ``"command"``, else `RATE_HARMONIC_LIMIT`.

    Parameters
    ----------
    hold : str or None
        The controller's hold (None: a cycle of a branch that does not say; the stricter limit).
    """
    return HELD_COMMAND_RATE_HARMONIC_LIMIT if hold == "command" else RATE_HARMONIC_LIMIT


def wall_steering(law: ForceLaw, alpha: float):
    """δ(x), rad: the direction of the resultant at distance d0 + x from a wall (x > 0 away from it), target at angle α (KB eq 4, 9).

    δ = atan2(P(d) − (1 + Q(d))·cos α, (1 + Q(d))·sin α), d = d0 + x: 0 at the equilibrium, −N·x to first order,
    not odd (the law's 1/dⁿ is steeper towards the wall).

    Parameters
    ----------
    law : ForceLaw
        The lateral law.
    alpha : float
        Target angle from the wall normal, rad.
    """
    d0 = wall_equilibrium(law, alpha)
    c, s = math.cos(alpha), math.sin(alpha)

    def delta(x):
        d = d0 + np.asarray(x, dtype=float)
        with np.errstate(all="ignore"):
            G = 1.0 + np.asarray(law.goal_force(d), dtype=float)
            return np.arctan2(np.asarray(law.force(d), dtype=float) - G * c, G * s)

    return delta


def wall_df(law: ForceLaw, alpha: float, A):
    """The biased (dual-input) describing function at a wall: (N_f(A) in 1/m, the bias B(A) in m) for amplitudes A (m).

    With x = B + A·sin θ the heading's mean must vanish for the robot to travel along the wall, so the mean of
    δ(B + A sin θ) is 0 (the bias B solves it, scipy brentq; B > 0: the cycle's centre lies further out than d0, the law
    being steeper towards the wall), and N_f(A) = −(first harmonic of δ)/A.

    Parameters
    ----------
    law : ForceLaw
        The lateral law.
    alpha : float
        Target angle from the wall normal, rad.
    A : array_like
        Amplitudes, m, below d0.
    """
    delta = wall_steering(law, alpha)
    d0 = wall_equilibrium(law, alpha)
    theta = 2.0 * math.pi * (np.arange(256) + 0.5) / 256
    sin = np.sin(theta)
    N, B = [], []
    for a in np.atleast_1d(np.asarray(A, dtype=float)):
        mean = lambda b: float(np.mean(delta(b + a * sin)))
        lo, hi = -d0 + a * (1.0 + 1e-9) + 1e-12, max(a, d0)
        while mean(hi) > 0:
            hi *= 2.0
        b = optimize.brentq(mean, lo, hi, xtol=1e-15, rtol=1e-13) if mean(lo) > 0 else math.nan
        B.append(b)
        N.append(-2.0 * float(np.mean(delta(b + a * sin) * sin)) / a if math.isfinite(b) else math.nan)
    return np.array(N), np.array(B)


def wall_branch(robot, controller, law: ForceLaw, alpha: float, *, model: str = "sampled", points: int = _BRANCH_POINTS) -> WobbleBranch:
    """The describing-function branch V(A) beside a wall (the biased describing function `wall_df`; otherwise as
    `corridor_branch`). The branch ends where the cycle's inner extreme d0 + B − A reaches W/2 (the robot touches the wall):
    that amplitude is its `clearance`.

    Parameters
    ----------
    robot : parameters.Robot
        τ, k, W and `max_steering_rate`.
    controller : parameters.Controller
        T, hold, compute delay.
    law : ForceLaw
        The wall's lateral law.
    alpha : float
        Target angle from the wall normal, rad.
    model : {"exact_delay", "sampled"}
        The loop model whose boundary closes the balance.
    points : int
        Amplitudes on the branch.
    """
    check_choice("model", model, WOBBLE_MODELS)
    d0, N = wall_gain(law, alpha)
    room = d0 - robot.W / 2
    if not (room > 0 and N > 0):
        raise ValueError(f"the wobble needs a restoring wall equilibrium clear of the wall (d0 > W/2, N > 0); got d0 = {d0:g} m, N = {N:g} 1/m")
    A = room * np.geomspace(1e-3, 1.0, int(points))
    Nf, B = wall_df(law, alpha, A)
    inner = d0 + B - A - robot.W / 2  # > 0: the cycle stays clear of the wall
    touching = np.flatnonzero(~(inner > 0))
    clearance = room
    if touching.size:
        j = touching[0]
        clearance = float(np.interp(0.0, [inner[j], inner[j - 1]], [A[j], A[j - 1]])) if j > 0 else float(A[0])
        Nf = np.where(A <= clearance, Nf, np.nan)
    beta_f = _quadratic_coefficient(lambda a: wall_df(law, alpha, [a])[0][0], N, d0)
    return _branch(robot, controller, wall_steering(law, alpha), N, A, Nf, clearance, model, beta_f)


def _fundamental_input(U: float, M: float) -> float:
    """E: the saturation's input amplitude whose output fundamental is U (< 4M/π)."""
    return U / saturation_df_for_output(U, M)


class _GainTable:
    """NV*(k·f) and ω*(k·f) of the loop model for steering-gain factors f in [0.02, 1], splined in log f (computed once)."""

    FACTORS = np.geomspace(0.02, 1.0, 64)

    def __init__(self, boundary):
        values = np.array([boundary(f) for f in self.FACTORS], dtype=float)
        x = np.log(self.FACTORS)
        self.NV = interpolate.CubicSpline(x, values[:, 0])
        self.omega = interpolate.CubicSpline(x, values[:, 1])

    def __call__(self, factor: float) -> tuple:
        x = math.log(factor)
        return float(self.NV(x)), float(self.omega(x))

    def factor(self, gain: float, lags: tuple, M: float) -> float | None:
        """The largest f with n_s(E) = f, where the applied rate's fundamental U = Θω·|P(jω)| (the drive's lags
        `limiter.lag_gain`), Θ = gain·ω/NV* (`gain` = A·N_f(A)); None when none exists (the limit cannot carry the cycle)."""
        f = np.geomspace(self.FACTORS[0], 1.0, 400)
        x = np.log(f)
        w = self.omega(x)
        U = gain * w * w / self.NV(x) * lag_gain(w, lags)
        g = saturation_df_for_output(U, M) - f
        change = np.flatnonzero((g[:-1] > 0) != (g[1:] > 0))
        if change.size == 0:
            return None
        j = change[-1]

        def residual(factor):
            NV, w = self(factor)
            u = gain * w * w / NV * lag_gain(w, lags)
            return saturation_df_for_output(u, M) - factor

        return optimize.brentq(residual, f[j], f[j + 1], xtol=1e-13)


@functools.lru_cache(maxsize=32)
def _gain_table(model: str, hold: str, compute_delay: int, loop: Loop) -> _GainTable:
    """The `_GainTable` of one loop (`limiter.motor_loop`), shared by its wall and corridor branches (64 model boundaries)."""
    loop_model = make_model(model, hold=hold, compute_delay=compute_delay)

    def boundary(gain_factor: float):
        b = loop_model.boundary(replace(loop, k=loop.k * gain_factor))
        return b.NV_critical, b.omega_critical

    return _GainTable(boundary)


def corridor_branch(robot, controller, law: ForceLaw, L: float, *, model: str = "sampled", points: int = _BRANCH_POINTS) -> WobbleBranch:
    """The describing-function branch V(A) of a robot in the middle of a corridor (module docstring).

    Parameters
    ----------
    robot : parameters.Robot
        τ, k, W and `max_steering_rate` (V is not used: the branch gives V for each A).
    controller : parameters.Controller
        T, hold, compute delay.
    law : ForceLaw
        The corridor's lateral law (`laws.force_law.law_in_force`; the grid's `GridWallLaw`).
    L : float
        Half-width, m, > W/2.
    model : {"exact_delay", "sampled"}
        The loop model whose boundary closes the balance.
    points : int
        Amplitudes on the branch (geometric from 10⁻³ of the clearance to the clearance).

    Returns
    -------
    WobbleBranch

    Raises
    ------
    ValueError
        For an unknown model, a corridor the robot does not fit, or N <= 0 (no centre equilibrium to wobble about).
    """
    check_choice("model", model, WOBBLE_MODELS)
    clearance = L - robot.W / 2
    if not clearance > 0:
        raise ValueError(f"L must exceed W/2 = {robot.W / 2:g} m for a wobble; got L = {L:g} m")
    N = corridor_gain(law, L)
    if not N > 0:
        raise ValueError(f"the wobble needs a restoring centre line (N > 0); got N = {N:g} 1/m")
    A = clearance * np.geomspace(1e-3, 1.0, int(points))
    return _branch(robot, controller, corridor_steering(law, L), N, A, field_df(law, L, A), clearance, model, field_cubic(law, L))


def _branch(robot, controller, delta, N: float, A, Nf, clearance: float, model: str, beta_f: float) -> WobbleBranch:
    """The branch V(A) for the field's describing function `Nf` at amplitudes `A` (module docstring), and where the
    steering-rate limit shapes the heading of a held command, the branch with it on the heading (`heading_limited`)."""
    branch = _branch_of(robot, controller, delta, N, A, Nf, clearance, model, beta_f)
    if branch.cascades is not None and np.any(branch.cascades):
        build = functools.partial(limited_branch, robot, controller, delta, N, A, Nf, clearance, model, beta_f, heading_limit=True)
        branch = replace(branch, heading_builder=build)
    return branch


def _branch_of(robot, controller, delta, N: float, A, Nf, clearance: float, model: str, beta_f: float) -> WobbleBranch:
    """The branch with the steering-rate limit on the command: `limited_branch` with a yaw acceleration limit, else the
    model's own boundary with the steering gain's factor (module docstring)."""
    if math.isfinite(robot.yaw_accel_limit):
        return limited_branch(robot, controller, delta, N, A, Nf, clearance, model, beta_f)
    loop_model = make_model(model, hold=controller.hold, compute_delay=controller.compute_delay)
    # in the motor's units: the plant gain g scales the command after the rate limit (docs/simulator.md), so
    # g·sat_M(u) = sat_gM(g·u): a robot (k, M, g) is the robot (g·k, g·M, 1); the dead time D and the lags τ, τ_a stay in the loop
    loop = motor_loop(robot, controller)
    lags, k, M = drive_lags(loop), loop.k, robot.plant_gain * robot.max_steering_rate

    def boundary(gain_factor: float):
        b = loop_model.boundary(motor_loop(robot, controller, gain_factor))
        return b.NV_critical, b.omega_critical

    NV0, w0 = boundary(1.0)
    if not (math.isfinite(NV0) and NV0 > 0 and w0):
        raise ValueError(f"the {model} loop has no oscillatory stability boundary here (NV* = {NV0:g} 1/s): no wobble to predict")
    V_star = NV0 / N
    h3 = harmonic_content(delta, A)
    sat = lambda x: np.clip(x, -M, M)
    speeds, omegas, headings, gains, thirds, rates = (np.full(A.size, np.nan) for _ in range(6))
    table = None  # built on the first amplitude the rate limit bites at
    for i, (a, nf) in enumerate(zip(A, Nf)):
        if not math.isfinite(nf):
            continue
        theta, w, factor = a * w0 * nf / NV0, w0, 1.0
        if theta * w0 * lag_gain(w0, lags) > M:  # the rate limit bites: solve for the steering gain's factor
            table = table or _gain_table(model, controller.hold, controller.compute_delay, loop)
            factor = table.factor(a * nf, lags, M)
            if factor is None:
                continue
            NV, w = table(factor)
            theta = a * w * nf / NV
        if not theta < J1_PEAK:
            continue
        U = theta * w * lag_gain(w, lags)
        speeds[i] = a * w / (2.0 * special.j1(theta))
        omegas[i], headings[i], gains[i] = w, theta, factor
        h3_rate = harmonic_content(sat, _fundamental_input(U, M)) if factor < 1.0 else 0.0
        rates[i] = h3_rate * lag_gain(w, lags) / (3.0 * lag_gain(3.0 * w, lags))
        thirds[i] = (h3[i] + h3_rate) * loop_filtering(w, lags, k * factor) \
            + special.jv(3, theta) / (3.0 * special.j1(theta))
    beta = beta_f - w0**2 / (8.0 * V_star**2)
    return WobbleBranch(model, A, speeds, omegas, headings, gains, thirds, rates, V_star, w0, beta, clearance, gain=N, hold=controller.hold)


def limited_branch(robot, controller, delta, N: float, A, Nf, clearance: float, model: str, beta_f: float, *,
                   heading_limit: bool = False) -> WobbleBranch:
    """The branch V(A) with the drive's yaw acceleration limit R: the rate limiter as one more describing function.

    The quasi-linear loop of the module docstring with the command's describing function N_c = n_s(E)·N_r(U, ω) (the
    saturation at g·ω_max, then the limiter at g·R, `describing.rate_limit_df`: sampled at T for the `sampled` loop, as
    the simulator's smoother acts once per period; continuous for `exact_delay`), complex: each amplitude solves
    1 + N_c·(H₀(ω) + K'·H₁(ω)) = 0 on the loop seen from its command (`limiter.limited_balance`), U the limiter's input
    amplitude, |N_r|·U = Θ·ω·√(1 + ω²τ²), K' = g·k·N_f(A)·A·ω/Θ, V = Aω/(2J₁(Θ)) as without the limit. Below the
    limiter's threshold N_r = 1 and the branch is the one without it, so β is unchanged: the limiter acts at finite
    amplitude, where its lag bends V(A) down — cycles below V* (`WobbleBranch.fold_speed`).

    ``heading_limit``: the steering-rate limit as the heading's rate limit instead — θ = RL(θ_lin), the rate limiter's
    describing function N_h(θ_lin·ω/(g·ω_max)) on the linear servo's heading, on the field's path only:
    1 + N_r·(H₀ + N_h·K'·H₁) = 0 — where the saturation clips the smoother's input (`WobbleCycle.cascade`).

    Parameters
    ----------
    robot : parameters.Robot
        τ, k, W, g, D, `max_steering_rate` and `yaw_accel_limit` (finite unless ``heading_limit``).
    controller : parameters.Controller
        T, compute delay; ``hold="command"`` (a servo has no command sequence to limit).
    delta : callable
        δ(y), the field's steering (for its third harmonic).
    N : float
        The field's gain at A → 0, 1/m.
    A, Nf : ndarray
        Amplitudes (m, increasing) and the field's describing function there (1/m).
    clearance : float
        m.
    model : {"exact_delay", "sampled"}
    beta_f : float
        The field's cubic coefficient, 1/m².
    heading_limit : bool
        The steering-rate limit on the heading (module docstring, "Trust").
    """
    balance = limited_balance(robot, controller, delta, A, Nf, model, heading_limit=heading_limit)
    V_star = balance.NV_critical / N
    beta = beta_f - balance.omega_critical**2 / (8.0 * V_star**2)
    b = balance
    return WobbleBranch(model, A, b.speeds, b.omegas, b.headings, b.rate_gains, b.third_harmonics, b.rate_harmonics, V_star,
                        b.omega_critical, beta, clearance, b.limiter_gains, b.limiter_lags, N, controller.hold, b.cascades)


def corridor_wobble(robot, controller, law: ForceLaw, L: float, tolerance: float | None = None, *, model: str = "sampled") -> Wobble:
    """The wobble of `robot` at its speed V in the middle of a corridor, and the speed limit for a tolerance (module docstring).

    Parameters
    ----------
    robot : parameters.Robot
        V, τ, k, W, `max_steering_rate`.
    controller : parameters.Controller
        T, hold, compute delay.
    law : ForceLaw
        The corridor's lateral law.
    L : float
        Half-width, m.
    tolerance : float, optional
        Largest acceptable lateral amplitude, m, in (0, L − W/2]; default a tenth of
        the clearance (`DEFAULT_TOLERANCE_FRACTION`).
    model : {"exact_delay", "sampled"}
        The loop model whose boundary closes the balance.

    Returns
    -------
    Wobble
    """
    if tolerance is not None:
        tolerance = check_number("tolerance", tolerance, 0.0, math.inf, unit="m")
    branch = corridor_branch(robot, controller, law, L, model=model)
    method = f"harmonic balance (describing functions of the field, the heading and the steering-rate limit) on the {model} loop"
    return _wobble_at(branch, robot.V, tolerance, method)


def wall_wobble(robot, controller, law: ForceLaw, alpha: float, tolerance: float | None = None, *, model: str = "sampled") -> Wobble:
    """The wobble of `robot` at its speed V beside a wall (the biased describing function, `wall_branch`), and the speed
    limit for a tolerance.

    Parameters
    ----------
    robot : parameters.Robot
        V, τ, k, W, `max_steering_rate`.
    controller : parameters.Controller
        T, hold, compute delay.
    law : ForceLaw
        The wall's lateral law.
    alpha : float
        Target angle from the wall normal, rad.
    tolerance : float, optional
        Largest acceptable lateral amplitude, m; default a tenth of the room d0 − W/2 the cycle has before it
        touches the wall (the branch's clearance).
    model : {"exact_delay", "sampled"}
        The loop model whose boundary closes the balance.

    Returns
    -------
    Wobble
    """
    if tolerance is not None:
        tolerance = check_number("tolerance", tolerance, 0.0, math.inf, unit="m")
    branch = wall_branch(robot, controller, law, alpha, model=model)
    method = (f"harmonic balance with the biased (dual-input) describing function of the field, the heading and the "
              f"steering-rate limit on the {model} loop")
    return _wobble_at(branch, robot.V, tolerance, method)


def _wobble_at(branch: WobbleBranch, V: float, tolerance: float | None, method: str) -> Wobble:
    """What a branch says at speed V (m/s) and for a tolerance (m; None: a tenth of the clearance)."""
    if tolerance is None:
        tolerance = DEFAULT_TOLERANCE_FRACTION * branch.clearance
    common = dict(criticality=branch.criticality, V_tolerance=branch.tolerance_speed(tolerance), tolerance=tolerance,
                  V_critical=branch.V_critical, V_fold=branch.fold_speed, method=method)
    limited = branch.limiter_gains is not None
    if limited:
        common["limiter"] = (None, None)
    stable = [c for c in branch.cycles_at(V) if c.stable]
    if limited and branch.fold_speed < V <= branch.V_critical:  # the limiter's lag bends the branch below V*
        unstable = [c for c in branch.cycles_at(V) if not c.stable]
        edge = f" beyond the unstable cycle of {unstable[0].amplitude:.3g} m" if unstable else ""
        reason = (f"below V* = {branch.V_critical:.4g} m/s a small start settles, but cycles exist down to V_fold = {branch.fold_speed:.4g} "
                  f"m/s (the yaw acceleration limit lags at finite amplitude): a start{edge} jumps to {'a large cycle' if stable else 'a wall'}; "
                  "--disturbance D says which for a start of D")
        return Wobble(None, None, None, not stable, third_harmonic=None, reason=reason, **common)
    jump = None
    if branch.criticality == "subcritical" and V > branch.fold_speed:
        unstable = [c for c in branch.cycles_at(V) if not c.stable]
        where = "a wall" if not stable else "a large cycle"
        if V <= branch.V_critical:
            edge = f" (beyond the unstable cycle of {unstable[0].amplitude:.3g} m)" if unstable else ""
            reason = (f"subcritical: between V_fold = {branch.fold_speed:.4g} and V* = {branch.V_critical:.4g} m/s a small start settles "
                      f"and a large one{edge} jumps to {where}; the describing function does not say which start the robot has")
            return Wobble(None, None, None, not stable, third_harmonic=None, reason=reason, **common)
        if not stable:
            return Wobble(None, None, None, True, third_harmonic=None,
                          reason=f"subcritical: past V* = {branch.V_critical:.4g} m/s the wobble jumps to a wall", **common)
        jump = f"subcritical: past V* = {branch.V_critical:.4g} m/s the wobble jumps to the large cycle"  # read below, as any cycle
    if V <= branch.V_critical:
        below = "below V*: the robot settles" if branch.criticality == "supercritical" else \
            "below V_fold: every start clear of the walls settles"
        return Wobble(0.0, 0.0, None, False, third_harmonic=None, reason=below, **common)
    if not stable:
        return Wobble(None, None, None, True, third_harmonic=None,
                      reason="no limit cycle clear of the walls: the wobble grows until the robot touches a wall", **common)
    cycle = stable[0]
    common["rate_harmonic"] = cycle.rate_harmonic
    if limited:
        common["limiter"] = (cycle.limiter_gain, cycle.limiter_lag)
    if not cycle.third_harmonic <= THIRD_HARMONIC_LIMIT:
        return Wobble(None, None, None, False, third_harmonic=cycle.third_harmonic,
                      reason=f"strong harmonics: predicted third harmonic {cycle.third_harmonic:.2f} of the fundamental "
                             f"(> {THIRD_HARMONIC_LIMIT:g}); the describing function is not trusted", **common)
    limit = rate_harmonic_limit(cycle.hold)
    if not cycle.rate_harmonic <= limit:
        return Wobble(None, None, None, False, third_harmonic=cycle.third_harmonic,
                      reason=f"the steering-rate limit shapes the heading (its third harmonic {cycle.rate_harmonic:.3f} of the "
                             f"fundamental > {limit:g}; rate describing function {cycle.rate_gain:.2f}): "
                             "the describing function is not trusted", **common)
    if cycle.cascade:
        shaped = reported_cycle(branch, V, cycle)
        if shaped is None:
            return Wobble(None, None, None, False, third_harmonic=cycle.third_harmonic,
                          reason="the steering-rate limit clips the smoother's input (the clipped command's flank changes faster than "
                                 "the yaw acceleration limit): the describing function is not trusted", **common)
        common["limiter"] = (shaped.limiter_gain, shaped.limiter_lag)
        common["method"] += "; where the steering-rate limit clips the smoother's input, that limit as the heading's rate limit"
        return Wobble(shaped.amplitude, shaped.heading_amplitude, shaped.omega, False, third_harmonic=shaped.third_harmonic,
                      reason="the steering-rate limit clips the smoother's input: taken as the heading's rate limit (the rate limiter's "
                             "describing function at g*max_steering_rate), the smoother on the command", **common)
    return Wobble(cycle.amplitude, cycle.heading_amplitude, cycle.omega, False, third_harmonic=cycle.third_harmonic, reason=jump, **common)
