"""The model-file expression grammar: a whitelist parser to sympy, and a printer back.

User text is read by the small tokenizer and operator-precedence parser below; nothing is
ever evaluated as Python. Numbers are bounded by value while parsing: every literal and
every constant intermediate result must be real, finite and below 1e300 in size, exact
rationals keep at most 1000 digits, and a power is refused before sympy computes it when
its exact value would be too large or too costly.
"""

from __future__ import annotations

import keyword
import math
import re
from collections.abc import Mapping

import sympy as sp

from ..errors import ModelError, did_you_mean
from .printing import as_expression, format_expression  # noqa: F401 - the grammar's printer, re-exported
from .tokens import _COMPARISONS, _FORBIDDEN_OPERATORS, _PRECEDENCE, _at, _quote, _tokens

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
# A name of the grammar: a coordinate, parameter, definition or component.
IDENTIFIER = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
RESERVED = frozenset(FUNCTIONS) | frozenset(CONSTANTS) | {"t"}

MAX_LENGTH = 50_000  # parsing and converting stay under about 1 s
# An expression written out in full (definitions substituted, each use a copy): sympy walks many
# expressions as trees, so 25 definitions that each use the one before twice cost 2^25 nodes.
MAX_TREE_NODES = 20_000  # derive of such a term takes ~15 s (measured: 5,600 nodes 4 s)
MAX_DEPTH = 100  # nesting (parentheses, calls, powers, signs); flat sums and products are free
MAX_EXPONENT = 1000
MAX_NUMBER_DIGITS = 300  # every number's size is below 10**300 (and a literal above 10**-300)
MAX_EXACT_DIGITS = 1000  # numerator and denominator of an exact rational
# Digits sympy may handle on the way to an exact power or sum (a 10**5-digit product is ms).
_MAX_WORK_DIGITS = 100_000
_LIMIT = 10.0**MAX_NUMBER_DIGITS

# Float twins of the functions, to bound a constant's value before sympy computes it.
_FLOAT_FUNCTIONS = {
    "sin": math.sin, "cos": math.cos, "tan": math.tan, "asin": math.asin, "acos": math.acos,
    "atan": math.atan, "atan2": math.atan2, "sinh": math.sinh, "cosh": math.cosh,
    "tanh": math.tanh, "exp": math.exp, "log": math.log, "sqrt": math.sqrt, "abs": abs,
    "sign": lambda x: float((x > 0) - (x < 0)),
}
_INFINITIES = (sp.zoo, sp.oo, -sp.oo)


def tree_size(expr: sp.Basic, limit: int | None = None) -> int:
    """Nodes of ``expr`` counted as a tree (a shared subexpression once per use), found on its
    graph in time linear in the distinct nodes; stops counting past ``limit``."""
    sizes: dict[int, int] = {}
    stack: list[tuple[sp.Basic, bool]] = [(expr, False)]
    while stack:
        node, ready = stack.pop()
        key = id(node)
        if key in sizes:
            continue
        if ready:
            sizes[key] = 1 + sum(sizes[id(a)] for a in node.args)
            if limit is not None and sizes[key] > limit:
                return sizes[key]
            continue
        stack.append((node, True))
        stack.extend((a, False) for a in node.args if id(a) not in sizes)
    return sizes[id(expr)]


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
        if text.bit_length() > 4 * MAX_NUMBER_DIGITS:
            raise fail(f"the number has more than {MAX_NUMBER_DIGITS} digits")
        return _literal(str(text), fail)
    if isinstance(text, float):
        if not math.isfinite(text):
            raise fail(f"the number {text!r} is not finite")
        return _literal(repr(text), fail)
    if isinstance(text, sp.Basic):
        return text
    if not isinstance(text, str):
        raise fail(f"expected an expression (a string) or a number, got {type(text).__name__}")
    if not text.strip():
        raise fail("the expression is empty")
    if len(text) > MAX_LENGTH:
        raise fail(f"the expression is longer than {MAX_LENGTH} characters")
    try:
        tree = _Parser(text, fail).parse()
        _check_names(tree, names, text, fail)
        return _Converter(names, fail, text).expression(tree)
    except RecursionError:  # sympy recursing through a deep (but allowed) nesting
        raise fail("the expression is nested too deeply") from None
    except MemoryError:
        raise fail("the expression is too large to handle") from None


# -- numbers ------------------------------------------------------------------------------

def _digits(value: int) -> int:
    """Decimal digits of an integer, from its bit length (never printed: no 4300-digit limit)."""
    return int(abs(value).bit_length() * 0.30103) + 1


def _literal(text: str, fail) -> sp.Rational:
    """The exact value of a decimal literal ('1.5e-3' is 3/2000), bounded before it is built."""
    clean = text.replace("_", "").lower()
    if clean[:2] in ("0x", "0o", "0b"):
        if len(clean) > MAX_NUMBER_DIGITS:
            raise fail(f"the number has more than {MAX_NUMBER_DIGITS} digits")
        _check_based(text, fail)
        value = int(clean, 0)
        if value >= 10**MAX_NUMBER_DIGITS:
            raise fail(f"the number has more than {MAX_NUMBER_DIGITS} digits")
        return sp.Integer(value)
    sign = -1 if clean.startswith("-") else 1
    clean = clean.lstrip("+-")
    mantissa, _, exponent_text = clean.partition("e")
    whole, _, fraction = mantissa.partition(".")
    digits = (whole + fraction).lstrip("0")
    if not digits:
        return sp.S.Zero
    if len(digits) > MAX_NUMBER_DIGITS:
        raise fail(f"the number has more than {MAX_NUMBER_DIGITS} digits")
    if len(exponent_text.lstrip("+-")) > 6:  # |exponent| >= 10**6: far outside any float
        exponent = 10**6 if not exponent_text.startswith("-") else -(10**6)
    else:
        exponent = int(exponent_text or 0)
    power = exponent - len(fraction)
    size = len(digits) - 1 + power  # floor(log10 |x|)
    if size >= MAX_NUMBER_DIGITS:
        if exponent_text:
            raise fail(f"the number {text} is too large (at most 1e{MAX_NUMBER_DIGITS} in size)")
        raise fail(f"the number has more than {MAX_NUMBER_DIGITS} digits")
    if size < -MAX_NUMBER_DIGITS:
        raise fail(f"the number {text} is too small (below 1e-{MAX_NUMBER_DIGITS}, it would be "
                   f"read as 0): write 0 or a larger number")
    value = sign * int(digits)
    return sp.Integer(value * 10**power) if power >= 0 else sp.Rational(value, 10**-power)


_BASES = {"x": ("a hexadecimal", "0123456789abcdef"), "o": ("an octal", "01234567"),
          "b": ("a binary", "01")}


def _check_based(text: str, fail) -> None:
    """A 0x/0o/0b literal's digits, checked as Python's int(text, 0) would, so that a malformed
    one ('0od', '0b2', '0x_') is the model's error, naming the digit, never int's ValueError."""
    kind, allowed = _BASES[text[1].lower()]
    body = text[2:]
    for char in body:
        if char != "_" and char.lower() not in allowed:
            raise fail(f"cannot parse the number {_quote(text)}: '{char}' is not {kind} digit")
    if not body.replace("_", "") or body.endswith("_") or "__" in body:
        raise fail(f"cannot parse the number {_quote(text)}: {kind} number needs digits after "
                   f"'{text[:2]}', with single underscores only between them")


# -- parsing ------------------------------------------------------------------------------

class _Node:
    """One node of the parsed expression; ``start:end`` is its span in the user's text."""

    __slots__ = ("kind", "value", "children", "start", "end", "depth")

    def __init__(self, kind, value, children, start, end, depth=1):
        self.kind, self.value, self.children = kind, value, children
        self.start, self.end, self.depth = start, end, depth


class _Parser:
    """Operator precedence (shunting-yard) parser: iterative, so flat sums and products of
    any length cost no recursion; only nesting is limited (to MAX_DEPTH)."""

    def __init__(self, text: str, fail):
        self.text, self.fail = text, fail
        self.operands: list[_Node] = []
        self.operators: list[list] = []  # [symbol, position, call name or None, argument count]
        self.open_parentheses = 0
        self.call_opened = False  # the previous token opened a call's parenthesis

    def error(self, position: int, reason: str) -> ModelError:
        return self.fail(f"cannot parse {_at(self.text, position)} at column {position + 1}: "
                         f"{reason}")

    def forbidden(self, message: str, position: int) -> ModelError:
        return self.fail(f"{message} (in {_at(self.text, position)})")

    def parse(self) -> _Node:
        tokens = list(_tokens(self.text, self.fail))
        expect_operand = True
        index = 0
        while True:
            kind, value, start, end = tokens[index]
            following = tokens[index + 1] if index + 1 < len(tokens) else ("end", "", end, end)
            index += 1
            call_opened, self.call_opened = self.call_opened, False
            if kind == "end":
                if expect_operand:
                    raise self.error(start, "the expression ends too early")
                while self.operators:
                    if self.operators[-1][0] == "(":
                        raise self.error(self.operators[-1][1], "'(' is never closed")
                    self.reduce()
                return self.operands[0]
            if kind in ("number", "bad"):
                if not expect_operand:
                    raise self.error(start, f"unexpected {value if kind == 'number' else 'text'} "
                                            f"(a missing operator?)")
                leaf = _literal(value, self.fail) if kind == "number" else value
                self.operands.append(_Node(kind, leaf, (), start, end))
                expect_operand = False
            elif kind == "name":
                self.name(value, start, end, following, expect_operand)
                if following[:2] == ("op", "(") and value not in ("True", "False", "None"):
                    index += 1  # the call's parenthesis is on the operator stack already
                    expect_operand = True
                    self.call_opened = True
                else:
                    expect_operand = False
            else:
                self.call_opened = call_opened
                expect_operand = self.operator(value, start, end, following, expect_operand)
                self.call_opened = False

    def name(self, name, start, end, following, expect_operand):
        if keyword.iskeyword(name) and name not in ("True", "False", "None"):
            messages = {
                "lambda": "lambda is not allowed", "if": "'if ... else' is not allowed",
                "else": "'if ... else' is not allowed", "and": "'and'/'or' are not allowed",
                "or": "'and'/'or' are not allowed", "for": "comprehensions are not allowed",
                "async": "comprehensions are not allowed", "await": "'await' is not allowed",
                "is": "comparisons are not allowed", "in": "comparisons are not allowed",
            }
            if name == "not":
                raise self.fail("the operator 'not' is not allowed")
            if name in messages:
                raise self.forbidden(messages[name], start)
            raise self.error(start, f"unexpected keyword '{name}'")
        if not expect_operand:
            raise self.error(start, f"unexpected name '{name}' (a missing operator?)")
        if name in ("True", "False", "None"):
            self.operands.append(
                _Node("bad", f"only numbers are allowed as constants, got {name}", (), start, end))
        elif following[:2] == ("op", "("):
            self.check_depth(start)
            self.operators.append(["(", following[2], (name, start), 0])
        else:
            self.operands.append(_Node("name", name, (), start, end))

    def operator(self, symbol, start, end, following, expect_operand) -> bool:
        """Handle one operator token; returns whether an operand comes next."""
        if symbol == "**":
            symbol = "^"
        if expect_operand:
            if symbol in ("+", "-"):
                self.operators.append(["neg" if symbol == "-" else "pos", start, None, 0])
                return True
            if symbol == "(":
                self.check_depth(start)
                self.operators.append(["(", start, None, 0])
                return True
            if symbol == ")" and self.call_opened:  # f(): no argument
                self.close(start, end, empty_call=True)
                return False
            if symbol == "[":
                raise self.forbidden("lists are not allowed in an expression", start)
            if symbol == "{":
                raise self.forbidden("dictionaries and sets are not allowed", start)
            if symbol == "*":
                raise self.forbidden("'*args' is not allowed", start)
            if symbol == "~":
                raise self.fail("the operator '~' is not allowed")
            if symbol == ")":
                raise self.error(start, "unexpected ')'")
            raise self.error(start, f"unexpected {symbol!r}")
        if symbol in ("+", "-", "*", "/", "^"):
            precedence = _PRECEDENCE[symbol]
            while self.operators and self.operators[-1][0] != "(" and (
                    _PRECEDENCE[self.operators[-1][0]] > precedence
                    or (_PRECEDENCE[self.operators[-1][0]] == precedence and symbol != "^")):
                self.reduce()
            self.operators.append([symbol, start, None, 0])
            return True
        if symbol == ")":
            self.close(start, end)
            return False
        if symbol == ",":
            while self.operators and self.operators[-1][0] != "(":
                self.reduce()
            if not self.operators or self.operators[-1][2] is None:
                raise self.forbidden("tuples are not allowed in an expression", start)
            self.operators[-1][3] += 1
            return True
        if symbol == ".":
            if following[0] == "name" and self.peek_call(following):
                raise self.fail(f"only the functions {', '.join(FUNCTIONS)} can be called")
            raise self.forbidden("attribute access ('.') is not allowed", start)
        if symbol == "(":
            raise self.fail(f"only the functions {', '.join(FUNCTIONS)} can be called")
        if symbol == "[":
            raise self.forbidden("indexing ('[...]') is not allowed", start)
        if symbol in _COMPARISONS:
            raise self.forbidden("comparisons are not allowed", start)
        if symbol in _FORBIDDEN_OPERATORS:
            raise self.forbidden(f"the operator {symbol!r} is not allowed", start)
        if symbol == ":=":
            raise self.forbidden("':=' is not allowed", start)
        if symbol == "=":
            call = next((op[2] for op in reversed(self.operators) if op[0] == "("), None)
            if call is not None:
                raise self.fail(f"{call[0]}() takes no keyword arguments")
        raise self.error(start, f"unexpected {symbol!r}")

    def peek_call(self, name_token) -> bool:
        rest = self.text[name_token[3]:].lstrip()
        return rest.startswith("(")

    def check_depth(self, position: int) -> None:
        self.open_parentheses += 1
        if self.open_parentheses > MAX_DEPTH:
            raise self.fail("the expression is nested too deeply")

    def close(self, start, end, *, empty_call=False):
        while self.operators and self.operators[-1][0] != "(":
            self.reduce()
        if not self.operators:
            raise self.error(start, "unexpected ')' (no '(' to close)")
        _, opened, call, count = self.operators.pop()
        self.open_parentheses -= 1
        if call is None:
            group = self.operands[-1]
            group.start, group.end = opened, end
            return
        count = 0 if empty_call else count + 1
        args = self.operands[len(self.operands) - count:] if count else []
        del self.operands[len(self.operands) - count:]
        depth = 1 + max((a.depth for a in args), default=0)
        self.operands.append(_Node("call", call[0], args, call[1], end, depth))
        self.limit(depth)

    def limit(self, depth: int) -> None:
        if depth > MAX_DEPTH:
            raise self.fail("the expression is nested too deeply")

    def reduce(self) -> None:
        symbol, position, _, _ = self.operators.pop()
        if symbol in ("neg", "pos"):
            operand = self.operands.pop()
            if symbol == "pos":
                operand.start = position
                self.operands.append(operand)
                return
            node = _Node("neg", None, [operand], position, operand.end, operand.depth + 1)
            self.limit(node.depth)
            self.operands.append(node)
            return
        right = self.operands.pop()
        left = self.operands.pop()
        if symbol == "^":
            node = _Node("pow", position, [left, right], left.start, right.end,
                         1 + max(left.depth, right.depth))
        else:
            kind = "add" if symbol in ("+", "-") else "mul"
            inverse = symbol in ("-", "/")
            if left.kind == kind and left.value is None:
                # a flat chain: a + b - c ... grows one node, not a nested tree
                left.children.append((inverse, right))
                left.end = right.end
                left.depth = max(left.depth, right.depth + 1)
                node = left
            else:
                node = _Node(kind, None, [(False, left), (inverse, right)], left.start,
                             right.end, 1 + max(left.depth, right.depth))
        self.limit(node.depth)
        self.operands.append(node)


def _check_names(tree: _Node, names: Mapping[str, sp.Expr], text: str, fail) -> None:
    """Every name, function and arity is checked before any arithmetic is done."""
    stack = [tree]
    while stack:
        node = stack.pop()
        if node.kind == "bad":
            raise fail(node.value)
        if node.kind == "name":
            name = node.value
            if name in names or name in CONSTANTS:
                continue
            if name in FUNCTIONS:
                raise fail(f"'{name}' is a function: call it as {name}(...)")
            known = list(names) + list(CONSTANTS)
            raise fail(f"unknown name '{name}'{did_you_mean(name, known)}")
        if node.kind == "call":
            name = node.value
            if name not in FUNCTIONS:
                raise fail(f"unknown function '{name}'{did_you_mean(name, FUNCTIONS)}")
            arity = FUNCTIONS[name][1]
            if len(node.children) != arity:
                raise fail(f"{name}() takes {arity} argument(s), got {len(node.children)}")
            stack.extend(reversed(node.children))
        elif node.kind in ("add", "mul"):
            stack.extend(child for _, child in reversed(node.children))
        else:
            stack.extend(reversed(node.children))


# -- conversion to sympy, with every constant bounded -----------------------------------------

class _Converter:
    """Builds sympy from the parsed tree. Beside each constant it carries a float twin, so a
    value that would be infinite, non-real or too large is refused before sympy works on it."""

    def __init__(self, names, fail, text):
        self.names = names
        self.fail = fail
        self.text = text
        self.name_values: dict[str, float | None] = {}

    def expression(self, tree: _Node) -> sp.Expr:
        expr, _ = self.visit(tree)
        self.final_check(expr)
        return expr

    def quote(self, node: _Node) -> str:
        return _quote(self.text, node.start, node.end)

    def visit(self, node: _Node) -> tuple[sp.Expr, float | None]:
        kind = node.kind
        if kind == "number":
            return node.value, float(node.value)
        if kind == "name":
            return self.name(node.value)
        if kind == "neg":
            operand, value = self.visit(node.children[0])
            return -operand, None if value is None else -value
        if kind == "add":
            return self.sum(node)
        if kind == "mul":
            return self.product(node)
        if kind == "pow":
            return self.power(node)
        return self.call(node)

    def name(self, name: str) -> tuple[sp.Expr, float | None]:
        expr = self.names[name] if name in self.names else CONSTANTS[name]
        if name not in self.name_values:
            self.name_values[name] = _float_of_constant(expr)
        return expr, self.name_values[name]

    def sum(self, node: _Node) -> tuple[sp.Expr, float | None]:
        terms, values = [], []
        for negative, child in node.children:
            expr, value = self.visit(child)
            terms.append(-expr if negative else expr)
            values.append(None if value is None else (-value if negative else value))
        self.check_work(terms, node)
        value = None
        if None not in values:
            value = math.fsum(values)
            if not abs(value) < _LIMIT:
                raise self.fail(f"the sum {self.quote(node)} is too large a number "
                                f"(beyond 1e{MAX_NUMBER_DIGITS})")
        result = sp.Add(*terms)
        self.check(result, node)
        return result, value if value is not None else _float_of_number(result)

    def product(self, node: _Node) -> tuple[sp.Expr, float | None]:
        factors, values = [], []
        for inverse, child in node.children:
            expr, value = self.visit(child)
            if inverse:
                if expr == 0:
                    raise self.fail(f"division by zero in {_quote(self.text)}")
                expr, value = 1 / expr, (1 / value) if value else None
            factors.append(expr)
            values.append(value)
        self.check_work(factors, node)
        value = None
        if None not in values:
            value = math.prod(values)
            if not abs(value) < _LIMIT:
                raise self.fail(f"the product {self.quote(node)} is too large a number "
                                f"(beyond 1e{MAX_NUMBER_DIGITS})")
        result = sp.Mul(*factors)
        self.check(result, node)
        return result, value if value is not None else _float_of_number(result)

    def check_work(self, operands: list[sp.Expr], node: _Node) -> None:
        """An exact sum or product of many rationals: refuse before sympy multiplies it out."""
        digits = sum(_digits(e.p) + _digits(e.q) for e in operands if e.is_Rational)
        if digits > _MAX_WORK_DIGITS:
            raise self.fail(f"the exact value of {self.quote(node)} has too many digits "
                            f"(more than {MAX_EXACT_DIGITS}): write it as a decimal number")

    def power(self, node: _Node) -> tuple[sp.Expr, float | None]:
        base, base_value = self.visit(node.children[0])
        exponent, exponent_value = self.visit(node.children[1])
        if exponent.is_Number and abs(exponent) > MAX_EXPONENT:
            raise self.fail(f"the exponent {exponent} is too large (at most {MAX_EXPONENT})")
        if base == 0 and (exponent.is_negative or (exponent_value or 0) < 0):
            raise self.fail(f"division by zero in {_quote(self.text)}")
        value: float | complex | None = None
        if base_value is not None and exponent_value is not None:
            try:
                value = base_value**exponent_value
            except OverflowError:
                value = math.inf
            except ZeroDivisionError:  # a base that underflowed to 0.0 (exp(-800)^-1)
                value = math.inf
            if not abs(value) < _LIMIT:
                raise self.fail(f"the power {self.quote(node)} is too large a number "
                                f"(beyond 1e{MAX_NUMBER_DIGITS})")
        self.check_power_cost(base, exponent, value, node)
        result = base**exponent
        if isinstance(value, complex):
            if not result.is_Number:  # rounding can make a zero base slightly negative
                raise self.fail(f"{self.quote(node)} is not a real number")
            value = float(result)
        self.check(result, node)
        return result, value if value is not None else _float_of_number(result)

    def check_power_cost(self, base, exponent, value, node) -> None:
        """Exact powers of rationals grow by digits, not by size: 1.0000001^1000 has 7000."""
        if not exponent.is_Rational or exponent.is_zero:
            return
        numerator, denominator = _exact_digits(base)
        if numerator + denominator == 0:
            return
        about = f" (about {value:.6g})" if isinstance(value, float) else ""
        size = round(math.ceil(abs(exponent)) * max(numerator, denominator))
        if size > MAX_EXACT_DIGITS:
            raise self.fail(f"the exact value of {self.quote(node)} has about {size} digits "
                            f"(at most {MAX_EXACT_DIGITS}): write it as a decimal number{about}")
        if exponent.q != 1 and exponent.q * (numerator + denominator) > _MAX_WORK_DIGITS:
            raise self.fail(f"the exact value of {self.quote(node)} is too costly to compute "
                            f"(a rational power with a {_digits(exponent.q)}-digit denominator): "
                            f"write it as a decimal number{about}")

    def call(self, node: _Node) -> tuple[sp.Expr, float | None]:
        name = node.value
        function = FUNCTIONS[name][0]
        visited = [self.visit(child) for child in node.children]
        args = [expr for expr, _ in visited]
        values = [value for _, value in visited]
        value = None
        outside_domain = False
        if None not in values:
            try:
                value = float(_FLOAT_FUNCTIONS[name](*values))
            except OverflowError:
                value = math.inf
            except (ValueError, ZeroDivisionError):
                outside_domain = True
            if value is not None and not abs(value) < _LIMIT:
                raise self.fail(f"the value of {self.quote(node)} is too large a number "
                                f"(beyond 1e{MAX_NUMBER_DIGITS})")
        result = function(*args)
        if outside_domain:
            # the float twin says log(0), sqrt(-1), asin(2), ...: sympy's exact value decides
            self.check(result, node)
            if not result.is_Number:
                raise self.fail(f"{self.quote(node)} is not a real number")
            value = float(result)
        self.check(result, node)
        return result, value if value is not None else _float_of_number(result)

    def check(self, expr: sp.Expr, node: _Node) -> None:
        """The value (or the numeric coefficient) of ``expr`` must be a finite real number."""
        candidates = [expr]
        if expr.is_Add or expr.is_Mul:
            candidates = list(expr.args[:2])
        for c in candidates:
            if any(c is infinity for infinity in _INFINITIES):
                raise self.fail(f"{self.quote(node)} is infinite")
            if c is sp.nan:
                raise self.fail(f"{self.quote(node)} is undefined (0/0, infinity - infinity, "
                                f"0*infinity or similar)")
            if c is sp.I:
                raise self.fail(f"{self.quote(node)} is not a real number")
            if c.is_Rational:
                if max(_digits(c.p), _digits(c.q)) > MAX_EXACT_DIGITS:
                    raise self.fail(f"the exact value of {self.quote(node)} has more than "
                                    f"{MAX_EXACT_DIGITS} digits: write it as a decimal number")
                if _digits(c.p) - _digits(c.q) > MAX_NUMBER_DIGITS:
                    raise self.fail(f"a number in {self.quote(node)} is too large "
                                    f"(beyond 1e{MAX_NUMBER_DIGITS})")
            elif c.is_Float and not math.isfinite(float(c)):
                raise self.fail(f"{self.quote(node)} is not finite")

    def final_check(self, expr: sp.Expr) -> None:
        """A last walk: no infinity, NaN or imaginary unit anywhere (from cancellations such
        as log(theta - theta))."""
        for part in sp.preorder_traversal(expr):
            if any(part is infinity for infinity in _INFINITIES):
                raise self.fail(f"{_quote(self.text)} is infinite")
            if part is sp.nan:
                raise self.fail(f"{_quote(self.text)} is undefined (NaN)")
            if part is sp.I:
                raise self.fail(f"{_quote(self.text)} is not a real number")


def _log10(value: int) -> float:
    return math.log10(abs(value)) if value else 0.0


def _exact_digits(base: sp.Expr) -> tuple[float, float]:
    """Digits (log10) of numerator and denominator of the rationals sympy multiplies out when
    it raises ``base`` to a rational power (its coefficient and rational radicals)."""
    numerator = denominator = 0.0
    for factor in (base.args if base.is_Mul else (base,)):
        if factor.is_Pow and factor.base.is_Rational and factor.exp.is_Rational:
            factor = factor.base
        if factor.is_Rational:
            numerator += _log10(factor.p)
            denominator += _log10(factor.q)
    return numerator, denominator


def _float_of_number(expr: sp.Expr) -> float | None:
    if expr.is_Number and expr.is_finite:
        value = float(expr)
        return value if math.isfinite(value) else None
    return None


def _float_of_constant(expr: object) -> float | None:
    """The float value of a name's value when it is a constant (pi, a constant definition)."""
    if not isinstance(expr, sp.Expr):
        return None
    if expr.is_Number:
        return _float_of_number(expr)
    if expr.free_symbols:
        return None
    try:
        value = complex(expr.evalf(20))
    except (TypeError, ValueError, OverflowError):
        return None
    if value.imag or not math.isfinite(value.real):
        return None
    return value.real
