"""Dimensional analysis of a model (and of a user's answer) with pint.

Each symbol gets the dimension of its declared unit (q_dot: unit/s, q_ddot: unit/s^2, t: s).
Radians are dimensionless, so sin(theta) is fine, while a generalized force on an angle still
has to be an energy per radian (N m) and on a length a force (N). A parameter without a unit
has an unknown dimension and the terms containing it are not judged.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from functools import singledispatch

import sympy as sp

from ..compile.exact import distinct_nodes
from ..model.model import Body, Damper, Model, Particle, PointForce, Spring, Torque, multiplier_name
from ..model.printing import shown_expression as format_expression  # messages only
from ..model.rotations import Moment, RigidBody
from ..model.units import UnitOutsideTable, generalized_force_unit, is_angle_unit, registry, si_dimension

ENERGY = "J"
POWER = "W"


@dataclass(frozen=True)
class UnitIssue:
    """One dimensionally inconsistent term: where it is, the term, and what is wrong."""

    item: str
    term: str
    message: str


@dataclass(frozen=True)
class UnitsReport:
    """Every inconsistent term of a model; ``consistent`` when there is none."""

    model: str
    issues: tuple[UnitIssue, ...]
    unchecked: tuple[str, ...]  # parameters without a unit (terms with them are not judged)

    @property
    def consistent(self) -> bool:
        return not self.issues

    @property
    def passed(self) -> bool:
        """The units check passed: no inconsistent term (the same as ``consistent``)."""
        return self.consistent

    def __repr__(self) -> str:
        if self.consistent:
            return f"UnitsReport({self.model!r}: consistent)"
        return "\n".join([f"UnitsReport({self.model!r}: {len(self.issues)} inconsistent term(s))"]
                         + [f"  {issue.message}" for issue in self.issues])


def quantity(unit: str | None):
    """A pint quantity of magnitude 1 in base units, or None for an unknown unit."""
    if unit is None:
        return None
    ureg = registry()
    if unit in ("", "1"):
        return ureg.Quantity(1)
    try:
        return ureg.Quantity(1, unit.replace("^", "**")).to_base_units()
    except Exception:  # noqa: BLE001 - pint raises many types for an unparsable unit
        return None


def symbol_units(model: Model, quantity_of=None) -> dict[sp.Symbol, object]:
    """Symbol -> unit quantity (None: unknown) for parameters, coordinates and their rates;
    pint's quantities, or ``quantity_of``'s (si_dimension: UnitOutsideTable past its table)."""
    if quantity_of is None:
        quantity_of, second = quantity, registry().Quantity(1, "s")
    else:
        second = quantity_of("s")
    units: dict[sp.Symbol, object] = {model.time: second}
    for p in model.parameters:
        units[p.symbol] = quantity_of(p.unit)
    for c in model.coordinates:
        # Radians are dimensionless: sin(theta) is fine and theta_dot is 1/s.
        q = quantity_of("" if is_angle_unit(c.unit) or not c.unit else c.unit)
        units[c.symbol] = q
        units[c.velocity] = None if q is None else q / second
        units[c.acceleration] = None if q is None else q / second**2
    for constraint in model.constraints:
        units[sp.Symbol(multiplier_name(constraint.name))] = None
    return units


def describe(q) -> str:
    if q is None:
        return "unknown units"
    if q.dimensionless:
        return "no units (dimensionless)"
    if not hasattr(q, "units"):  # a table Dimension: its report is never shown (pint redoes it)
        return str(q.dimensionality)
    text = f"{q.units:~C}"
    return text.replace("**", "^")


# Past this many issues a repeated sub-expression's issues are not listed again (the report
# shows the first few and counts the rest).
MAX_REPEATED_ISSUES = 10_000


class DimensionChecker:
    """Walks a sympy expression, returning its dimension and collecting inconsistencies."""

    def __init__(self, units: Mapping[sp.Symbol, object], quantity_of=None):
        self.units = units
        self.issues: list[UnitIssue] = []
        self._quantity = quantity_of or quantity
        self._one = registry().Quantity(1) if quantity_of is None else quantity_of("")
        self._memo: dict = {}

    def check(self, item: str, expression: sp.Expr, expected: str | None = None,
              what: str = "") -> None:
        """Record every inconsistent term of ``expression``; with ``expected``, every term whose
        dimension differs from it (``what`` names the expected quantity, e.g. 'an energy')."""
        target = self._quantity(expected) if expected is not None else None
        terms = sp.Add.make_args(expression) if target is not None else (expression,)
        for term in terms:
            if term.is_Number:
                continue  # a bare number is an SI value of whatever the item needs
            dim = self.dimension(term, item)
            if target is not None and dim is not None and not _same(dim, target):
                label = what or f"in {expected}"
                self.issues.append(UnitIssue(
                    item, format_expression(term),
                    f"{item} must be {label} ({_named(expected, target)}), but the term "
                    f"{format_expression(term)} has {describe(dim)}"))

    def dimension(self, expr: sp.Expr, item: str):
        """The dimension of ``expr`` (None: unknown), its issues recorded. Memoized per
        sub-expression and item, its issues recorded again on each repeat (as the walk without
        the memo would): a chain of bodies shares each rotation's entries down the chain, whose
        walk without it grew like 3^depth (the 20-body chain took minutes)."""
        key = (expr, item)
        found = self._memo.get(key)
        if found is not None:
            dim, issues = found
            if len(self.issues) < MAX_REPEATED_ISSUES:
                self.issues.extend(issues)
            return dim
        start = len(self.issues)
        dim = self._dimension(expr, item)
        self._memo[key] = (dim, self.issues[start:])
        return dim

    def _dimension(self, expr: sp.Expr, item: str):
        if expr.is_Number or expr in (sp.pi, sp.E) or expr.is_NumberSymbol:
            return self._one
        if isinstance(expr, sp.Symbol):
            return self.units.get(expr)
        if isinstance(expr, sp.Add):
            # Bare numbers added to a term take its units (SI values), so they are not judged.
            dims = [(term, self.dimension(term, item)) for term in expr.args if not term.is_Number]
            known = [(term, d) for term, d in dims if d is not None]
            if not known:
                return None
            groups: list[list] = []
            for term, d in known:
                for group in groups:
                    if _same(group[0][1], d):
                        group.append((term, d))
                        break
                else:
                    groups.append([(term, d)])
            if len(groups) > 1:
                groups.sort(key=len, reverse=True)
                major = groups[0][0][1]
                if len(groups[0]) == len(groups[1]):  # no majority: name every group
                    listed = "; ".join(
                        ", ".join(format_expression(term) for term, _ in group)
                        + f" ({describe(group[0][1])})" for group in groups)
                    self.issues.append(UnitIssue(
                        item, format_expression(expr),
                        f"in {item}, the terms{_of(expr)} do not share units: "
                        f"{listed}"))
                    return None
                for group in groups[1:]:
                    for term, d in group:
                        self.issues.append(UnitIssue(
                            item, format_expression(term),
                            f"in {item}, the term {format_expression(term)} has {describe(d)} "
                            f"where the other terms{_of(expr)} have {describe(major)}"))
                return major
            return None if len(known) < len(dims) else known[0][1]
        if isinstance(expr, sp.Mul):
            result = self._one
            for factor in expr.args:
                d = self.dimension(factor, item)
                if d is None:
                    return None
                result = result * d
            return result
        if isinstance(expr, sp.Pow):
            base, exponent = expr.args
            b = self.dimension(base, item)
            if exponent.is_Number:
                return None if b is None else b ** float(exponent)
            self._dimensionless(exponent, item, "an exponent", expr)
            if b is not None and not b.dimensionless:
                self._issue(item, base, b, f"the base of {format_expression(expr)} "
                            "with a symbolic exponent")
            return self._one
        if isinstance(expr, sp.Abs):
            return self.dimension(expr.args[0], item)
        if isinstance(expr, sp.sign):
            self.dimension(expr.args[0], item)
            return self._one
        if isinstance(expr, sp.atan2):
            a, b = (self.dimension(arg, item) for arg in expr.args)
            if a is not None and b is not None and not _same(a, b):
                self.issues.append(UnitIssue(
                    item, format_expression(expr),
                    f"in {item}, the two arguments of {format_expression(expr)} have "
                    f"{describe(a)} and {describe(b)}"))
            return self._one
        if isinstance(expr, sp.Function):
            for arg in expr.args:
                self._dimensionless(arg, item, f"the argument of {expr.func.__name__}", expr)
            return self._one
        return None

    def _dimensionless(self, arg: sp.Expr, item: str, role: str, whole: sp.Expr) -> None:
        d = self.dimension(arg, item)
        if d is not None and not d.dimensionless:
            self._issue(item, arg, d, f"{role} in {format_expression(whole)}")

    def _issue(self, item: str, term: sp.Expr, d, role: str) -> None:
        self.issues.append(UnitIssue(
            item, format_expression(term),
            f"in {item}, {role} must be dimensionless, but {format_expression(term)} has "
            f"{describe(d)}"))


def _of(expr: sp.Expr) -> str:
    """' of <expr>' when short enough to read in a message."""
    text = format_expression(expr)
    return f" of {text}" if len(text) <= 80 else ""


def _named(expected: str, target) -> str:
    if not expected:
        return describe(target)
    base = describe(target)
    return expected if base == expected else f"{expected} = {base}"


def _same(a, b) -> bool:
    return a.dimensionality == b.dimensionality


def check_model_units(model: Model) -> UnitsReport:
    """Every dimensionally inconsistent term of the model: T, V, D, components, loads, Q.

    Every `derive` of a model file runs this (its warnings), and pint's import and registry
    were a third of a small command's time: a model whose units all lie in the exact SI table
    (si_dimension) is judged without pint. pint judges it again whenever the table meets a unit
    outside it or finds an issue (the messages name units as pint writes them), so every
    report is pint's own.
    """
    try:
        report = _check_model_units(model, si_dimension)
    except UnitOutsideTable:
        report = None
    if report is None or report.issues:
        report = _check_model_units(model, None)
    return report


def _check_model_units(model: Model, quantity_of) -> UnitsReport:
    checker = DimensionChecker(symbol_units(model, quantity_of), quantity_of)
    c = checker.check
    if model.kinetic_energy != 0:
        c("T", model.kinetic_energy, ENERGY, "an energy")
    if model.potential_energy != 0:
        c("V", model.potential_energy, ENERGY, "an energy")
    if model.dissipation != 0:
        c("D", model.dissipation, POWER, "a power (Rayleigh dissipation)")
    if model.gravity is not None:
        c("gravity.g", model.gravity.magnitude, "m/s^2", "an acceleration")
    # A robot read from URDF: its lengths, masses and inertias are SI numbers by the format
    # (m, kg, kg m^2), multiplied by sines of the joint angles; no symbol with a unit to judge.
    rigid_bodies = model.rigid_bodies if model.kinematic_tree is None else ()
    items = [item for component in (*model.particles, *model.bodies, *rigid_bodies,
                                    *model.springs, *model.dampers, *model.loads)
             for item in unit_items(component)]
    # A model whose positions never name a length (center = [0, 0, -0.5], turned by angles)
    # writes its geometry in SI metres by the format, as a URDF does: nothing to judge there.
    # One that names a length somewhere (L in x) is judged everywhere (y = -cos(theta) is wrong).
    numbers_only = not any(_names_a_length(item[1], checker.units) for item in items
                           if item[2] == "m")
    for item in items:
        if numbers_only and item[2] == "m" and _numbers_and_angles(item[1], checker.units):
            continue
        c(*item)
    for name, value in model.generalized_forces:
        coordinate = model.coordinate(name)
        c(f"Q[{name}]", value, generalized_force_unit(coordinate.unit),
          f"energy per unit of {name}")
    for constraint in model.constraints:
        c(f"constraints[{constraint.name}]", constraint.expression, None)
    unchecked = tuple(p.name for p in model.parameters if p.unit is None)
    return UnitsReport(model.name, _unique(checker.issues), unchecked)


@singledispatch
def unit_items(component) -> list[tuple]:
    """(field, expression, expected SI unit, what it is) for each part of one component: one
    table entry per kind (tests/model/test_component_tables.py walks every kind)."""
    raise TypeError(f"no units for a component of kind {type(component).__name__}")


def _symbols(expr) -> set:
    """The symbols in ``expr``, each distinct sub-expression visited once: sympy's free_symbols
    visits a shared one per occurrence (a 25-body chain's positions took 39 s)."""
    if not isinstance(expr, sp.Basic):
        return set()
    return {node for node in distinct_nodes((expr,)) if node.is_Symbol}


def _numbers_and_angles(expr, units) -> bool:
    """Whether ``expr`` holds no symbol but dimensionless ones (angles), and one at least."""
    symbols = _symbols(expr)
    return bool(symbols) and all(units.get(s) is not None and units[s].dimensionless
                                 for s in symbols)


def _names_a_length(expr, units) -> bool:
    """Whether ``expr`` holds a symbol whose unit has a length in it (m, m/s, ...)."""
    return any(units.get(s) is not None and "[length]" in units[s].dimensionality
               for s in _symbols(expr))


def _lengths(where: str, vector) -> list[tuple]:
    return [(f"{where}.{axis}", r, "m", "a length") for axis, r in zip("xyz", vector, strict=True)]


@unit_items.register
def _(particle: Particle) -> list[tuple]:
    where = f"particles[{particle.name}]"
    return [(f"{where}.mass", particle.mass, "kg", "a mass"),
            *_lengths(f"{where}.position", particle.position)]


@unit_items.register
def _(body: Body) -> list[tuple]:
    where = f"bodies[{body.name}]"
    return [(f"{where}.mass", body.mass, "kg", "a mass"),
            (f"{where}.inertia", body.inertia, "kg*m^2", "a moment of inertia"),
            *_lengths(f"{where}.position", body.position),
            (f"{where}.angle", body.angle, "", "an angle")]


@unit_items.register
def _(rigid: RigidBody) -> list[tuple]:
    where = f"bodies[{rigid.name}]"
    return [(f"{where}.mass", rigid.mass, "kg", "a mass"),
            *((f"{where}.inertia[{i}][{j}]", entry, "kg*m^2", "a moment of inertia")
              for i, row in enumerate(rigid.inertia) for j, entry in enumerate(row[i:], start=i)),
            *_lengths(f"{where}.position", rigid.position),
            # direction cosines: angles inside
            *((f"{where}.rotation[{i}][{j}]", entry, "", "a direction cosine")
              for i, row in enumerate(rigid.rotation) for j, entry in enumerate(row))]


@unit_items.register
def _(spring: Spring) -> list[tuple]:
    where = f"springs[{spring.name}]"
    return [(f"{where}.stiffness", spring.stiffness, None),
            (f"{where}.potential", sp.Rational(1, 2) * spring.stiffness
             * (spring.length - spring.rest_length) ** 2, ENERGY, "an energy")]


@unit_items.register
def _(damper: Damper) -> list[tuple]:
    return [(f"dampers[{damper.name}].dissipation",
             sp.Rational(1, 2) * damper.coefficient * damper.rate**2, POWER, "a power")]


@unit_items.register
def _(load: PointForce) -> list[tuple]:
    where = f"loads[{load.name}]"
    return [*_lengths(f"{where}.point", load.point),
            *((f"{where}.force.{axis}", f, "N", "a force")
              for axis, f in zip("xyz", load.force, strict=True))]


@unit_items.register
def _(load: Moment) -> list[tuple]:
    return [(f"loads[{load.name}].moment.{axis}", m, "N*m", "a moment")
            for axis, m in zip("xyz", load.moment, strict=True)]


@unit_items.register
def _(load: Torque) -> list[tuple]:
    where = f"loads[{load.name}]"
    return [(f"{where}.torque", load.torque, "N*m", "a torque"),
            (f"{where}.angle", load.angle, "", "an angle")]


def answer_unit_issues(model: Model, items: list[tuple[str, sp.Expr, str | None, str]],
                       extra: Mapping[sp.Symbol, object] | None = None) -> list[UnitIssue]:
    """Unit issues of a user's items: (item, expression, expected unit or None, what). As
    for the model (check_model_units): the exact SI table first, without pint; pint again
    wherever the table meets another unit or finds an issue, so every issue is pint's own."""
    try:
        issues = _answer_unit_issues(model, items, extra, si_dimension)
    except UnitOutsideTable:
        issues = None
    return _answer_unit_issues(model, items, extra, None) if issues is None or issues \
        else issues


def _answer_unit_issues(model: Model, items, extra, quantity_of) -> list[UnitIssue]:
    units = symbol_units(model, quantity_of)
    units.update(extra or {})
    checker = DimensionChecker(units, quantity_of)
    for item, expression, expected, what in items:
        checker.check(item, expression, expected, what)
    return list(_unique(checker.issues))


def _unique(issues: list[UnitIssue]) -> tuple[UnitIssue, ...]:
    seen, out = set(), []
    for issue in issues:
        key = (issue.item, issue.term, issue.message)
        if key not in seen:
            seen.add(key)
            out.append(issue)
    return tuple(out)
