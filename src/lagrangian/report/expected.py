"""The check section's "expected" column as MathML, like the rest of the page.

A finding's expected answer is text in the model-file grammar (check/diagnose.py writes it with
format_expression): an expression, an equation "lhs = rhs" or a list "a, b". It is read back by
the grammar's own whitelist parser (never evaluated) in the model's names, a name it does not
know (a momentum p_phi of [hamiltonian]) read as a plain symbol, and written by the page's
MathWriter. Text that does not read as the grammar stays text.
"""

from __future__ import annotations

import re

import sympy as sp

from ..errors import ModelError
from ..model.answer import answer_names
from ..model.expressions import FUNCTIONS, RESERVED, parse_expression
from .html import Markup, math
from .mathml import math_inline, mo

_NAME = re.compile(r"(?<![\w.])([A-Za-z][A-Za-z0-9_]*)(?!\s*\()")
_MAX_TEXT = 4000  # characters: beyond this the expected answer is shown as the text it is


def _pieces(text: str) -> list[str] | None:
    """The top-level pieces of ``text`` split at ", " (outside parentheses), or None."""
    pieces, depth, start = [], 0, 0
    for i, char in enumerate(text):
        if char in "([":
            depth += 1
        elif char in ")]":
            depth -= 1
        elif char == "," and depth == 0:
            pieces.append(text[start:i].strip())
            start = i + 1
    pieces.append(text[start:].strip())
    return pieces if all(pieces) else None


def expected_markup(writer, model, text: str | None) -> Markup | str:
    """The expected answer ``text`` as inline MathML, or the text itself where it does not
    read as the model grammar (a word such as "none")."""
    if not text:
        return ""
    if len(text) > _MAX_TEXT:
        return text
    names = dict(answer_names(model))
    if _NAME.fullmatch(text.strip()) and text.strip() not in names:
        return text  # a word ("none"), not an expression
    for name in _NAME.findall(text):
        if name not in names and name not in RESERVED and name not in FUNCTIONS:
            names[name] = sp.Symbol(name)
    rows = []
    for piece in _pieces(text) or [text]:
        sides = piece.split(" = ")
        try:
            parsed = [parse_expression(side, names, field="expected") for side in sides]
        except ModelError:
            return text
        row = []
        for i, side in enumerate(parsed):
            row.append((mo("=") if i else "") + writer(side))
        rows.append("".join(row))
    return math(math_inline(mo(",").join(rows)))
