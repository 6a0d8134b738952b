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
from collections.abc import Mapping

import sympy as sp

from ..errors import ModelError, did_you_mean
from .expression_values import _Converter
from .grammar import (  # noqa: F401 - the grammar's names, re-exported
    _LIMIT,
    CONSTANTS,
    FUNCTIONS,
    IDENTIFIER,
    MAX_DEPTH,
    MAX_EXACT_DIGITS,
    MAX_EXPONENT,
    MAX_LENGTH,
    MAX_NUMBER_DIGITS,
    MAX_TREE_NODES,
    RESERVED,
    _digits,
    _Node,
)
from .printing import as_expression, format_expression  # noqa: F401 - the grammar's printer, re-exported
from .tokens import _COMPARISONS, _FORBIDDEN_OPERATORS, _PRECEDENCE, _at, _quote, _tokens


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
            raise fail(f"the number {text} is too large (every number must be below "
                       f"1e{MAX_NUMBER_DIGITS} in size)")
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
