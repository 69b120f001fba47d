"""How the validation's figures move with each threshold of the oscillation judge (docs/judge.md).

For every shipped map (depot, warehouse, tb3_sandbox) at CARMEL (the default robot) and at the small robot
(``--W 0.3 --V 0.5``), the map is analysed and driven once, as ``pfm-stability map MAP --validate N --seed S`` does
(`validation.map_drives.simulate_drives`: the same drives, seeded), and the drives are judged again
(`validation.map_drives.judge_drives`) with each threshold of `maps.judging.judge_thresholds.JudgeThresholds` moved down and up
(`VARIANTS`), the others at their defaults: recall, precision and specificity, each with its 95 % interval over the
drives (`map_drives._interval`, through `judge_drives`), and the episodes found.

**Only the judge side moves.** The prediction along the drives' own paths is made once, with the package's table
(`JUDGE`): the map's prediction uses the same judge — the loop driven along a path is judged by `maps.judging.episodes`
(episode periods, growth, amplitude, noise floor, smoothing, gaps, edges) and the window-edge relay is unstable when its
cycle reaches `amplitude_threshold` (`maps.deciding.decide`) — so a change to one of those fields in the package would move the
prediction too. What this measures is how much the agreement rests on where the judge draws the line for the drives.

``swing_points`` and ``wobble_factor`` move only the reported weave sizes (``false_alarm_swinging``, ``wobble``),
not the three figures, and are not varied; ``average_periods`` is varied on the judge only (it also defines the drives'
own paths, the prediction's, which stay).

    python experiments/judge_thresholds.py --out experiments/results [--drives 50] [--seed 0] [--quick]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import jsonable, output_dir, save_figure, write_json  # noqa: E402

from pfm_stability.maps.judging.judge_thresholds import JUDGE, JudgeThresholds  # noqa: E402

MAPS = ("depot", "warehouse", "tb3_sandbox")
"""The shipped maps (`cli.map.SHIPPED_MAPS`)."""
ROBOTS = {"CARMEL": (), "W 0.3, V 0.5": ("--W", "0.3", "--V", "0.5")}
"""The robots of docs/maps.md's tables: CARMEL's preset, and the small robot (command-line options)."""
FIGURES = ("recall", "precision", "specificity")
TARGETS = {"recall": 0.9, "precision": 0.8, "specificity": 0.8}
"""The targets where measured (docs/judge.md)."""
DRIVING_STEPS = 300
"""Progress steps a map's analysis and drives count for: they take a minute or so, a re-judging a fraction of a second."""


@dataclass(frozen=True)
class Variant:
    """One threshold moved: the field and its low and high values (the default is the table's).

    Attributes
    ----------
    field : str
        A `JudgeThresholds` field.
    low, high : float
        The values tried below and above the default.
    why : str
        Why these values.
    """

    field: str
    low: float
    high: float
    why: str


VARIANTS = (
    Variant("episode_periods", 2, 4, "integer periods: the neighbours"),
    Variant("growth_efolds", 0.5, 1.5, "x0.5, x1.5"),
    Variant("amplitude_threshold", 0.010, 0.020, "just past the stable ripple's 1.3 cm and at the rate-limited cycle's 2 cm"),
    Variant("noise_floor", 0.0025, 0.0075, "x0.5, x1.5"),
    Variant("average_periods", 0.75, 1.25, "x0.75, x1.25 (x0.5 removes half the weave: no oscillation left to judge)"),
    Variant("smoothing_periods", 0.0625, 0.25, "P/16, P/4"),
    Variant("edge_periods", 0.25, 0.75, "x0.5, x1.5"),
    Variant("min_gap_periods", 0.125, 0.375, "x0.5, x1.5"),
    Variant("max_gap_periods", 0.75, 1.5, "x0.75, x1.5 (below P/2 nothing is an oscillation)"),
    Variant("lead_periods", 0.0, 0.5, "the first turning point itself, half a period before it"),
    Variant("match_distance", 0.25, 1.0, "x0.5, x2 (at least W: CARMEL's 0.8 m holds below it)"),
    Variant("start_periods", 0.5, 1.5, "x0.5, x1.5"),
    Variant("start_share", 0.125, 0.375, "x0.5, x1.5"),
    Variant("end_periods", 2.0, 4.0, "integer periods: the neighbours of episode_periods"),
    Variant("match_window", 0.25, 0.75, "Λ/4, 3Λ/4"),
)
"""Each threshold varied, with its low and high values; the others at `JUDGE`'s."""


@dataclass(frozen=True)
class Judged:
    """The figures of one re-judging of a map's drives.

    Attributes
    ----------
    recall, precision, specificity : float or None
        By length (None: nothing to measure).
    recall_interval, precision_interval, specificity_interval : tuple of float or None
        Their 95 % intervals over the drives.
    episodes : int
        Episodes found.
    episode_length : float
        Their length along the drives' own paths, m.
    lengths : dict
        `DriveValidation.lengths`.
    """

    recall: float | None
    precision: float | None
    specificity: float | None
    recall_interval: tuple | None
    precision_interval: tuple | None
    specificity_interval: tuple | None
    episodes: int
    episode_length: float
    lengths: dict

    def to_dict(self) -> dict:
        """JSON form (without the lengths but the episodes', the measured and the predicted-unstable)."""
        out = {k: v for k, v in dataclasses.asdict(self).items() if k != "lengths"}
        out.update({k: self.lengths[k] for k in ("drive_paths_driven", "predicted_unstable_driven", "quiet_driven")})
        return jsonable(out)


def judged(runs, thresholds: JudgeThresholds = JUDGE) -> Judged:
    """`runs` (`map_drives.DriveRuns`) judged with `thresholds` (`map_drives.judge_drives`): its figures."""
    from pfm_stability.validation.map_drives import judge_drives

    v = judge_drives(runs, thresholds)
    return Judged(v.recall, v.precision, v.specificity, v.recall_interval, v.precision_interval, v.specificity_interval,
                  v.counts["episodes"], v.lengths["episode"], v.lengths)


def analysis_of(map_name: str, robot: tuple, drives: int, seed: int):
    """The analysis ``pfm-stability map MAP ROBOT --validate DRIVES --seed SEED`` makes (`cli.map.run`'s steps)."""
    from pfm_stability.cli import build_parser
    from pfm_stability.cli.map import map_path
    from pfm_stability.cli.options import resolve_law, resolve_parameters
    from pfm_stability.maps.analysis import analyze_map, check_map_law
    from pfm_stability.maps.reading.occupancy import load_map

    args = build_parser().parse_args(["map", map_name, *robot, "--validate", str(drives), "--seed", str(seed)])
    params = resolve_parameters(args)
    law, _ = resolve_law(args, params)
    check_map_law(law)
    return analyze_map(load_map(map_path(args.map)), params.robot, params.controller, law, model=args.model,
                       unknown=args.unknown, corridors=args.wobble is not None, cell_size=args.cell_size,
                       min_length=args.min_length, warn=lambda line: None)


def settings() -> list:
    """(field, label, value, thresholds) of every judging: the default, then each `VARIANTS` low and high."""
    out = [("default", "default", None, JUDGE)]
    for v in VARIANTS:
        out += [(v.field, "low", v.low, JUDGE.replace(**{v.field: v.low})),
                (v.field, "high", v.high, JUDGE.replace(**{v.field: v.high}))]
    return out


def run(out, drives: int = 50, seed: int = 0, quick: bool = False) -> dict:
    """Drive every map at both robots once, re-judge with every setting, write JSON, Markdown and PNG into `out`."""
    from tqdm import tqdm

    from pfm_stability.validation.map_drives import simulate_drives

    out = output_dir(out)
    maps, variants = (MAPS[:1], settings()[:5]) if quick else (MAPS, settings())
    drives = 6 if quick else drives
    results = []
    with tqdm(total=len(maps) * len(ROBOTS) * (DRIVING_STEPS + len(variants)), desc="judge thresholds", unit="step") as bar:
        for map_name in maps:
            for robot_name, robot in ROBOTS.items():
                bar.set_postfix_str(f"{map_name}, {robot_name}: driving")
                started = time.perf_counter()
                analysis = analysis_of(map_name, robot, drives, seed)
                runs = simulate_drives(analysis, drives, seed=seed)
                simulated = time.perf_counter() - started
                bar.update(DRIVING_STEPS)
                rows = []
                for field, label, value, thresholds in variants:
                    bar.set_postfix_str(f"{map_name}, {robot_name}: {field} {label}")
                    rows.append({"field": field, "setting": label, "value": value, **judged(runs, thresholds).to_dict()})
                    bar.update()
                results.append({"map": map_name, "robot": robot_name, "drives": len(runs.drives), "period": runs.period,
                                "seconds_driving": simulated, "rows": rows})
    data = {"inputs": {"drives": drives, "seed": seed, "maps": list(maps), "robots": {k: list(v) for k, v in ROBOTS.items()},
                       "defaults": JUDGE.to_dict(), "variants": [dataclasses.asdict(v) for v in VARIANTS]},
            "note": "only the judge side moved: the prediction along the drives' own paths is the package's (JUDGE)",
            "runs": results, "mixed": mixed(results)}
    write_json(out / "judge_thresholds.json", data)
    (out / "judge_thresholds.md").write_text(markdown(data))
    save_figure(figure(data), out / "judge_thresholds.png")
    return data


STEP = 0.02
"""A figure that moves by at least this much (2 percentage points) from the default counts as moved (`mixed`)."""


def mixed(results: list) -> list:
    """The settings that raise a figure on one map and robot and lower one on another, by at least `STEP` (a figure
    with nothing to measure at the default that a setting gives below its target — episodes no drive had, missed —
    counts as lowered): (field, setting, value, the runs helped, the runs hurt)."""
    out = []
    for k, (field, label, value, _) in enumerate(settings()):
        if field == "default":
            continue
        helped, hurt = [], []
        for r in results:
            rows = {(row["field"], row["setting"]): row for row in r["rows"]}
            if (field, label) not in rows:
                continue
            row, base = rows[(field, label)], rows[("default", "default")]
            for name in FIGURES:
                if row[name] is None:
                    continue
                if base[name] is None:
                    if row[name] < TARGETS[name]:
                        hurt.append(f"{r['map']}, {r['robot']}: {name} n/a -> {100 * row[name]:.0f} % ({row['episodes']} episodes)")
                    continue
                delta = row[name] - base[name]
                where = f"{r['map']}, {r['robot']}: {name} {100 * base[name]:.0f} -> {100 * row[name]:.0f} %"
                if delta >= STEP:
                    helped.append(where)
                elif delta <= -STEP:
                    hurt.append(where)
        runs_helped, runs_hurt = ({h.split(":")[0] for h in side} for side in (helped, hurt))
        if any(a != b for a in runs_helped for b in runs_hurt):  # up on one map or robot, down on another
            out.append({"field": field, "setting": label, "value": value, "helped": helped, "hurt": hurt})
    return out


def _pct(value, interval) -> str:
    """A figure and its interval, in %."""
    if value is None:
        return "n/a"
    if interval is None:
        return f"{100 * value:.0f}"
    return f"{100 * value:.0f} ({100 * interval[0]:.0f}–{100 * interval[1]:.0f})"


def markdown(data: dict) -> str:
    """The results as Markdown: per map and robot, every setting's figures with intervals and episodes."""
    inp = data["inputs"]
    lines = [f"# The judge's thresholds: sensitivity ({inp['drives']} drives per map and robot, seed {inp['seed']})", "",
             "Written by `python experiments/judge_thresholds.py --out experiments/results` (docs/judge.md). Each threshold "
             "moved alone, the others at their defaults; the same drives re-judged. Recall, precision, specificity in % "
             "with their 95 % interval over the drives; n/a: nothing to measure. **Only the judge side moved**: the "
             "prediction along the drives' paths is the package's.", ""]
    for r in data["runs"]:
        lines += [f"## {r['map']}, {r['robot']} ({r['drives']} drives, P = {r['period']:.2f} s)" if r["period"] else
                  f"## {r['map']}, {r['robot']} ({r['drives']} drives)", "",
                  "| threshold | setting | value | episodes (m) | recall | precision | specificity | measured m |",
                  "| --- | --- | --- | --- | --- | --- | --- | --- |"]
        defaults = JUDGE.to_dict()
        for row in r["rows"]:
            value = row["value"] if row["field"] != "default" else ""
            if row["field"] == "end_periods" and row["setting"] == "default":
                value = defaults["end_periods"]
            lines.append(f"| {row['field']} | {row['setting']} | {value} | {row['episodes']} ({row['episode_length']:.1f}) | "
                         f"{_pct(row['recall'], row['recall_interval'])} | {_pct(row['precision'], row['precision_interval'])} | "
                         f"{_pct(row['specificity'], row['specificity_interval'])} | {row['drive_paths_driven']:.0f} |")
        lines.append("")
    lines += ["## Settings that help one map and hurt another", "",
              f"A figure moved by at least {100 * STEP:.0f} points from the default, up on one map or robot and down on another.", ""]
    if not data["mixed"]:
        lines.append("None.")
    for m in data["mixed"]:
        lines.append(f"- `{m['field']}` {m['setting']} ({m['value']}): up — {'; '.join(m['helped'])}; down — {'; '.join(m['hurt'])}")
    return "\n".join(lines) + "\n"


def figure(data: dict):
    """Per threshold (rows) and figure (columns): each map and robot's figure with its interval at low, default and
    high (x), one colour per map and robot."""
    import matplotlib.pyplot as plt

    fields = [v["field"] for v in data["inputs"]["variants"]]
    runs = [r for r in data["runs"] if any(row[f] is not None for row in r["rows"] for f in FIGURES)]
    fig, axes = plt.subplots(len(fields), 3, figsize=(13, 2.1 * len(fields) + 1), sharey=True, squeeze=False)
    colours = plt.get_cmap("tab10")
    for i, field in enumerate(fields):
        for j, name in enumerate(FIGURES):
            ax = axes[i, j]
            for c, r in enumerate(runs):
                rows = {row["setting"]: row for row in r["rows"] if row["field"] in (field, "default")}
                xs, ys, lo, hi = [], [], [], []
                for x, setting in enumerate(("low", "default", "high")):
                    row = rows.get(setting)
                    if row is None or row[name] is None:
                        continue
                    interval = row[f"{name}_interval"] or (row[name], row[name])
                    xs.append(x + 0.08 * (c - (len(runs) - 1) / 2))
                    ys.append(100 * row[name])
                    lo.append(100 * (row[name] - interval[0]))
                    hi.append(100 * (interval[1] - row[name]))
                if xs:
                    ax.errorbar(xs, ys, yerr=[lo, hi], marker="o", ms=4, capsize=2, lw=1, color=colours(c),
                                label=f"{r['map']}, {r['robot']}")
            variant = next(v for v in data["inputs"]["variants"] if v["field"] == field)
            default = data["inputs"]["defaults"][field]
            default = data["inputs"]["defaults"]["episode_periods"] if default is None else default
            ax.set_xticks([0, 1, 2], [f"{variant['low']:g}", f"{default:g}", f"{variant['high']:g}"])
            ax.set_xlim(-0.5, 2.5)
            ax.set_ylim(-5, 105)
            ax.axhline(100 * TARGETS[name], color="0.6", lw=0.8, ls=":")
            ax.grid(alpha=0.3)
            if i == 0:
                ax.set_title(f"{name} (%; target dotted)")
            if j == 0:
                ax.set_ylabel(field, fontsize=9)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    for ax in axes.flat:
        h, lab = ax.get_legend_handles_labels()
        if len(lab) > len(labels):
            handles, labels = h, lab
    silent = [f"{r['map']}, {r['robot']}" for r in data["runs"] if r not in runs]
    fig.suptitle(f"The judge's thresholds, each moved alone: low, default, high ({data['inputs']['drives']} drives per map "
                 f"and robot, seed {data['inputs']['seed']}; 95 % intervals over the drives; only the judge side moved)"
                 + (f"\nno figure at any setting: {'; '.join(silent)}" if silent else ""), y=0.998, fontsize=11)
    fig.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, 0.984), ncol=min(4, max(1, len(labels))), fontsize=9)
    fig.tight_layout(rect=(0, 0, 1, 0.98))
    return fig


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(Path(__file__).resolve().parent / "results"))
    parser.add_argument("--drives", type=int, default=50, help="drives per map and robot (default 50)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--quick", action="store_true", help="one map, six drives, the first two thresholds")
    args = parser.parse_args(argv)
    data = run(args.out, drives=args.drives, seed=args.seed, quick=args.quick)
    print(json.dumps(data["mixed"], indent=1) if data["mixed"] else "no setting helps one map and hurts another")
    return 0


if __name__ == "__main__":
    sys.exit(main())
