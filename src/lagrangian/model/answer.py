"""A user's hand derivation (ANSWER.toml) read in the model-file grammar, to be checked.

Tables: ``[energy]`` T, V, D and L (the Lagrangian, checked as T - V);
``[generalized_forces]`` one entry per coordinate;
``[equations]`` one entry per coordinate, ``"lhs = rhs"`` or an expression equal to zero;
``[multipliers]`` ``count`` or ``names``; the final answers (``[matrices]``, ``[frequencies]``,
``[mode_shapes]``, ``[linearized]``, ``[generalized_forces]`` with ``at``, ``[equilibria]``,
``[statics]``) are kept as written here and read where they are checked
(check/final_reading.py). Names that the model does not know (a reaction force ``N``, a
tension ``T_rod``) are kept as *foreign symbols*, so the checker can say why they do not
belong, instead of failing to parse.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import sympy as sp

from ..errors import ModelError
from .answer_notation import (
    module_notation_text,
    prime_hint,
    primes_as_rates,
    time_derivative_parts,
)
from .expressions import CONSTANTS, FUNCTIONS, parse_expression
from .model import Model, multiplier_name
from .reader import check_known_keys, load_toml, read_text_file
from .tokens import plain_names

# Final answers: results to compare with the analysis (check/final_answers.py).
FINAL_TABLES = ("matrices", "frequencies", "mode_shapes", "linearized", "equilibria", "statics")
MATRICES = ("M", "K", "C")
FREQUENCY_KEYS = ("omega", "f", "period", "zeta")
# What L conserves, Routh and Hamilton (check/conserved_answers.py), kept as written too.
MECHANICS_TABLES = ("momenta", "conserved", "routhian", "hamiltonian")
TABLES = ("energy", "generalized_forces", "equations", "multipliers", *FINAL_TABLES,
          *MECHANICS_TABLES, "coordinates")
_FOREIGN = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
_TIME_DERIVATIVE_NAME = "d_dt_of_"  # stands for a d/dt(...) cut out of an answer's text
ENERGY_KEYS = ("T", "V", "D", "L")  # L: the Lagrangian, checked as T - V
MULTIPLIER_KEYS = ("count", "names")


def answer_file_schema() -> dict[str, tuple[frozenset[str], frozenset[str]]]:
    """Every key the answer reader accepts: table -> (required keys, optional keys); "" is the
    top level, "<coordinate>" any coordinate's name. docs/model-file.md's table is checked against it."""
    none, coordinate = frozenset(), frozenset({"<coordinate>"})
    return {"": (none, frozenset(TABLES)),
            "energy": (none, frozenset(ENERGY_KEYS)),
            "generalized_forces": (none, coordinate | {"at"}),
            "equations": (none, coordinate),
            "multipliers": (none, frozenset(MULTIPLIER_KEYS)),
            "matrices": (none, frozenset(MATRICES)),
            "frequencies": (none, frozenset(FREQUENCY_KEYS)),
            "mode_shapes": (frozenset({"shapes"}), none),
            "linearized": (frozenset({"about"}), coordinate),
            "equilibria": (none, coordinate),
            "statics": (frozenset({"at"}), frozenset({"<parameter>", "lambda_<constraint>"})),
            "momenta": (none, coordinate),
            "conserved": (none, frozenset({"cyclic", "quantities"})),
            "routhian": (frozenset({"cyclic"}), frozenset({"R", "L_R"})),
            "hamiltonian": (frozenset({"H"}), none)}


@dataclass(frozen=True)
class Answer:
    """The items a user derived by hand; each expression is sympy, None where not given."""

    source: str
    kinetic_energy: sp.Expr | None = None
    potential_energy: sp.Expr | None = None
    dissipation: sp.Expr | None = None
    lagrangian: sp.Expr | None = None  # [energy] L, checked as T - V
    generalized_forces: tuple[tuple[str, sp.Expr], ...] = ()
    equations: tuple[tuple[str, sp.Expr], ...] = ()
    multiplier_count: int | None = None
    multiplier_names: tuple[str, ...] | None = None
    # item ("T", "Q[theta]", "equation[x]") -> names the model does not declare
    foreign: tuple[tuple[str, frozenset[sp.Symbol]], ...] = field(default=())
    # The final-answer tables as written (matrices, frequencies, mode_shapes, linearized,
    # generalized_forces with `at`, equilibria, coordinates): read where they are checked.
    final_tables: tuple[tuple[str, object], ...] = ()

    def foreign_symbols(self, item: str) -> frozenset[sp.Symbol]:
        return dict(self.foreign).get(item, frozenset())

    @property
    def is_empty(self) -> bool:
        return (self.kinetic_energy is None and self.potential_energy is None
                and self.dissipation is None and self.lagrangian is None
                and not self.generalized_forces
                and not self.equations and self.multiplier_count is None
                and self.multiplier_names is None
                and all(key == "coordinates" for key, _ in self.final_tables))


def answer_names(model: Model) -> dict[str, sp.Expr]:
    """Every name an answer may use: parameters, coordinates with _dot/_ddot, definitions, t,
    and the multipliers lambda_<constraint>."""
    names: dict[str, sp.Expr] = {"t": model.time}
    for p in model.parameters:
        names[p.name] = p.symbol
    for c in model.coordinates:
        names[c.name] = c.symbol
        names[c.velocity.name] = c.velocity
        names[c.acceleration.name] = c.acceleration
    for name, value in model.definitions:
        names[name] = value
    for constraint in model.constraints:
        name = multiplier_name(constraint.name)
        names[name] = sp.Symbol(name)
    return names


def read_answer(path: str | Path, model: Model) -> Answer:
    """Read ANSWER.toml against ``model``; errors name the file and the key."""
    return parse_answer(read_text_file(path), model, source=str(path))


def parse_answer(text: str, model: Model, *, source: str = "<answer>") -> Answer:
    return answer_from_mapping(load_toml(text, source), model, source=source)


def answer_from_mapping(data: Mapping, model: Model, *, source: str = "<answer>") -> Answer:
    check_known_keys(data, TABLES, None, source)
    names = answer_names(model)
    coordinates = [c.name for c in model.coordinates]
    foreign: dict[str, frozenset[sp.Symbol]] = {}

    def expression(value: object, field: str, item: str,
                   known: Mapping[str, sp.Expr] = names) -> sp.Expr:
        if not isinstance(value, str):
            return parse_expression(value, known, field=field, source=source)
        cut = time_derivative_parts(value, _TIME_DERIVATIVE_NAME)
        if cut is not None:  # d/dt(m L² θ̇) + m g L sinθ, the module's Lagrange equation
            value, parts = cut
            known = {**known, **{name: _total_derivative(
                expression(inner, field, item, known), model, field, source)
                for name, inner in parts}}
        rewritten = module_notation_text(value)
        for k, text in enumerate([rewritten, value] if rewritten is not None else [value]):
            try:
                extra = _foreign_names(text, known, field, source)
                parsed = parse_expression(text, {**known, **extra}, field=field, source=source)
            except ModelError as error:
                if k == 0 and rewritten is not None:
                    continue  # the grammar's own message, of the text as written
                raise _prime_or(error, value, known, field, source) from None
            if extra:
                foreign[item] = foreign.get(item, frozenset()) | set(extra.values())
            return parsed
        raise AssertionError("unreachable")  # the last text parses or raises

    energy = _table(data, "energy", source)
    check_known_keys(energy, ENERGY_KEYS, "energy", source)
    values = {key: expression(energy[key], f"energy.{key}", key) for key in energy}

    forces = _table(data, "generalized_forces", source)
    generalized: tuple[tuple[str, sp.Expr], ...] = ()
    if "at" not in forces:  # with `at`, values at a configuration: a final answer
        check_known_keys(forces, coordinates, "generalized_forces", source, what="coordinate")
        generalized = tuple(
            (name, expression(forces[name], f"generalized_forces.{name}", f"Q[{name}]"))
            for name in coordinates if name in forces
        )
    final = tuple((key, data[key]) for key in (*FINAL_TABLES, *MECHANICS_TABLES, "coordinates")
                  if key in data)
    if "at" in forces:
        final += (("generalized_forces", forces),)

    table = _table(data, "equations", source)
    check_known_keys(table, coordinates, "equations", source, what="coordinate")
    equations = []
    for name in coordinates:
        if name not in table:
            continue
        field, item = f"equations.{name}", f"equation[{name}]"
        value = table[name]
        if isinstance(value, str) and "=" in value:
            sides = value.split("=")
            if len(sides) != 2 or any(s[-1:] in "<>!" for s in sides[:1]) or not sides[1].strip():
                raise ModelError(f"an equation is 'lhs = rhs' or one expression equal to zero, "
                                 f"got {value!r}", field=field, source=source)
            equations.append((name, expression(sides[0], field, item)
                              - expression(sides[1], field, item)))
        else:
            equations.append((name, expression(value, field, item)))

    count, multiplier_names = None, None
    multipliers = _table(data, "multipliers", source)
    check_known_keys(multipliers, MULTIPLIER_KEYS, "multipliers", source)
    if "count" in multipliers:
        count = multipliers["count"]
        if isinstance(count, bool) or not isinstance(count, int) or count < 0:
            raise ModelError(f"expected a whole number >= 0, got {count!r}",
                             field="multipliers.count", source=source)
    if "names" in multipliers:
        listed = multipliers["names"]
        if not isinstance(listed, list) or not all(isinstance(n, str) for n in listed):
            raise ModelError("expected a list of names", field="multipliers.names", source=source)
        multiplier_names = tuple(listed)
        if count is not None and count != len(listed):
            raise ModelError(f"count = {count} but {len(listed)} names are listed",
                             field="multipliers", source=source)

    answer = Answer(
        source=source,
        kinetic_energy=values.get("T"),
        potential_energy=values.get("V"),
        dissipation=values.get("D"),
        lagrangian=values.get("L"),
        generalized_forces=generalized,
        equations=tuple(equations),
        multiplier_count=count,
        multiplier_names=multiplier_names,
        foreign=tuple(sorted(foreign.items(), key=lambda kv: kv[0])),
        final_tables=final,
    )
    if answer.is_empty:
        raise ModelError("the answer has nothing to check: give [energy] T/V/D/L, "
                         "[generalized_forces], [equations], [multipliers], [matrices], "
                         "[frequencies], [mode_shapes], [linearized], [equilibria], [momenta], "
                         "[conserved], [routhian] or [hamiltonian]",
                         source=source)
    return answer


def _total_derivative(expression: sp.Expr, model: Model, field: str, source: str) -> sp.Expr:
    """d/dt of an expression in q, q_dot and t: sum dE/dq q_dot + dE/dq_dot q_ddot + dE/dt."""
    if any(expression.has(c.acceleration) for c in model.coordinates):
        raise ModelError("d/dt(...) of an acceleration is not read: write the equation with "
                         "q_ddot at most", field=field, source=source)
    return sp.expand(sum((expression.diff(c.symbol) * c.velocity
                          + expression.diff(c.velocity) * c.acceleration
                          for c in model.coordinates), expression.diff(model.time)))


def answer_expression(value: object, names: Mapping[str, sp.Expr], field: str,
                      source: str) -> sp.Expr:
    """One answer expression, in the grammar or as the module prints it (½ m L² θ̇², cosθ,
    implicit products, √): model/answer_notation.py; a prime gets the spelling to use."""
    if not isinstance(value, str):
        return parse_expression(value, names, field=field, source=source)
    rewritten = module_notation_text(value)
    if rewritten is not None:
        try:
            return parse_expression(rewritten, names, field=field, source=source)
        except ModelError:
            pass  # the grammar's own message, of the text as written
    try:
        return parse_expression(value, names, field=field, source=source)
    except ModelError as error:
        raise _prime_or(error, value, names, field, source) from None


def _prime_or(error: ModelError, text: str, names: Mapping[str, sp.Expr], field: str,
              source: str) -> ModelError:
    """The prime's spelling hint where ``text`` reads with its primes as rates, else ``error``."""
    spelled = primes_as_rates(text)
    if spelled is None:
        return error
    for candidate in (module_notation_text(spelled), spelled):
        if candidate is None:
            continue
        try:
            extra = {n: sp.Symbol(n) for n in plain_names(candidate) if _FOREIGN.match(n)}
            parse_expression(candidate, {**extra, **names}, field=field, source=source)
        except ModelError:
            continue
        return ModelError(prime_hint(text), field=field, source=source)
    return error


def _foreign_names(text: str, names: Mapping[str, sp.Expr], field: str,
                   source: str) -> dict[str, sp.Symbol]:
    """Plain identifiers in ``text`` that the model does not declare (never called functions).

    Syntax and grammar errors are left for the grammar parser to report.
    """
    extra: dict[str, sp.Symbol] = {}
    for name in plain_names(text):
        if name in names or name in CONSTANTS or name in FUNCTIONS:
            continue
        if not _FOREIGN.match(name):
            raise ModelError(f"'{name}' is not a valid name", field=field, source=source)
        extra[name] = sp.Symbol(name)
    return extra


def _table(data: Mapping, key: str, source: str) -> Mapping:
    value = data.get(key, {})
    if not isinstance(value, Mapping):
        raise ModelError(f"expected a table [{key}]", field=key, source=source)
    return value
