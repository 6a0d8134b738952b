"""An answer written as the course module prints it, read into the grammar's ASCII.

The module writes ½ m L² θ̇², −m g L cosθ, p_φ²/(2 m l² sin²θ) and √(g/L): multiplication by
spaces (or a middle dot), a function applied to a name without parentheses, √ for sqrt. This
pass rewrites such text token by token (model/tokens.py reads the Unicode spellings) into the
model grammar, inserting * and parentheses; nothing is evaluated. It is used for answers only:
a model file keeps its explicit grammar. A prime (theta', θ') is refused with the spelling to
use. The module's Lagrange equation, d/dt(m L² θ̇) + m g L sinθ = 0, is read with each d/dt(...)
cut out (time_derivative_parts) and taken as the total time derivative of what it holds.
"""

from __future__ import annotations

import re

from ..errors import ModelError
from ..spelling import FRACTIONS, SUPERSCRIPTS
from .expressions import FUNCTIONS
from .tokens import _tokens

# a name and a prime after it (theta', θ''); given as a hint only where the text reads with
# the primes spelled as rates (not a quoted string, '__import__('os')')
_PRIME = re.compile(r"([^\W\d]\w*|[^\x00-\x7f][\u0300-\u036f]*)\s*('{1,2}|\u2032|\u2033)")
_SUPER = "".join(SUPERSCRIPTS)
_FRACTION = "".join(FRACTIONS)
# a function name glued to what it applies to (cosθ, sin²θ), a power or a fraction glued to a
# name (L²θ̇, ½m): a space between them, read as the module means it
_GLUED_FUNCTION = re.compile(
    r"(?<![A-Za-z_])(" + "|".join(sorted(FUNCTIONS, key=len, reverse=True)) +
    r")(?=[" + _SUPER + r"]|[^\x00-\x7f])")
_GLUED_POWER = re.compile(r"([" + _SUPER + r"])(?=[^\W\d_" + _SUPER + r"])")
_GLUED_FRACTION = re.compile(r"([" + _FRACTION + r"])(?=[^\s*/+\-)])")
_ROOT = re.compile("\u221a")
# a number glued to a Greek or other non-ASCII letter (2π, 2θ): the module's product, kept
# together as one operand (sin 2θ is sin(2θ)) unless a power or more letters follow (2θ², 2πf)
_GLUED_NUMBER = re.compile(r"(?<![\w.])(\d+(?:\.\d+)?)([^\W\d_\x00-\x7f][\u0300-\u036f]*)"
                           r"(?![\w\u0300-\u036f" + _SUPER + r"])")
_GLUED_NUMBER_BEFORE = re.compile(r"(?<![\w.])(\d+(?:\.\d+)?)(?=[^\W\d_\x00-\x7f])")
# d/dt( opening a total time derivative, not part of a longer name (rad/dt)
_TIME_DERIVATIVE = re.compile(r"(?<![\w.])d\s*/\s*dt\s*\(")
_OPERAND_END = ("name", "number", ")")


def primes_as_rates(text: str) -> str | None:
    """``text`` with each prime spelled as a rate (theta' as theta_dot), None without one."""
    if _PRIME.search(text) is None:
        return None
    return _PRIME.sub(lambda m: m.group(1) + ("_ddot" if m.group(2) in ("''", "\u2033")
                                              else "_dot"), text)


def prime_hint(text: str) -> str | None:
    """The spelling hint for a prime (theta', θ'), or None."""
    match = _PRIME.search(text)
    if match is None:
        return None
    name, marks = match.group(1), match.group(2)
    double = marks in ("''", "\u2033")
    spelled = next((kind_value[1] for kind_value in _safe_tokens(name)
                    if kind_value[0] == "name"), name)
    rate = f"{spelled}_ddot" if double else f"{spelled}_dot"
    return (f"{match.group(0).strip()!r}: a prime is not read: write {rate} for "
            f"{'an acceleration' if double else 'a rate'} (or the dotted letter)")


def _safe_tokens(text: str) -> list[tuple[str, str]]:
    try:
        return [(kind, value) for kind, value, _, _ in
                _tokens(text, lambda message: ModelError(message))]
    except ModelError:
        return []


def module_notation_text(text: str) -> str | None:
    """``text`` in the grammar's ASCII when it uses the module's notation (implicit products,
    a function applied without parentheses, √); None when it needs no rewriting (the grammar
    reads it as it is) or does not tokenize (the grammar's own message is then given)."""
    spaced = _GLUED_FUNCTION.sub(r"\1 ", text)
    spaced = _GLUED_POWER.sub(r"\1 ", spaced)
    spaced = _GLUED_FRACTION.sub(r"\1 ", spaced)
    spaced = _ROOT.sub(" sqrt ", spaced)
    spaced = _GLUED_NUMBER.sub(r"(\1 \2)", spaced)
    spaced = _GLUED_NUMBER_BEFORE.sub(r"\1 ", spaced)
    tokens = _safe_tokens(spaced)
    if not tokens:
        return None
    tokens = [t for t in tokens if t[0] != "end"]
    out, changed = _rewrite(tokens)
    changed = changed or spaced != text
    return "".join(value if kind != "name" else f" {value} " for kind, value in out) \
        if changed else None


def time_derivative_parts(text: str, prefix: str) -> tuple[str, list[tuple[str, str]]] | None:
    """``text`` with each outermost d/dt(...) replaced by a name ``prefix``1, ``prefix``2, ...,
    and each name with the text inside its parentheses; None without a d/dt( or where its
    parentheses do not close (the grammar's own message is then given)."""
    parts: list[tuple[str, str]] = []
    out, start = [], 0
    for match in _TIME_DERIVATIVE.finditer(text):
        if match.start() < start:
            continue  # inside a d/dt already cut out: read with it
        depth, end = 1, match.end()
        while end < len(text) and depth:
            depth += {"(": 1, ")": -1}.get(text[end], 0)
            end += 1
        if depth:
            return None
        name = f"{prefix}{len(parts) + 1}"
        parts.append((name, text[match.end():end - 1]))
        out += [text[start:match.start()], f" {name} "]
        start = end
    if not parts:
        return None
    return "".join(out) + text[start:], parts


def _is_function(token: tuple[str, str]) -> bool:
    return token[0] == "name" and token[1] in FUNCTIONS


def _rewrite(tokens: list[tuple[str, str]]) -> tuple[list[tuple[str, str]], bool]:
    out: list[tuple[str, str]] = []
    changed = False
    i = 0
    while i < len(tokens):
        token = tokens[i]
        if _is_function(token) and i + 1 < len(tokens) and tokens[i + 1] != ("op", "("):
            # sin θ, sin² θ, sin²(θ₁ − θ₂): the function of one operand, the power after it
            j, power = i + 1, []
            if tokens[j] == ("op", "**"):
                k = j + 1
                if k < len(tokens) and tokens[k] == ("op", "("):
                    depth, m = 0, k
                    while m < len(tokens):
                        depth += tokens[m] == ("op", "(")
                        depth -= tokens[m] == ("op", ")")
                        m += 1
                        if depth == 0:
                            break
                    power, j = tokens[j:m], m
                elif k < len(tokens):
                    power, j = tokens[j:k + 1], k + 1
            operand, j = _operand(tokens, j)
            if not operand:
                out.append(token)
                i += 1
                continue
            _join(out, ("name", token[1]))
            out += [("op", "("), *operand, ("op", ")"), *power]
            changed = True
            i = j
            continue
        changed |= _join(out, token)
        i += 1
    return out, changed


def _operand(tokens: list[tuple[str, str]], j: int) -> tuple[list[tuple[str, str]], int]:
    """The operand a bare function applies to: a parenthesized group, or a name or number with
    its power (θ, x₁², 2), none where something else follows."""
    if j >= len(tokens):
        return [], j
    if tokens[j] == ("op", "("):
        depth, m = 0, j
        while m < len(tokens):
            depth += tokens[m] == ("op", "(")
            depth -= tokens[m] == ("op", ")")
            m += 1
            if depth == 0:
                break
        return tokens[j:m], m
    if tokens[j][0] in ("name", "number") and not _is_function(tokens[j]):
        end = j + 1
        if end + 1 < len(tokens) and tokens[end] == ("op", "**") and \
                tokens[end + 1][0] == "number":
            end += 2
        return tokens[j:end], end
    return [], j


def _join(out: list[tuple[str, str]], token: tuple[str, str]) -> bool:
    """Append ``token``, with a * before it where two operands meet (m g, 2 m, ) (, L θ̇);
    True when a * was inserted."""
    previous = out[-1] if out else None
    starts = token[0] in ("name", "number") or token == ("op", "(")
    ends = previous is not None and (previous[0] in ("name", "number") or previous == ("op", ")"))
    call = previous is not None and _is_function(previous) and token == ("op", "(")
    if starts and ends and not call:
        out += [("op", "*"), token]
        return True
    out.append(token)
    return False


__all__ = ["module_notation_text", "prime_hint", "primes_as_rates", "time_derivative_parts"]
