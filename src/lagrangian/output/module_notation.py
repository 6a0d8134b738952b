"""Expressions written as the course module prints them: ½ m l² sin²θ φ̇, −m g L cosθ.

Greek names as letters, rates with a dot over (θ̇, θ̈), digits of a name as subscripts (x₁),
integer powers as superscripts, implicit multiplication by spaces, the Unicode minus. The
answer reader reads this notation back (model/answer_notation.py).
"""

from __future__ import annotations

import re
import unicodedata

import sympy as sp

GREEK = {
    "alpha": "α", "beta": "β", "gamma": "γ", "delta": "δ", "epsilon": "ε", "zeta": "ζ",
    "eta": "η", "theta": "θ", "iota": "ι", "kappa": "κ", "lambda": "λ", "mu": "μ", "nu": "ν",
    "xi": "ξ", "rho": "ρ", "sigma": "σ", "tau": "τ", "phi": "φ", "chi": "χ", "psi": "ψ",
    "omega": "ω", "Gamma": "Γ", "Delta": "Δ", "Theta": "Θ", "Lambda": "Λ", "Xi": "Ξ",
    "Sigma": "Σ", "Phi": "Φ", "Psi": "Ψ", "Omega": "Ω",
}
SUPERSCRIPTS = str.maketrans("0123456789-", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻")
SUBSCRIPTS = str.maketrans("0123456789", "₀₁₂₃₄₅₆₇₈₉")
DOT, DDOT = "\u0307", "\u0308"
MINUS = "−"
_LOWERED = set("₀₁₂₃₄₅₆₇₈₉")
_NAME = re.compile(r"^([A-Za-z]+?)(\d*)(_dot|_ddot)?$")


def symbol_notation(name: str) -> str:
    """theta1_dot -> θ̇₁, k_c -> k_c, x2 -> x₂."""
    match = _NAME.match(name)
    if match is None:
        return "_".join(symbol_notation(part) if part else part for part in name.split("_")) \
            if "_" in name else name
    body, digits, rate = match.groups()
    letters = GREEK.get(body, body)
    if rate:
        letters = letters[:-1] + letters[-1] + (DOT if rate == "_dot" else DDOT)
    return letters + digits.translate(SUBSCRIPTS)


def module_notation(expr: sp.Basic) -> str:
    """``expr`` in the module's printed notation."""
    expr = sp.sympify(expr)  # safe: sympy objects, never text
    return _add(expr)


def _add(expr: sp.Expr) -> str:
    if not expr.is_Add:
        return _signed(expr)
    text = ""
    for k, term in enumerate(expr.as_ordered_terms()):
        part = _signed(term)
        if k == 0:
            text = part
        elif part.startswith(MINUS):
            text += f" {MINUS} {part[1:]}"
        else:
            text += f" + {part}"
    return text


def _signed(expr: sp.Expr) -> str:
    coefficient, rest = expr.as_coeff_Mul()
    if coefficient.is_negative:
        return MINUS + _product(-coefficient, rest)
    return _product(coefficient, rest)


def _product(coefficient: sp.Expr, rest: sp.Expr) -> str:
    numerator, denominator = [], []
    for factor in sp.Mul.make_args(rest):
        if factor is sp.S.One:
            continue
        base, exponent = factor.as_base_exp()
        if exponent.is_number and exponent.is_negative and exponent != -sp.S.Half:
            denominator.append(base if exponent == -1 else sp.Pow(base, -exponent))
        else:
            numerator.append(factor)
    p, q = (coefficient.p, coefficient.q) if coefficient.is_Rational else (coefficient, 1)
    words = [_factor(f) for f in numerator]
    if coefficient.is_Rational and p == 1 and q == 2 and numerator:
        words.insert(0, "½")
        q = 1
    elif p != 1 or not numerator:
        words.insert(0, _number(p))
    text = " ".join(words)
    if q != 1 or denominator:
        below = " ".join([*([_number(q)] if q != 1 else []), *(_factor(f) for f in denominator)])
        wrap = len(denominator) + (q != 1) > 1 or (denominator and denominator[0].is_Add)
        text = f"{text}/({below})" if wrap else f"{text}/{below}"
    return text


def _number(value) -> str:
    if isinstance(value, int) or (isinstance(value, sp.Integer)):
        return str(value)
    return sp.sstr(value).replace("-", MINUS)


def _factor(expr: sp.Expr) -> str:
    if expr.is_Symbol:
        return symbol_notation(expr.name)
    if expr.is_Add:
        return f"({_add(expr)})"
    if expr.is_Pow:
        base, exponent = expr.args
        if exponent == sp.S.Half:
            return f"√({_add(base)})" if not base.is_Symbol else f"√{_factor(base)}"
        if exponent == -sp.S.Half:
            return f"1/√({_add(base)})"
        if exponent.is_Integer and exponent > 0:
            power = str(exponent).translate(SUPERSCRIPTS)
            if isinstance(base, sp.Function) and len(base.args) == 1:
                return _function(base, power)
            return _factor(base) + power
        return f"{_factor(base)}^({_add(exponent)})"
    if isinstance(expr, sp.Function):
        return _function(expr, "")
    if expr is sp.pi:
        return "π"
    return _add(expr) if expr.is_Mul else sp.sstr(expr)


def _function(expr: sp.Function, power: str) -> str:
    name = {"Abs": "abs"}.get(type(expr).__name__, type(expr).__name__)
    if len(expr.args) == 1 and expr.args[0].is_Symbol and name in ("sin", "cos", "tan"):
        letter = _factor(expr.args[0])
        bare = "".join(c for c in letter if not unicodedata.combining(c) and c not in _LOWERED)
        if len(bare) == 1:  # cosθ, sinφ₁; a longer name keeps its parentheses: cos(lam)
            return f"{name}{power}{letter}"
    inner = ", ".join(_add(a) for a in expr.args)
    return f"{name}{power}({inner})"


__all__ = ["module_notation", "symbol_notation"]
