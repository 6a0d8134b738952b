"""The model-file expression grammar: a whitelist parser to sympy, and a printer back.

User text is parsed with Python's ``ast`` and every node is checked against the
grammar; nothing is ever evaluated as Python.
"""

from __future__ import annotations

import ast
import math
from collections.abc import Mapping

import sympy as sp
from sympy.printing.str import StrPrinter

from ..errors import ModelError, did_you_mean

FUNCTIONS: dict[str, tuple[object, int]] = {
    "sin": (sp.sin, 1),
    "cos": (sp.cos, 1),
    "tan": (sp.tan, 1),
    "asin": (sp.asin, 1),
    "acos": (sp.acos, 1),
    "atan": (sp.atan, 1),
    "atan2": (sp.atan2, 2),
    "sinh": (sp.sinh, 1),
    "cosh": (sp.cosh, 1),
    "tanh": (sp.tanh, 1),
    "exp": (sp.exp, 1),
    "log": (sp.log, 1),
    "sqrt": (sp.sqrt, 1),
    "abs": (sp.Abs, 1),
    "sign": (sp.sign, 1),
}
CONSTANTS: dict[str, sp.Expr] = {"pi": sp.pi}
RESERVED = frozenset(FUNCTIONS) | frozenset(CONSTANTS) | {"t"}

MAX_LENGTH = 20_000
MAX_DEPTH = 200
MAX_EXPONENT = 1000
MAX_NUMBER_DIGITS = 300

_BINARY = {ast.Add: sp.Add, ast.Sub: None, ast.Mult: sp.Mul, ast.Div: None, ast.Pow: None}

_FORBIDDEN_NAMES = {
    ast.Attribute: "attribute access ('.') is not allowed",
    ast.Subscript: "indexing ('[...]') is not allowed",
    ast.Lambda: "lambda is not allowed",
    ast.Compare: "comparisons are not allowed",
    ast.BoolOp: "'and'/'or' are not allowed",
    ast.IfExp: "'if ... else' is not allowed",
    ast.List: "lists are not allowed in an expression",
    ast.Tuple: "tuples are not allowed in an expression",
    ast.Dict: "dictionaries are not allowed",
    ast.Set: "sets are not allowed",
    ast.ListComp: "comprehensions are not allowed",
    ast.GeneratorExp: "comprehensions are not allowed",
    ast.JoinedStr: "strings are not allowed",
    ast.NamedExpr: "':=' is not allowed",
    ast.Starred: "'*args' is not allowed",
    ast.Await: "'await' is not allowed",
}


def parse_expression(
    text: object,
    names: Mapping[str, sp.Expr],
    *,
    field: str | None = None,
    source: str | None = None,
) -> sp.Expr:
    """Parse one expression of the model grammar into sympy, resolving ``names``.

    ``text`` may be a string or a plain number (TOML int/float). ``names`` maps each
    declared name (parameter, coordinate, velocity, definition, ...) to its sympy value.
    """

    def fail(message: str) -> ModelError:
        return ModelError(message, field=field, source=source)

    if isinstance(text, bool):
        raise fail("expected an expression or a number, got a boolean")
    if isinstance(text, int):
        _check_integer(text, fail)
        return sp.Integer(text)
    if isinstance(text, float):
        return _float(text, fail)
    if isinstance(text, sp.Basic):
        return text
    if not isinstance(text, str):
        raise fail(f"expected an expression (a string) or a number, got {type(text).__name__}")
    if not text.strip():
        raise fail("the expression is empty")
    if len(text) > MAX_LENGTH:
        raise fail(f"the expression is longer than {MAX_LENGTH} characters")
    source_text = text.replace("^", "**")
    try:
        tree = ast.parse(source_text.strip(), mode="eval")
    except SyntaxError as exc:
        column = f" at column {exc.offset}" if exc.offset else ""
        raise fail(f"cannot parse {text!r}{column}: invalid syntax") from None
    except (ValueError, RecursionError, MemoryError):
        raise fail(f"cannot parse {text!r}") from None
    return _Converter(names, fail, text).visit(tree.body, 0)


def _check_integer(value: int, fail) -> None:
    if abs(value) >= 10**MAX_NUMBER_DIGITS:
        raise fail(f"the number has more than {MAX_NUMBER_DIGITS} digits")


def _float(value: float, fail) -> sp.Expr:
    if not math.isfinite(value):
        raise fail(f"the number {value!r} is not finite")
    # Exact rationals keep symbolic cancellation exact (floats leave residues that never cancel).
    return sp.Rational(repr(value))


class _Converter:
    def __init__(self, names, fail, text):
        self.names = names
        self.fail = fail
        self.text = text

    def visit(self, node: ast.AST, depth: int) -> sp.Expr:
        if depth > MAX_DEPTH:
            raise self.fail("the expression is nested too deeply")
        if isinstance(node, ast.Constant):
            return self._constant(node.value)
        if isinstance(node, ast.Name):
            return self._name(node.id)
        if isinstance(node, ast.UnaryOp):
            operand = self.visit(node.operand, depth + 1)
            if isinstance(node.op, ast.USub):
                return -operand
            if isinstance(node.op, ast.UAdd):
                return operand
            raise self.fail(f"the operator {_op_text(node.op)!r} is not allowed")
        if isinstance(node, ast.BinOp):
            return self._binary(node, depth)
        if isinstance(node, ast.Call):
            return self._call(node, depth)
        message = _FORBIDDEN_NAMES.get(type(node), f"'{type(node).__name__}' is not allowed")
        raise self.fail(f"{message} (in {self.text!r})")

    def _constant(self, value: object) -> sp.Expr:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.fail(f"only numbers are allowed as constants, got {value!r}")
        if isinstance(value, int):
            _check_integer(value, self.fail)
            return sp.Integer(value)
        return _float(value, self.fail)

    def _name(self, name: str) -> sp.Expr:
        if name in self.names:
            return self.names[name]
        if name in CONSTANTS:
            return CONSTANTS[name]
        if name in FUNCTIONS:
            raise self.fail(f"'{name}' is a function: call it as {name}(...)")
        known = list(self.names) + list(CONSTANTS)
        raise self.fail(f"unknown name '{name}'{did_you_mean(name, known)}")

    def _binary(self, node: ast.BinOp, depth: int) -> sp.Expr:
        op = type(node.op)
        if op not in _BINARY:
            raise self.fail(f"the operator {_op_text(node.op)!r} is not allowed (in {self.text!r})")
        left = self.visit(node.left, depth + 1)
        right = self.visit(node.right, depth + 1)
        if op is ast.Add:
            return left + right
        if op is ast.Sub:
            return left - right
        if op is ast.Mult:
            return left * right
        if op is ast.Div:
            if right == 0:
                raise self.fail(f"division by zero in {self.text!r}")
            return left / right
        return self._power(left, right)

    def _power(self, base: sp.Expr, exponent: sp.Expr) -> sp.Expr:
        if exponent.is_Number:
            if abs(exponent) > MAX_EXPONENT:
                raise self.fail(f"the exponent {exponent} is too large (at most {MAX_EXPONENT})")
            if base.is_Number and base != 0:
                digits = float(abs(exponent)) * math.log10(float(abs(base)))
                if abs(digits) > MAX_NUMBER_DIGITS:
                    raise self.fail("the power is too large a number")
            if base == 0 and exponent.is_negative:
                raise self.fail(f"division by zero in {self.text!r}")
        return base**exponent

    def _call(self, node: ast.Call, depth: int) -> sp.Expr:
        if not isinstance(node.func, ast.Name):
            raise self.fail(f"only the functions {', '.join(FUNCTIONS)} can be called")
        name = node.func.id
        if name not in FUNCTIONS:
            raise self.fail(f"unknown function '{name}'{did_you_mean(name, FUNCTIONS)}")
        if node.keywords:
            raise self.fail(f"{name}() takes no keyword arguments")
        function, arity = FUNCTIONS[name]
        if len(node.args) != arity:
            raise self.fail(f"{name}() takes {arity} argument(s), got {len(node.args)}")
        args = [self.visit(arg, depth + 1) for arg in node.args]
        return function(*args)


def _op_text(op: ast.AST) -> str:
    return {
        ast.BitXor: "^", ast.BitAnd: "&", ast.BitOr: "|", ast.LShift: "<<", ast.RShift: ">>",
        ast.Mod: "%", ast.FloorDiv: "//", ast.MatMult: "@", ast.Invert: "~", ast.Not: "not",
    }.get(type(op), type(op).__name__)


class _GrammarPrinter(StrPrinter):
    """Prints sympy back into the model-file grammar (what :func:`parse_expression` reads)."""

    def _print_Abs(self, expr):
        return f"abs({self._print(expr.args[0])})"

    def _print_Exp1(self, expr):
        return "exp(1)"

    def _print_Pi(self, expr):
        return "pi"

    def _print_Float(self, expr):
        return repr(float(expr))

    def _print_Pow(self, expr, rational=False):
        base, exponent = expr.args
        if exponent is sp.S.Half:
            return f"sqrt({self._print(base)})"
        if exponent == -sp.S.Half:
            return f"1/sqrt({self._print(base)})"
        return super()._print_Pow(expr, rational)


_PRINTER = _GrammarPrinter({"order": None})


def as_expression(value: object) -> sp.Basic:
    """A sympy object or a Python number as a sympy object.

    Strings are refused: user text goes through :func:`parse_expression` only.
    """
    if isinstance(value, sp.Basic):
        return value
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise TypeError(f"expected a sympy object or a number, got {type(value).__name__}")
    return sp.Integer(value) if isinstance(value, int) else sp.Float(value)


def format_expression(expr: sp.Expr) -> str:
    """Format a sympy expression as a string of the model-file grammar."""
    return _PRINTER.doprint(as_expression(expr))
