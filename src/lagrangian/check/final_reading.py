"""The final answers of an answer file read: matrices, frequencies, mode shapes, linearized
equations, generalized forces at a configuration, equilibria, statics loads (tables of ANSWER.toml that
model/answer.py keeps as written); errors name the file, the table and the field.

A decimal number keeps the precision it was written with: "4.43 rad/s" is 3 significant figures,
so it stands for any value that rounds to it (half a unit in the last written digit, in SI here);
a whole number (2, -1, 0) and a constant (pi, pi/2) are exact.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import sympy as sp

from ..errors import ModelError
from ..model.answer import FREQUENCY_KEYS, MATRICES
from ..model.answer_notation import module_notation_text
from ..model.model import Model, multiplier_name
from ..model.reader import check_known_keys
from ..model.units import generalized_force_unit, parse_quantity

FREQUENCY_KINDS = {"omega": ("rad/s", "natural frequency"), "f": ("Hz", "frequency"),
                   "period": ("s", "period")}
# A written number: sign, digits with an optional point, optional exponent, optional unit.
_NUMBER = re.compile(r"^\s*([-+]?)(\d+\.?\d*|\.\d+)(?:[eE]([-+]?\d+))?\s*(.*?)\s*$")
_CONSTANT_WORDS = re.compile(r"\bpi\b|\b[A-Za-z_]\w*\s*\(")  # pi and function calls
_LETTER = re.compile(r"[^\W\d]")
_DECIMAL = re.compile(r"(?<![A-Za-z_0-9.])(\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")


@dataclass(frozen=True)
class Written:
    """A number as written: its SI ``value`` and ``step``, one unit in the last written digit
    (SI); ``step`` is None for an exact value (2, 0, pi/2: compared to rounding only)."""

    text: str
    value: float
    step: float | None
    figures: int | None = None
    in_parameters: bool = False  # written in the model's parameters (sqrt(k/m))

    @property
    def precision(self) -> str:
        """How it is compared, in words ("to the 3 significant figures you wrote")."""
        if self.in_parameters:
            return "at the model's parameter values, as written in its parameters"
        if self.step is None:
            return "exactly: a whole number or a constant is exact"
        if self.figures is not None:
            plural = "" if self.figures == 1 else "s"
            return f"to the {self.figures} significant figure{plural} you wrote"
        return "to the precision you wrote"


@dataclass(frozen=True)
class Entry:
    """A matrix entry or an equation: sympy ``value``; ``relative`` is the relative precision of
    the numbers written in it (None: no measured numbers, compared symbolically)."""

    text: str
    value: sp.Expr
    written: Written | None = None
    relative: float | None = None


@dataclass(frozen=True)
class FinalAnswers:
    """Every final-answer table of an answer file, in the model's coordinate order."""

    order: tuple[str, ...]                      # the student's coordinate order
    matrices: tuple[tuple[str, tuple[tuple[Entry, ...], ...]], ...] = ()
    frequency_kind: str | None = None           # omega, f or period
    frequencies: tuple[Written, ...] = ()
    damping_ratios: tuple[Written, ...] = ()
    mode_shapes: tuple[tuple[Written, ...], ...] = ()   # components in the student's order
    about: tuple[tuple[str, float], ...] | None = None  # [linearized] about (SI)
    linearized: tuple[tuple[str, Entry], ...] = ()
    forces_at: tuple[tuple[str, float], ...] | None = None
    forces: tuple[tuple[str, Written], ...] = ()
    equilibria: tuple[tuple[str, tuple[Written, ...]], ...] = ()
    statics_at: tuple[tuple[str, float], ...] | None = None  # [statics] at (SI)
    statics: tuple[tuple[str, Written], ...] = ()  # load magnitudes, then reactions lambda_<c>

    @property
    def is_empty(self) -> bool:
        return not (self.matrices or self.frequencies or self.damping_ratios or self.mode_shapes
                    or self.linearized or self.forces or self.equilibria or self.statics)


SLACK = 1e-9  # relative: a value that rounds to the written one, up to float rounding


def agrees(written: Written, true: float, scale: float = 1.0) -> bool:
    """``true`` rounds to ``written`` at the precision it was written to (exact: to 1e-9)."""
    if not math.isfinite(true):
        return False
    if written.step is None:
        return abs(true - written.value) <= SLACK * max(abs(true), abs(written.value), scale)
    return abs(true - written.value) <= written.step / 2 + SLACK * max(abs(true), written.step)


def read_written(value: object, unit: str | None, field: str, source: str) -> Written:
    """A number with an optional unit ("4.43 rad/s", 4.43, "30deg", "pi") in SI, with the
    precision it was written to."""
    if isinstance(value, bool) or not isinstance(value, int | float | str):
        raise ModelError(f"expected a number with its unit as a string (like '4.43 rad/s'), "
                         f"got {value!r}", field=field, source=source)
    text = repr(value) if isinstance(value, float) else " ".join(str(value).split())
    try:
        si = parse_quantity(text, unit, field)
    except ModelError as error:
        raise ModelError(error.message, field=field, source=source) from None
    match = _NUMBER.match(text)
    # a ratio (zeta, a shape component) has no unit: the unit library would take '1 m' as 1
    if unit == "1" and (match[4] if match else _LETTER.search(_CONSTANT_WORDS.sub("", text))):
        raise ModelError(f"expected a plain number without a unit, got {text!r}", field=field,
                         source=source)
    if match is None:  # a constant expression: pi, 3*pi/4 rad
        return Written(text, si, None)
    sign, digits, exponent, unit_text = match.groups()
    number = float(sign + digits + (f"e{exponent}" if exponent else ""))
    if "." not in digits:
        return Written(text, si, None)  # a whole number (2, -1, 0) is exact
    factor = si / number if number else parse_quantity(f"1 {unit_text}".strip(), unit, field)
    decimals = len(digits.partition(".")[2])
    step = abs(factor) * 10.0 ** (-decimals + int(exponent or 0))
    significant = digits.replace(".", "").lstrip("0")
    return Written(text, si, step, len(significant) or None)


def relative_precision(text: object) -> float | None:
    """Half a unit in the last digit, relative, of the least precise measured number written in
    an expression ("9.81/0.5*theta": 0.5/5 = 10%); None when it has no measured number (only
    whole numbers, such as 1/2 or 2*m, which are exact)."""
    if not isinstance(text, str):
        return relative_precision(repr(text)) if isinstance(text, float) else None
    worst = None
    for match in _DECIMAL.finditer(text):
        literal = match.group(0)
        mantissa = match.group(1)
        value = float(literal)
        if "." not in mantissa:  # whole numbers are exact
            continue
        if value == 0:
            continue
        exponent = int(literal.lower().partition("e")[2] or 0)
        step = 10.0 ** (-len(mantissa.partition(".")[2]) + exponent)
        share = step / 2 / value
        worst = share if worst is None else worst + share  # relative errors add
    return worst


def read_final_answers(data: Mapping, model: Model,
                       expression: Callable[[object, str], sp.Expr], source: str) -> FinalAnswers:
    """The final-answer tables of ``data`` (an answer file's tables)."""
    coordinates = [c.name for c in model.coordinates]
    order = _order(data.get("coordinates"), coordinates, source)
    reader = _Reader(model, order, expression, source)
    fields = {}
    if "matrices" in data:
        fields["matrices"] = reader.matrices(_table(data, "matrices", source))
    if "frequencies" in data:
        fields.update(reader.frequencies(_table(data, "frequencies", source)))
    if "mode_shapes" in data:
        fields["mode_shapes"] = reader.mode_shapes(_table(data, "mode_shapes", source))
    if "linearized" in data:
        fields.update(reader.linearized(_table(data, "linearized", source)))
    forces = data.get("generalized_forces")
    if isinstance(forces, Mapping) and "at" in forces:
        fields.update(reader.forces(forces))
    if "equilibria" in data:
        fields["equilibria"] = reader.equilibria(_table(data, "equilibria", source))
    if "statics" in data:
        fields.update(reader.statics(_table(data, "statics", source)))
    return FinalAnswers(order=tuple(order), **fields)


class _Reader:
    def __init__(self, model: Model, order: list[str], expression, source: str):
        self.model = model
        self.order = order
        self.expression = expression
        self.source = source
        self.units = {c.name: c.unit for c in model.coordinates}

    def fail(self, message: str, field: str) -> ModelError:
        return ModelError(message, field=field, source=self.source)

    def _list(self, value: object, field: str, length: int | None = None,
              noun: str = "entries", per: str = "") -> list:
        """A non-empty list (of ``length`` items where given)."""
        if not isinstance(value, list) or not value:
            shown = repr(value) if len(repr(value)) <= 60 else repr(value)[:57] + "..."
            raise self.fail(f"expected a list of {noun}{per}, got {shown}", field)
        if length is not None and len(value) != length:
            raise self.fail(f"expected {length} {noun}{per}, got {len(value)}", field)
        return value

    def matrices(self, table: Mapping) -> tuple:
        _known(table, MATRICES, "matrices", self.source)
        n = len(self.order)
        per = f" (one per coordinate: {', '.join(self.order)})"
        result = []
        for name in MATRICES:
            if name not in table:
                continue
            field = f"matrices.{name}"
            rows = self._list(table[name], field, n, "rows", per)
            matrix = []
            for i, row in enumerate(rows, start=1):
                row = self._list(row, f"{field}[{i}]", n, "entries", per)
                matrix.append(tuple(self._entry(v, f"{field}[{i}][{j}]")
                                    for j, v in enumerate(row, start=1)))
            result.append((name, tuple(matrix)))
        return tuple(result)

    def _entry(self, value: object, field: str) -> Entry:
        if isinstance(value, int | float) and not isinstance(value, bool) or \
                isinstance(value, str) and _NUMBER.match(value) and not _NUMBER.match(value)[4]:
            written = read_written(value, None, field, self.source)
            return Entry(written.text, sp.Float(written.value), written=written)
        if not isinstance(value, str):
            raise self.fail(f"expected an expression or a number, got {value!r}", field)
        return Entry(value, self.expression(value, field), relative=relative_precision(value))

    def frequencies(self, table: Mapping) -> dict:
        _known(table, FREQUENCY_KEYS, "frequencies", self.source)
        kinds = [k for k in FREQUENCY_KINDS if k in table]
        if len(kinds) > 1:
            raise self.fail(f"give one of omega, f or period, not {' and '.join(kinds)}",
                            "frequencies")
        fields: dict = {}
        if kinds:
            kind = kinds[0]
            unit = FREQUENCY_KINDS[kind][0]
            field = f"frequencies.{kind}"
            values = self._list(table[kind], field, noun=f"values in {unit}")
            fields["frequency_kind"] = kind
            fields["frequencies"] = tuple(
                self._frequency(v, kind, f"{field}[{i}]") for i, v in enumerate(values, start=1))
        if "zeta" in table:
            values = self._list(table["zeta"], "frequencies.zeta", noun="damping ratios")
            fields["damping_ratios"] = tuple(read_written(v, "1", f"frequencies.zeta[{i}]",
                                                          self.source)
                                             for i, v in enumerate(values, start=1))
        if not fields:
            raise self.fail("give omega = [...] (rad/s), f = [...] (Hz) or period = [...] (s)",
                            "frequencies")
        return fields

    def _frequency(self, value: object, kind: str, field: str) -> Written:
        text = value if isinstance(value, str) else ""
        # rad is dimensionless to the unit library, so Hz and rad/s would pass for each other
        if kind == "omega" and re.search(r"hz", text, re.I):
            raise self.fail(f"omega is in rad/s; write a frequency in Hz as f = [...], got "
                            f"{value!r}", field)
        if kind == "f" and re.search(r"rad|deg|rpm|rev", text, re.I):
            raise self.fail(f"f is in Hz (cycles per second); write rad/s as omega = [...], "
                            f"got {value!r}", field)
        written = self._symbolic(value, field)
        if written is None:
            written = read_written(value, FREQUENCY_KINDS[kind][0], field, self.source)
        if written.value <= 0:
            raise self.fail(f"expected a positive {FREQUENCY_KINDS[kind][1]}, got {value!r}",
                            field)
        return written

    def _symbolic(self, value: object, field: str) -> Written | None:
        """A value written in the model's parameters ("sqrt(k/m)", "√(g/L)", "2*pi*sqrt(m/k)"),
        taken at the model's values and compared exactly (to 1e-9); None when ``value`` is a
        number with a unit (read_written reads it) or names no parameter."""
        quantity = _NUMBER.match(value) if isinstance(value, str) else None
        if not isinstance(value, str) or quantity and (
                not quantity[4] or quantity[4][0] not in "*/^(+-" and quantity[4][0].isascii()):
            return None  # a number, with its unit where it has one (4.43 rad/s); 2π reads on
        parameters = {p.symbol: p for p in self.model.parameters}
        try:
            expression = self.expression(value, field)
        except ModelError:
            return None  # a unit (4.43 rad/s) or a fault that read_written names
        symbols = expression.free_symbols
        if not symbols and module_notation_text(value) is not None:
            return Written(value, float(expression), None)  # √2, 2π: exact, as the module writes
        if not symbols or not symbols <= set(parameters):
            if symbols - set(parameters):
                names = ", ".join(sorted(str(s) for s in symbols - set(parameters)))
                raise self.fail(f"{value!r} may use the model's parameters only, not {names}",
                                field)
            return None
        missing = sorted(p.name for s, p in parameters.items() if s in symbols and p.value is None)
        if missing:
            raise self.fail(f"{value!r} uses parameters without a value: {', '.join(missing)}",
                            field)
        number = expression.xreplace({s: parameters[s].value for s in symbols})
        try:
            return Written(value, float(number), None, in_parameters=True)
        except TypeError:
            raise self.fail(f"{value!r} is not a real number at the model's values", field) \
                from None

    def mode_shapes(self, table: Mapping) -> tuple:
        _known(table, ("shapes",), "mode_shapes", self.source)
        if "shapes" not in table:
            raise self.fail("give shapes = [[...], ...], one list per mode", "mode_shapes.shapes")
        shapes = self._list(table["shapes"], "mode_shapes.shapes", noun="shapes")
        n = len(self.order)
        per = f" (one per coordinate: {', '.join(self.order)})"
        result = []
        for i, shape in enumerate(shapes, start=1):
            field = f"mode_shapes.shapes[{i}]"
            shape = self._list(shape, field, n, "components", per)
            written = tuple(self._symbolic(v, f"{field}[{j}]")
                            or read_written(v, "1", f"{field}[{j}]", self.source)
                            for j, v in enumerate(shape, start=1))
            if all(w.value == 0 for w in written):
                raise self.fail("a mode shape cannot be all zeros", field)
            result.append(written)
        return tuple(result)

    def linearized(self, table: Mapping) -> dict:
        _known(table, ("about", *self.order), "linearized", self.source, what="key or coordinate")
        about = table.get("about")
        if not isinstance(about, Mapping) or not about:
            raise self.fail("give the equilibrium as about = { coordinate = value, ... }",
                            "linearized.about")
        equations = []
        for name in self.order:
            if name in table:
                equations.append((name, self._equation(table[name], f"linearized.{name}")))
        if not equations:
            raise self.fail(f"give one equation per coordinate ({', '.join(self.order)})",
                            "linearized")
        return {"about": self._configuration(about, "linearized.about"),
                "linearized": tuple(equations)}

    def _equation(self, value: object, field: str) -> Entry:
        if not isinstance(value, str):
            raise self.fail(f"expected an equation as a string, got {value!r}", field)
        sides = value.split("=")
        if len(sides) > 2 or len(sides) == 2 and (not sides[1].strip() or sides[0][-1:] in "<>!"):
            raise self.fail(f"an equation is 'lhs = rhs' or one expression equal to zero, got "
                            f"{value!r}", field)
        expr = self.expression(sides[0], field)
        if len(sides) == 2:
            expr = expr - self.expression(sides[1], field)
        return Entry(value, expr, relative=relative_precision(value))

    def _configuration(self, table: object, field: str) -> tuple[tuple[str, float], ...]:
        if not isinstance(table, Mapping) or not table:
            raise self.fail("expected a table { coordinate = value, ... }", field)
        _known(table, self.order, field, self.source, what="coordinate")
        return tuple((name, read_written(table[name], self.units[name] or "m",
                                         f"{field}.{name}", self.source).value)
                     for name in self.order if name in table)

    def forces(self, table: Mapping) -> dict:
        _known(table, ("at", *self.order), "generalized_forces", self.source,
               what="key or coordinate")
        at = self._configuration(table["at"], "generalized_forces.at")
        values = tuple((name, read_written(table[name],
                                           generalized_force_unit(self.units[name]),
                                           f"generalized_forces.{name}", self.source))
                       for name in self.order if name in table)
        if not values:
            raise self.fail("with `at`, give each generalized force as a number with its unit "
                            "(theta = \"43.3 N*m\")", "generalized_forces")
        return {"forces_at": at, "forces": values}

    def equilibria(self, table: Mapping) -> tuple:
        _known(table, self.order, "equilibria", self.source, what="coordinate")
        result, length = [], None
        for name in self.order:
            if name not in table:
                continue
            field = f"equilibria.{name}"
            values = self._list(table[name], field, noun="positions")
            if length is not None and len(values) != length:
                raise self.fail(f"expected {length} positions, one per equilibrium (as the "
                                f"coordinates before it), got {len(values)}", field)
            length = len(values)
            result.append((name, tuple(read_written(v, self.units[name] or "m", f"{field}[{i}]",
                                                    self.source)
                                       for i, v in enumerate(values, start=1))))
        if not result:
            raise self.fail(f"give each coordinate's positions ({', '.join(self.order)} = "
                            f"[...])", "equilibria")
        return tuple(result)

    def statics(self, table: Mapping) -> dict:
        """[statics]: at = { theta = "40deg" } and each load magnitude solved for (a parameter,
        "148 N"), optionally the reactions (lambda_<constraint>, SI or with a unit)."""
        model = self.model
        parameters = {p.name: p.unit for p in model.parameters}
        reactions = [multiplier_name(c.name) for c in model.constraints]
        _known(table, ("at", *parameters, *reactions), "statics", self.source,
               what="key, parameter or multiplier")
        if "at" not in table:
            raise self.fail("give the configuration as at = { coordinate = value, ... } "
                            "(coordinates left out follow the constraints)", "statics.at")
        at = self._configuration(table["at"], "statics.at")
        loads = [(name, read_written(table[name], unit or None, f"statics.{name}", self.source))
                 for name, unit in parameters.items() if name in table]
        if not loads:
            raise self.fail("give each load magnitude you solved for as a parameter of the model "
                            f"with its value (one of: {', '.join(parameters) or 'none'})",
                            "statics")
        loads += [(name, read_written(table[name], None, f"statics.{name}", self.source))
                  for name in reactions if name in table]
        return {"statics_at": at, "statics": tuple(loads)}


def _order(value: object, coordinates: list[str], source: str) -> list[str]:
    """The student's coordinate order: ``coordinates = ["x2", "x1"]`` or a ``[coordinates]``
    table (its keys in order); the model's when not given."""
    if value is None:
        return coordinates
    if isinstance(value, Mapping):
        names = list(value)
    elif isinstance(value, list) and all(isinstance(v, str) for v in value):
        names = value
    else:
        raise ModelError(f"expected a list of coordinate names, got {value!r}",
                         field="coordinates", source=source)
    for name in names:
        if name not in coordinates:
            _known({name: None}, coordinates, "coordinates", source, what="coordinate")
    if sorted(names) != sorted(coordinates):
        raise ModelError(f"list every coordinate once, in your order (the model has "
                         f"{', '.join(coordinates)}), got {', '.join(names) or 'none'}",
                         field="coordinates", source=source)
    return list(names)


def _known(table: Mapping, allowed, field: str, source: str, what: str = "key") -> None:
    check_known_keys(table, allowed, field, source, what=what)


def _table(data: Mapping, key: str, source: str) -> Mapping:
    value = data.get(key, {})
    if not isinstance(value, Mapping):
        raise ModelError(f"expected a table [{key}]", field=key, source=source)
    return value
