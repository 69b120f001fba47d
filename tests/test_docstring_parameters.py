"""House style (docs/architecture.md): a public docstring's numpydoc ``Parameters`` section
matches the signature it documents.

`tests/test_docstrings.py` checks that every public object has a docstring; this module checks
that the docstring is *right* about the arguments: every documented name is a parameter, every
parameter is documented, and they come in the signature's order. A renamed, added or removed
argument whose docstring was not updated fails here.

What is checked (public = named in some module's ``__all__``; each object once, at the module
that defines it):

* functions, and the methods, static and class methods a public class defines itself: the
  ``Parameters`` section against ``inspect.signature`` (``self``/``cls`` excluded; ``*args`` and
  ``**kwargs`` only if the docstring documents them, as ``*args`` or ``args``). A method without
  a docstring of its own shows the one it overrides (``help``, `inspect.getdoc`): that docstring is
  checked where it is written, and the override must take the same parameters;
* classes: the constructor's parameters (``inspect.signature(cls)``). A class documents them in
  ``Parameters`` (checked as above) or, a dataclass, in ``Attributes``: there every constructor
  parameter must appear, in order, and every listed name must be an attribute of the class
  (fields, properties and class attributes may be listed besides the constructor's);
* names are identifiers: a prose line inside ``Parameters`` is parsed by numpydoc as a
  parameter named by the line and is reported (prose belongs above the section).

Exceptions whose constructor is the builtin one have no signature to check.
``KNOWN_MISMATCHES`` lists the mismatches of modules whose docstrings another piece of work
owns; remove an entry when its docstring is fixed (an entry that no longer mismatches is
harmless; a new mismatch anywhere fails).
"""

import dataclasses
import importlib
import inspect
import pkgutil
import warnings

import pytest
from numpydoc.docscrape import NumpyDocString

import pfm_stability

MODULES = sorted(
    m.name for m in pkgutil.walk_packages(pfm_stability.__path__, "pfm_stability.") if not m.name.endswith("__main__")
)

# module:qualname of mismatches outside the docstrings this test was written with (report/, cli/, io/,
# laws/, parameters.py, checks.py, plots/, models/holonomic*.py, models/base.py): fix, then delete the line.
KNOWN_MISMATCHES = frozenset({
    *(f"pfm_stability.checks:{q}" for q in ("check_choice", "check_integer", "check_output_dir",
        "check_positive_axis", "describe_range")),
    *(f"pfm_stability.cli:{q}" for q in ("main", "unknown_options")),
    *(f"pfm_stability.cli.formatting:{q}" for q in ("number", "percent", "table")),
    *(f"pfm_stability.cli.options:{q}" for q in ("add_family_options", "add_law_options", "add_parameter_options",
        "check", "describe", "input_file", "integer", "number", "output_path", "resolve_family", "resolve_law",
        "resolve_parameters", "shipped_or_given", "typed")),
    *(f"pfm_stability.cli.render:{q}" for q in ("render_derivation_latex", "render_derivation_text",
        "render_door_text", "render_map_text", "render_markdown", "render_parameter_sweep_text", "render_text",
        "render_traps_text")),
    *(f"pfm_stability.cli.render_families:{q}" for q in ("equilibrium_notes", "family_scenario", "family_tail")),
    *(f"pfm_stability.cli.render_runs:{q}" for q in ("render_simulation_text", "render_sweep_text",
        "render_validation_text")),
    *(f"pfm_stability.io.config:{q}" for q in ("read_yaml",)),
    *(f"pfm_stability.io.files:{q}" for q in ("atomic_directory", "check_writable", "open_new", "save_figure",
        "write_text")),
    *(f"pfm_stability.io.nav2:{q}" for q in ("Nav2Values", "is_nav2")),
    *(f"pfm_stability.io.serialize:{q}" for q in ("dumps", "json_array", "json_default", "json_number", "json_ready",
        "parse_json_number")),
    *(f"pfm_stability.laws.effective_force:{q}" for q in ("GridWallLaw.force", "GridWallLaw.lumped",
        "GridWallLaw.slope", "GridWallLaw.window_force", "GridWallLaw.with_scale", "check_window_cells",
        "corridor_lateral_force", "working_range")),
    *(f"pfm_stability.laws.fields:{q}" for q in ("Branch", "Branch.gain", "Branch.nearest_crossing", "Branch.point",
        "GnronLaw", "check_law_parameters", "finite_goal_gain", "make_law")),
    *(f"pfm_stability.laws.force_law:{q}" for q in ("ForceLaw.distance_for", "ForceLaw.equivalent_f",
        "ForceLaw.force", "ForceLaw.goal_force", "ForceLaw.goal_slope", "ForceLaw.local_exponent", "ForceLaw.slope",
        "ForceLaw.wall_balance", "ForceLaw.wall_ratio", "ForceLaw.wall_ratio_slope", "ForceLaw.with_scale",
        "PowerLaw.distance_for", "corridor_equilibria", "corridor_gain", "power_law_corridor_gain",
        "power_law_wall_gain", "wall_equilibria", "wall_gain", "wall_gain_arrays", "wall_gain_at_distance")),
    *(f"pfm_stability.laws.fuzzy:{q}" for q in ("DfapfControllers.K_V_of", "DfapfControllers.eta_of",
        "DfapfControllers.eta_with_slopes", "FuzzySystem.evaluate", "FuzzySystem.evaluate_with_gradient",
        "FuzzySystem.output_range", "FuzzyVariable.clip", "FuzzyVariable.membership_slopes",
        "FuzzyVariable.memberships", "FuzzyVariable.offsets", "symmetrized_rows")),
    *(f"pfm_stability.laws.fuzzy_law:{q}" for q in ("FuzzyScheduledLaw.corridor_equilibria",
        "FuzzyScheduledLaw.corridor_lateral_force", "FuzzyScheduledLaw.robust_bracket", "FuzzyScheduledLaw.shape",
        "FuzzyScheduledLaw.wall_equilibria", "FuzzyScheduledLaw.wall_force")),
    *(f"pfm_stability.laws.potentials:{q}" for q in ("attraction_derivatives", "attraction_force", "gnron_forces",
        "gnron_potential", "k2_closed_form", "khatib_force", "khatib_potential", "ray_stationary_points")),
    *(f"pfm_stability.laws.scene:{q}" for q in ("Circle", "Circle.geometry", "FieldLaw", "FieldLaw.from_dict",
        "Polygon", "Polygon.contains", "Polygon.geometry", "Scene", "Scene.from_dict", "Scene.grid", "Scene.load",
        "Segment", "Segment.geometry", "field")),
    *(f"pfm_stability.laws.velocity_laws:{q}" for q in ("VelocityAttraction.damping_ratio",
        "VelocityAttraction.force", "VelocityAttraction.holonomic_corridor_gains",
        "VelocityAttraction.holonomic_wall_gains", "VelocityAttraction.natural_frequency",
        "VelocityAttraction.position_force", "VelocityAttraction.steering_corridor_equilibria",
        "VelocityAttraction.steering_wall_equilibria", "VelocityAttraction.velocity_force",
        "VelocityGatedRepulsion.at_rest_force", "VelocityGatedRepulsion.braked_clearance",
        "VelocityGatedRepulsion.evaluate", "VelocityGatedRepulsion.magnitude",
        "VelocityGatedRepulsion.non_smooth_corridor", "VelocityGatedRepulsion.non_smooth_wall",
        "VelocityGatedRepulsion.potential", "stall_band")),
    *(f"pfm_stability.models.base:{q}" for q in ("AffineGainModel.batch_polynomials",
        "AffineGainModel.characteristic", "AffineGainModel.growth_rates", "AffineGainModel.polynomials",
        "AffineGainModel.rightmost_root", "AffineGainModel.roots", "Boundary.contains", "Boundary.from_interval",
        "LoopModel.boundary", "LoopModel.compute_boundary", "LoopModel.critical_delay", "LoopModel.critical_gain_k",
        "LoopModel.growth_rates", "LoopModel.is_stable", "LoopModel.rightmost_root", "check_heading_gain", "checked",
        "divergent_reason", "gain_margin", "gain_range", "interval_margin", "interval_verdict", "neutral_quotient",
        "verdict_label")),
    *(f"pfm_stability.models.holonomic:{q}" for q in ("HolonomicBoundary.contains",
        "HolonomicBoundary.from_interval", "HolonomicContinuous.critical_delay", "HolonomicContinuous.parts",
        "HolonomicFirstOrder.parts", "HolonomicModel.boundary", "HolonomicModel.compute_boundary",
        "HolonomicModel.critical_delay", "HolonomicModel.damping_range", "HolonomicModel.is_stable",
        "HolonomicModel.rightmost_root", "HolonomicPade.parts", "PolynomialHolonomicModel.characteristic",
        "PolynomialHolonomicModel.parts", "check_kappa")),
    *(f"pfm_stability.models.holonomic_delay:{q}" for q in ("HolonomicExactDelay.critical_delay",
        "HolonomicExactDelay.quasi_polynomial", "HolonomicExactDelay.unstable_root_count",
        "HolonomicSampled.delta_matrix", "HolonomicSampled.delta_parts", "HolonomicSampled.jury_stable",
        "HolonomicSampled.parts", "HolonomicSampled.z_polynomial")),
    *(f"pfm_stability.parameters:{q}" for q in ("Range", "Wall.from_degrees", "check_corridor_fits",
        "check_parameter", "get_preset", "to_degrees", "to_radians")),
    *(f"pfm_stability.plots.common:{q}" for q in ("figure_and_axes", "model_description", "model_label", "model_style")),
    *(f"pfm_stability.plots.comparison:{q}" for q in ("plot_critical_gain_vs_delay", "plot_kb_error_map",
        "plot_kb_error_maps")),
    *(f"pfm_stability.plots.force:{q}" for q in ("plot_equivalent_f", "plot_force_summary")),
    *(f"pfm_stability.plots.map:{q}" for q in ("known_extent", "map_greys")),
    *(f"pfm_stability.plots.sweep:{q}" for q in ("plot_sweep_summary",)),
    *(f"pfm_stability.plots.validation:{q}" for q in ("plot_growth_rate", "plot_simulated_boundary", "plot_validation")),
    *(f"pfm_stability.report.families:{q}" for q in ("FamilyLaw.choice", "HolonomicVerdict.to_dict",
        "holonomic_verdict", "make_family_law")),
    *(f"pfm_stability.report.stability:{q}" for q in ("build_report", "kb_error", "kb_errors", "remedies_by_key")),
})


def public_objects():
    """Every public function and class of the package, once each: {(module, qualname): object}."""
    found = {}
    for name in MODULES:
        module = importlib.import_module(name)
        for attr in getattr(module, "__all__", []):
            obj = getattr(module, attr, None)
            if not (inspect.isfunction(obj) or inspect.isclass(obj)):
                continue
            home = getattr(obj, "__module__", "") or ""
            if home.startswith("pfm_stability"):
                found.setdefault((home, obj.__qualname__), obj)
    return found


def parse(doc):
    """The numpydoc sections of ``doc``; numpydoc's own complaints (unknown sections) are not ours."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return NumpyDocString(doc)


def documented_names(section):
    """Names of a numpydoc ``Parameters``/``Attributes`` section, ``x, y : float`` counted as two."""
    return [n.strip() for p in section for n in p.name.split(",") if n.strip()]


def signature_names(function, documented):
    """Parameters a docstring must document: all but self/cls, and ``*args``/``**kwargs`` only if documented."""
    names = []
    for i, (name, p) in enumerate(inspect.signature(function).parameters.items()):
        if i == 0 and name in ("self", "cls"):
            continue
        if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD):
            star = "*" if p.kind == p.VAR_POSITIONAL else "**"
            if star + name in documented:
                names.append(star + name)
            elif name in documented:
                names.append(name)
            continue
        names.append(name)
    return names


def bad_names(documented):
    """Documented 'names' that are not identifiers (prose parsed as a parameter)."""
    return [n for n in documented if not n.lstrip("*").isidentifier()]


def function_problem(function, doc):
    """What is wrong with ``doc``'s Parameters section for ``function`` (None: nothing)."""
    if not doc:
        return None  # tests/test_docstrings.py reports a missing docstring
    try:
        documented = documented_names(parse(doc)["Parameters"])
    except ValueError as error:  # numpydoc cannot parse it
        return f"unparsable docstring: {error}"
    try:
        expected = signature_names(function, documented)
    except (TypeError, ValueError):
        return None  # no introspectable signature
    if bad := bad_names(documented):
        return f"Parameters lists non-names {bad} (prose belongs above the section)"
    if documented != expected:
        return f"Parameters documents {documented}, the signature has {expected}"
    return None


def class_problem(cls):
    """What is wrong with a class docstring's account of its constructor (None: nothing)."""
    doc = cls.__doc__
    if not doc:
        return None
    try:
        sections = parse(inspect.cleandoc(doc))
    except ValueError as error:
        return f"unparsable docstring: {error}"
    try:
        parameters = inspect.signature(cls).parameters
    except (TypeError, ValueError):
        return None  # builtin constructor (exceptions)
    if sections["Parameters"]:
        documented = documented_names(sections["Parameters"])
        if bad := bad_names(documented):
            return f"Parameters lists non-names {bad} (prose belongs above the section)"
        expected = signature_names(cls, documented)
        if documented != expected:
            return f"Parameters documents {documented}, the constructor has {expected}"
        return None
    expected = signature_names(cls, [])
    if not expected:
        return None
    attributes = documented_names(sections["Attributes"])
    if not (dataclasses.is_dataclass(cls) and attributes):
        return f"the constructor's parameters {expected} are not documented (Parameters section)"
    if bad := bad_names(attributes):
        return f"Attributes lists non-names {bad} (prose belongs above the section)"
    fields = {f.name for f in dataclasses.fields(cls)}
    if unknown := [n for n in attributes if n not in fields and not hasattr(cls, n)]:
        return f"Attributes lists {unknown}, which are not attributes of the class"
    in_order = [n for n in attributes if n in expected]
    if in_order != expected:
        return f"Attributes documents the constructor's parameters as {in_order}, the constructor has {expected}"
    return None


def problems_of(obj):
    """Every mismatch of a public function or class (its own methods too): {qualname: problem}."""
    out = {}
    if inspect.isfunction(obj):
        if problem := function_problem(obj, inspect.getdoc(obj)):
            out[obj.__qualname__] = problem
        return out
    if problem := class_problem(obj):
        out[obj.__qualname__] = problem
    for name, member in vars(obj).items():
        if name.startswith("_"):
            continue
        function = member.__func__ if isinstance(member, (staticmethod, classmethod)) else member
        if not inspect.isfunction(function):
            continue
        if function.__doc__:
            problem = function_problem(function, inspect.getdoc(function))
        else:
            problem = override_problem(obj, name, function)
        if problem:
            out[f"{obj.__qualname__}.{name}"] = problem
    return out


def override_problem(cls, name, function):
    """An undocumented override shows the docstring of the method it overrides: it must take the same parameters."""
    for base in cls.__mro__[1:]:
        member = vars(base).get(name)
        inherited = member.__func__ if isinstance(member, (staticmethod, classmethod)) else member
        if inspect.isfunction(inherited) and inherited.__doc__:
            mine, theirs = signature_names(function, []), signature_names(inherited, [])
            if mine != theirs:
                return f"shows the docstring of {base.__qualname__}.{name}{theirs} but takes {mine}"
            return None
    return None


PUBLIC = public_objects()
HOMES = sorted({home for home, _ in PUBLIC})


def test_the_check_sees_the_package():
    """Guards against a check that passes because it looks at nothing: the package has hundreds of
    public functions and classes, and the check parses real Parameters sections."""
    assert len(PUBLIC) > 300
    documented = [obj for obj in PUBLIC.values() if inspect.isfunction(obj) and parse(inspect.getdoc(obj) or "")["Parameters"]]
    assert len(documented) > 200


def test_the_check_catches_each_kind_of_mismatch():
    """Each rule of the module docstring, on a small function that breaks it."""

    def documented(a, b, *args, c=1, **kwargs):
        """Add.

        Parameters
        ----------
        a : float
            First.
        b, c : float
            Second and third.
        """

    def reordered(a, b):
        """Add.

        Parameters
        ----------
        b : float
            Second.
        a : float
            First.
        """

    def prose(a):
        """Add.

        Parameters
        ----------
        a : float
            First.
        All arrays broadcast together.
        """

    def missing(a, b):
        """Add.

        Parameters
        ----------
        a : float
            First.
        """

    @dataclasses.dataclass(frozen=True)
    class Fields:
        """Record.

        Attributes
        ----------
        x : float
            First.
        total : float
            A property besides the fields.
        y : float
            Second.
        """

        x: float
        y: float

        @property
        def total(self):
            return self.x + self.y

    @dataclasses.dataclass(frozen=True)
    class Swapped:
        """Record.

        Attributes
        ----------
        y : float
            Second.
        x : float
            First.
        """

        x: float
        y: float

    assert function_problem(documented, inspect.getdoc(documented)) is None
    assert "documents ['b', 'a']" in function_problem(reordered, inspect.getdoc(reordered))
    assert "non-names" in function_problem(prose, inspect.getdoc(prose))
    assert "the signature has ['a', 'b']" in function_problem(missing, inspect.getdoc(missing))
    assert class_problem(Fields) is None
    assert "constructor has ['x', 'y']" in class_problem(Swapped)


@pytest.mark.parametrize("home", HOMES)
def test_parameters_sections_match_signatures(home):
    problems = {}
    for (module, _), obj in PUBLIC.items():
        if module == home:
            problems.update(problems_of(obj))
    unexpected = {q: p for q, p in problems.items() if f"{home}:{q}" not in KNOWN_MISMATCHES}
    assert not unexpected, "\n".join(f"{home}:{q}: {p}" for q, p in sorted(unexpected.items()))
