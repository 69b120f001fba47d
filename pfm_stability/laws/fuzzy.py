"""A small Mamdani fuzzy inference system and the two controllers of the DFAPF paper.

The dynamic fuzzy artificial potential field (DFAPF paper, "Dynamic fuzzy artificial
potential field", Tables 1–2) schedules the repulsion gains η and K_V with two
two-input, one-output fuzzy controllers. The paper gives the universes, the linguistic
sets and the rule tables; everything else is our documented reconstruction
(docs/velocity_and_fuzzy.md, choices R1–R7):

* R1: Mamdani; AND = min, implication = min, aggregation = max, centroid
  defuzzification on 1001 points of the output universe;
* R2: Gaussian sets uniformly spaced, σ = 0.8·spacing/(2√(2 ln 2)) (a full width at
  half maximum of 0.8 spacings);
* R3: the bearing θ is periodic (distances between θ and a centre are wrapped).

The tables are data (``data/fuzzy/dfapf.yaml``), read by `load_dfapf`. Besides the
output, `FuzzySystem.evaluate_with_gradient` gives the exact derivatives of the
discretised centroid with respect to both inputs (the aggregated membership at each
output point is a max–min of smooth memberships, so it is differentiable almost
everywhere: forward-mode through the active branch). numpy only; the data file is read
by the package's one YAML reader (`pfm_stability.io.yaml_files`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..checks import check_choice, check_integer
from ..io.yaml_files import read_yaml

__all__ = [
    "DFAPF_FILE",
    "FWHM_FRACTION",
    "OUTPUT_POINTS",
    "DfapfControllers",
    "FuzzySystem",
    "FuzzyVariable",
    "load_dfapf",
    "symmetrized_rows",
]

FWHM_FRACTION = 0.8
"""Full width at half maximum of each Gaussian set, in set spacings (R2)."""

OUTPUT_POINTS = 1001
"""Points of the output universe on which the centroid is taken (R1)."""

DFAPF_FILE = Path(__file__).resolve().parent.parent / "data" / "fuzzy" / "dfapf.yaml"
"""The universes and rule tables of the DFAPF paper's two controllers."""

_SIGMA_PER_FWHM = 1.0 / (2.0 * math.sqrt(2.0 * math.log(2.0)))
_CHUNK = 2048


@dataclass(frozen=True)
class FuzzyVariable:
    """A linguistic variable: a universe and Gaussian sets uniformly spaced on it.

    Parameters
    ----------
    name : str
        The variable's name (``"theta"``, ``"d"``).
    low, high : float
        The universe, in `unit`.
    sets : tuple of str
        Set names in the order of `centres`.
    centres : tuple of float
        Set centres, uniformly spaced (a periodic universe: spaced by
        (high − low)/len(sets), wrapping round).
    periodic : bool
        True for an angle: distances to a centre are taken modulo (high − low).
    unit : str
        Unit of the universe (``"deg"``, ``"m"``, ``"1"``).
    """

    name: str
    low: float
    high: float
    sets: tuple
    centres: tuple
    periodic: bool = False
    unit: str = "1"

    def __post_init__(self):
        if not (math.isfinite(self.low) and math.isfinite(self.high) and self.low < self.high):
            raise ValueError(f"{self.name}: the universe [low, high] must be finite with low < high; got [{self.low}, {self.high}]")
        if len(self.sets) != len(self.centres) or len(self.sets) < 2 or len(set(self.sets)) != len(self.sets):
            raise ValueError(f"{self.name}: sets must be at least 2 distinct names, one per centre")
        c = np.asarray(self.centres, dtype=float)
        step = np.diff(c)
        if not np.allclose(step, self.spacing, rtol=1e-9, atol=0.0):
            raise ValueError(f"{self.name}: centres must be uniformly spaced by {self.spacing:g} (R2); got {list(self.centres)}")
        if not self.periodic and not (math.isclose(c[0], self.low) and math.isclose(c[-1], self.high)):
            raise ValueError(f"{self.name}: the first and last centres must be the ends of the universe [{self.low:g}, {self.high:g}]")

    @property
    def period(self) -> float:
        """high − low: the period of a periodic universe."""
        return self.high - self.low

    @property
    def spacing(self) -> float:
        """Distance between neighbouring centres, in `unit`."""
        if self.periodic:
            return self.period / len(self.sets)
        return (self.high - self.low) / (len(self.sets) - 1)

    @property
    def sigma(self) -> float:
        """Gaussian σ of every set, in `unit`: FWHM_FRACTION·spacing/(2√(2 ln 2)) (R2)."""
        return FWHM_FRACTION * self.spacing * _SIGMA_PER_FWHM

    def offsets(self, x):
        """x − centre for every set, shape x.shape + (n_sets,) (wrapped to [−period/2, period/2) when periodic).

        Parameters
        ----------
        x : float or ndarray
            Values, in the variable's unit.
        """
        x = np.asarray(x, dtype=float)[..., None]
        dx = x - np.asarray(self.centres, dtype=float)
        if self.periodic:
            dx = (dx + 0.5 * self.period) % self.period - 0.5 * self.period
        return dx

    def memberships(self, x):
        """Membership of x in every set, shape x.shape + (n_sets,), in [0, 1].

        Parameters
        ----------
        x : float or ndarray
            Values, in the variable's unit.
        """
        dx = self.offsets(x)
        return np.exp(-0.5 * (dx / self.sigma) ** 2)

    def membership_slopes(self, x):
        """(μ, dμ/dx) for every set, each of shape x.shape + (n_sets,); dμ/dx in 1/`unit`.

        Parameters
        ----------
        x : float or ndarray
            Values, in the variable's unit.
        """
        dx = self.offsets(x)
        mu = np.exp(-0.5 * (dx / self.sigma) ** 2)
        return mu, -dx / self.sigma**2 * mu

    def clip(self, x):
        """x limited to the universe (a periodic universe is never clipped).

        Parameters
        ----------
        x : float or ndarray
            Values, in the variable's unit.
        """
        x = np.asarray(x, dtype=float)
        return x if self.periodic else np.clip(x, self.low, self.high)


@dataclass(frozen=True)
class FuzzySystem:
    """A two-input, one-output Mamdani system (R1): min, min, max, centroid on `points` points.

    Parameters
    ----------
    name : str
    first, second : FuzzyVariable
        The inputs: rows and columns of `table`.
    output : FuzzyVariable
    table : tuple of tuple of int
        table[i][j] = index of the output set fired by (first set i AND second set j).
    points : int
        Points of the output universe for the centroid (1001, R1).
    """

    name: str
    first: FuzzyVariable
    second: FuzzyVariable
    output: FuzzyVariable
    table: tuple
    points: int = OUTPUT_POINTS

    def __post_init__(self):
        check_integer("points", self.points, 3, 10**6)
        t = np.asarray(self.table)
        if t.shape != (len(self.first.sets), len(self.second.sets)):
            raise ValueError(f"{self.name}: the rule table must have {len(self.first.sets)} rows and {len(self.second.sets)} columns; got shape {t.shape}")
        if t.min() < 0 or t.max() >= len(self.output.sets):
            raise ValueError(f"{self.name}: rule outputs must index the {len(self.output.sets)} output sets")

    def _grid(self):
        y = np.linspace(self.output.low, self.output.high, self.points)
        return y, self.output.memberships(y).T  # (n_out, points)

    def _strengths(self, x1, x2, slopes: bool):
        """Per output set: the strength W_k = max over its rules of min(μ1_i, μ2_j), and dW_k/dx1, dW_k/dx2."""
        x1, x2 = np.broadcast_arrays(np.asarray(x1, dtype=float), np.asarray(x2, dtype=float))
        x1, x2 = self.first.clip(x1), self.second.clip(x2)
        m1, s1 = self.first.membership_slopes(x1)
        m2, s2 = self.second.membership_slopes(x2)
        first_wins = m1[..., :, None] <= m2[..., None, :]  # the min is the first input's membership
        w = np.where(first_wins, m1[..., :, None], m2[..., None, :])
        dw1 = np.where(first_wins, s1[..., :, None], 0.0)
        dw2 = np.where(first_wins, 0.0, s2[..., None, :])
        t = np.asarray(self.table)
        n_out = len(self.output.sets)
        shape = x1.shape
        W = np.zeros(shape + (n_out,))
        G1 = np.zeros(shape + (n_out,))
        G2 = np.zeros(shape + (n_out,))
        flat = w.reshape(shape + (-1,))
        f1, f2 = dw1.reshape(shape + (-1,)), dw2.reshape(shape + (-1,))
        for k in range(n_out):
            rules = np.flatnonzero(t.ravel() == k)
            if rules.size == 0:
                continue
            sub = flat[..., rules]
            best = np.argmax(sub, axis=-1)[..., None]
            W[..., k] = np.take_along_axis(sub, best, -1)[..., 0]
            if slopes:
                G1[..., k] = np.take_along_axis(f1[..., rules], best, -1)[..., 0]
                G2[..., k] = np.take_along_axis(f2[..., rules], best, -1)[..., 0]
        return W, G1, G2

    def evaluate(self, x1, x2):
        """The crisp output at (x1, x2) (arrays broadcast); inputs outside a non-periodic universe are clipped to it.

        Parameters
        ----------
        x1, x2 : float or ndarray
            The two inputs, in their variables' units.
        """
        return self.evaluate_with_gradient(x1, x2, slopes=False)[0]

    def evaluate_with_gradient(self, x1, x2, *, slopes: bool = True):
        """(y, ∂y/∂x1, ∂y/∂x2) of the discretised centroid, exact almost everywhere (forward mode).

        The aggregated membership at each output point is max_k min(W_k, μ_k(y)),
        so its derivative is dW_k/dx where W_k is the active term and 0 where the
        output set's own membership is. Derivatives are one-sided at the (measure-zero)
        points where two branches tie, and 0 in an input clipped to its universe.
        Arrays broadcast; they are evaluated in chunks of `_CHUNK` points (memory).

        Parameters
        ----------
        x1, x2 : float or ndarray
            The two inputs, in their variables' units.
        slopes : bool, optional
            Whether to return the partial derivatives (False: None in their place).
        """
        a, b = np.broadcast_arrays(np.asarray(x1, dtype=float), np.asarray(x2, dtype=float))
        fa, fb = a.ravel(), b.ravel()
        parts = [self._chunk(fa[i:i + _CHUNK], fb[i:i + _CHUNK], slopes) for i in range(0, max(fa.size, 1), _CHUNK)]
        out = [np.concatenate([p[j] for p in parts]).reshape(a.shape) if slopes or j == 0 else None for j in range(3)]
        if a.ndim == 0:
            out = [None if o is None else float(o) for o in out]
        return tuple(out)

    def _chunk(self, x1, x2, slopes):
        """`evaluate_with_gradient` on 1-D arrays x1, x2 of the same length."""
        W, G1, G2 = self._strengths(x1, x2, slopes)
        y, mu_out = self._grid()
        cap = W[..., :, None] < mu_out  # (…, n_out, points): the strength is the active min
        vals = np.where(cap, W[..., :, None], mu_out)
        k = np.argmax(vals, axis=-2)[..., None, :]
        agg = np.take_along_axis(vals, k, -2)[..., 0, :]
        area = agg.sum(-1)
        moment = (agg * y).sum(-1)
        out = moment / area
        if not slopes:
            return out, None, None
        active = np.take_along_axis(cap, k, -2)[..., 0, :]
        grads = []
        for G in (G1, G2):
            dagg = np.where(active, np.take_along_axis(np.broadcast_to(G[..., :, None], vals.shape), k, -2)[..., 0, :], 0.0)
            grads.append(((dagg * y).sum(-1) - out * dagg.sum(-1)) / area)
        x1b, x2b = np.broadcast_arrays(np.asarray(x1, dtype=float), np.asarray(x2, dtype=float))
        inside1 = self.first.periodic | ((x1b > self.first.low) & (x1b < self.first.high))
        inside2 = self.second.periodic | ((x2b > self.second.low) & (x2b < self.second.high))
        return out, np.where(inside1, grads[0], 0.0), np.where(inside2, grads[1], 0.0)

    def output_range(self, samples: int = 61) -> tuple[float, float]:
        """(min, max) of the output over a `samples` × `samples` grid of the inputs (R6: the centroid compresses the universe).

        Parameters
        ----------
        samples : int, optional
            Grid points per input.
        """
        a = np.linspace(self.first.low, self.first.high, samples)
        b = np.linspace(self.second.low, self.second.high, samples)
        out = self.evaluate(a[:, None], b[None, :])
        return float(out.min()), float(out.max())


def symmetrized_rows(rows: dict, side: str) -> dict:
    """The rule rows of a θ-table made left–right symmetric: each mirrored pair takes the rows of `side`.

    Rows are keyed by the bearing sets NH, NB, NM, NS, Z, PS, PM, PB. With
    ``side="negative"`` the rows NB, NM, NS are kept and copied to PB, PM, PS;
    with ``side="positive"`` the reverse. NH (±180°) and Z (0°) mirror onto
    themselves. The columns (distance, ΔV) are not mirrored: neither changes sign
    when the obstacle is mirrored about the direction of motion.

    Parameters
    ----------
    rows : dict
        The table's rule rows by bearing set.
    side : str
        ``"negative"`` or ``"positive"``: whose rows are kept.
    """
    check_choice("symmetrize", side, ("negative", "positive"))
    out = dict(rows)
    for n, p in (("NB", "PB"), ("NM", "PM"), ("NS", "PS")):
        if side == "negative":
            out[p] = rows[n]
        else:
            out[n] = rows[p]
    return out


@dataclass(frozen=True)
class DfapfControllers:
    """The DFAPF paper's two controllers, in SI inputs.

    Attributes
    ----------
    eta : FuzzySystem
        Controller 1 (Table 1): η from the obstacle bearing θ (deg) and distance d (m).
    K_V : FuzzySystem
        Controller 2 (Table 2): K_V from θ (deg) and the normalised relative speed ΔV.
    symmetrize : str or None
        Which side's rows were mirrored onto the other (`symmetrized_rows`), or None.
    """

    eta: FuzzySystem
    K_V: FuzzySystem
    symmetrize: str | None = None

    def eta_of(self, d, theta):
        """η at distance d (m) and bearing θ (rad, counter-clockwise positive).

        Parameters
        ----------
        d : float or ndarray
            Distance, m.
        theta : float or ndarray
            Bearing, rad, counter-clockwise positive.
        """
        return self.eta.evaluate(np.degrees(theta), d)

    def eta_with_slopes(self, d, theta):
        """(η, ∂η/∂d in 1/m, ∂η/∂θ in 1/rad) at d (m), θ (rad).

        Parameters
        ----------
        d : float or ndarray
            Distance, m.
        theta : float or ndarray
            Bearing, rad, counter-clockwise positive.
        """
        y, g_theta, g_d = self.eta.evaluate_with_gradient(np.degrees(theta), d)
        return y, g_d, g_theta * (180.0 / math.pi)

    def K_V_of(self, dV, theta):
        """K_V at normalised relative speed ΔV (clipped to [−1, 1], R7) and bearing θ (rad).

        Parameters
        ----------
        dV : float or ndarray
            Normalised relative speed ΔV, dimensionless.
        theta : float or ndarray
            Bearing, rad.
        """
        return self.K_V.evaluate(np.degrees(theta), dV)


def _variable(name: str, spec: dict) -> FuzzyVariable:
    try:
        low, high = (float(v) for v in spec["range"])
        return FuzzyVariable(
            name, low, high, tuple(str(s) for s in spec["sets"]), tuple(float(c) for c in spec["centres"]),
            bool(spec.get("periodic", False)), str(spec.get("unit", "1")),
        )
    except (KeyError, TypeError) as exc:
        raise ValueError(f"fuzzy variable {name}: needs range, sets and centres ({exc})") from None


def _system(name: str, spec: dict, variables: dict, side: str | None) -> FuzzySystem:
    try:
        first, second = (variables[v] for v in spec["inputs"])
        output = variables[spec["output"]]
        rows = {str(k): list(v) for k, v in spec["rules"].items()}
    except (KeyError, TypeError, ValueError) as exc:
        raise ValueError(f"fuzzy controller {name}: needs inputs (two variables), output and rules ({exc})") from None
    if sorted(rows) != sorted(first.sets):
        raise ValueError(f"fuzzy controller {name}: rule rows must be exactly {', '.join(first.sets)}")
    if side is not None:
        rows = symmetrized_rows(rows, side)
    table = []
    for r in first.sets:
        if len(rows[r]) != len(second.sets):
            raise ValueError(f"fuzzy controller {name}: row {r} must have {len(second.sets)} entries")
        try:
            table.append(tuple(output.sets.index(str(o)) for o in rows[r]))
        except ValueError:
            raise ValueError(f"fuzzy controller {name}: row {r} names an output set not in {', '.join(output.sets)}") from None
    return FuzzySystem(name, first, second, output, tuple(table))


def load_dfapf(symmetrize=False, path=None) -> DfapfControllers:
    """The DFAPF paper's two controllers, read from ``data/fuzzy/dfapf.yaml`` (or `path`).

    Parameters
    ----------
    symmetrize : bool or str
        False: the tables as printed (left–right asymmetric). True or
        ``"negative"``: the N-rows (obstacle on the right) are copied onto the
        P-rows; ``"positive"``: the reverse (`symmetrized_rows`). True means
        "negative" because in Table 1 the N-rows decrease monotonically with |θ| at
        d = ZD (LA, MA, SA, SA, NA) while the P-rows do not (LA, NA, SA, SA, NA).
    path : str or Path, optional
        Another file of the same layout.
    """
    if symmetrize is True:
        side = "negative"
    elif symmetrize is False or symmetrize is None:
        side = None
    else:
        side = check_choice("symmetrize", symmetrize, ("negative", "positive"))
    tables = read_yaml(path or DFAPF_FILE, "fuzzy tables")
    data = tables.data
    try:
        items = data["variables"].items()
        controllers = data["controllers"]
        eta, kv = controllers["eta"], controllers["K_V"]
    except (KeyError, TypeError, AttributeError) as exc:
        raise tables.error(f"needs variables and controllers eta and K_V ({exc})") from None
    variables = {}
    for name, spec in items:
        try:
            variables[name] = _variable(name, spec)
        except ValueError as exc:
            raise tables.error(str(exc), ("variables", name)) from None
    systems = []
    for name, spec in (("eta", eta), ("K_V", kv)):
        try:
            systems.append(_system(name, spec, variables, side))
        except ValueError as exc:
            raise tables.error(str(exc), ("controllers", name)) from None
    return DfapfControllers(*systems, side)
