"""Handout LaTeX of a derivation: `derive --format latex [--standalone]`.

Equations of motion are written M q_ddot + Phi_q^T lambda = f, one per coordinate, tagged with
its coordinate, accelerations on the left in coordinate order. Rows whose estimated printed
width passes a line are broken at top-level + and - (inside the outermost parentheses of a
product where needed); a matrix too wide for a line is listed entry by entry. User text (the
model's name) reaches LaTeX only through :func:`escape_text`.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from functools import lru_cache

import sympy as sp

from ..derivation.equations import EquationsOfMotion
from ..model.notation import ModelLatexPrinter, join_terms, model_latex_printer
from .derivation_display import _Display, _latex_letters

# Estimated printed width (pt, 10 pt Computer Modern, display style) a row may take. The
# standalone page is 453 pt wide (A4, 25 mm margins) and article's default column 345 pt:
# 320 pt leaves room for a tag and the estimate's error (within 15 % of pdflatex's widths).
LINE_WIDTH_PT = 320.0
STANDALONE_WIDTH_PT = 395.0  # the standalone page's own 453 pt, less a tag and the error

Terms = list[tuple[bool, str]]  # (negative, LaTeX of the magnitude), joined with + and -

# -- escaping user text -------------------------------------------------------------------------

_TEXT_ESCAPES = {
    # ASCII's specials as math or accents, not \textless and its kin: those live in the TS1
    # encoding, whose only fonts in a plain TeX Live are bitmaps drawn by METAFONT on first use
    "\\": r"\ensuremath{\backslash}", "{": r"\{", "}": r"\}", "$": r"\$", "&": r"\&", "%": r"\%",
    "#": r"\#", "_": r"\_", "^": r"\^{}", "~": r"\~{}",
    "<": r"\ensuremath{<}", ">": r"\ensuremath{>}", "|": r"\ensuremath{|}", '"': "''",
    # typography beyond Latin-1 that names often carry
    "\u2013": "--", "\u2014": "---", "\u2018": "`", "\u2019": "'", "\u201c": "``",
    "\u201d": "''", "\u2026": "...",
}


def escape_text(text: str) -> str:
    """Plain user text as LaTeX text that typesets it literally and runs nothing: every
    special character escaped, line breaks and control characters made spaces, characters
    pdflatex cannot set (outside Latin-1) made '?'."""
    out = []
    for char in text:
        if char in _TEXT_ESCAPES:
            out.append(_TEXT_ESCAPES[char])
        elif char < " " or char == "\x7f":
            out.append(" ")
        elif ord(char) > 0xFF or "\x80" <= char < "\xa0":
            out.append("?")
        else:
            out.append(char)
    return "".join(out)


# -- printed width, estimated -------------------------------------------------------------------

_TOKEN = re.compile(r"\\[A-Za-z]+|\\.|\S")  # commands, escaped characters, glyphs
_SPACES = {r"\,": 1.67, r"\;": 2.78, r"\:": 2.22, r"\!": -1.67, r"\quad": 10.0,
           r"\qquad": 20.0, "~": 3.33, r"\ ": 3.33}
_FUNCTIONS = {"sin", "cos", "tan", "cot", "sec", "csc", "sinh", "cosh", "tanh", "log", "ln",
              "exp", "arcsin", "arccos", "arctan", "max", "min"}
_ONE_ARGUMENT = {r"\dot", r"\ddot", r"\dddot", r"\mathrm", r"\mathit", r"\hat", r"\bar",
                 r"\tilde", r"\vec", r"\text", r"\mathsf", r"\operatorname"}
_DELIMITERS = {r"\left": 4.5, r"\right": 4.5, r"\bigl": 4.2, r"\bigr": 4.2, r"\Bigl": 4.8,
               r"\Bigr": 4.8, r"\biggl": 5.6, r"\biggr": 5.6}
_RELATIONS = {"=", "<", ">", r"\leq", r"\geq", r"\approx"}
_BINARY = {"+", "-", r"\cdot", r"\times"}
_SMALLER = {1.0: 0.7, 0.7: 0.5, 0.5: 0.5}  # display/text -> script -> scriptscript


def _glyph(char: str) -> float:
    if char.isdigit():
        return 5.0
    if char.isalpha():
        if char in "ijltfr":
            return 3.6
        if char in "mwMW":
            return 8.6 if char.islower() else 9.7
        return 7.6 if char.isupper() else 5.4
    return {"(": 3.9, ")": 3.9, "[": 2.8, "]": 2.8, ",": 4.5, ";": 4.5, ".": 2.8,
            "|": 2.8}.get(char, 7.8)


_GLYPHS = {char: _glyph(char) for char in
           "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789()[],;.|"}


class _TooWide(Exception):
    """Raised by a reader as soon as the width passes its room (long rows are read no further)."""


class _WidthReader:
    """Reads LaTeX math token by token, summing glyph widths (sizes by style); a group whose
    width passes its ``room`` raises _TooWide."""

    def __init__(self, text: str):
        self.tokens = _TOKEN.findall(text)
        self.position = 0

    def _next(self) -> str | None:
        if self.position >= len(self.tokens):
            return None
        self.position += 1
        return self.tokens[self.position - 1]

    def group(self, scale: float, fraction: float, room: float = math.inf) -> float:
        width, after_operand = 0.0, False
        while (token := self._next()) is not None and token != "}":
            w, after_operand = self._atom(token, scale, fraction, after_operand, room - width)
            width += w
            if width > room:
                raise _TooWide
        return width

    def _argument(self, scale: float, fraction: float, room: float) -> float:
        token = self._next()
        if token is None:
            return 0.0
        if token == "{":
            return self.group(scale, fraction, room)
        return self._atom(token, scale, fraction, False, room)[0]

    def _atom(self, token: str, scale: float, fraction: float, after_operand: bool,
              room: float) -> tuple[float, bool]:
        """(width, whether it ends an operand, so that a following +/- is binary)."""
        glyph = _GLYPHS.get(token)
        if glyph is not None:  # most tokens: a letter, a digit, a parenthesis
            return glyph * scale, token not in "(["
        if token == "{":
            return self.group(scale, fraction, room), True
        if token in "^_":
            small = _SMALLER[scale]
            return self._argument(small, _SMALLER[small], room) + 0.5, True
        if token in _RELATIONS:
            return 7.8 * scale + (5.56 if scale == 1.0 else 0.0), False
        if token in _BINARY:
            return 7.8 * scale + (4.44 if after_operand and scale == 1.0 else 0.0), False
        if token in _SPACES:
            return _SPACES[token] * scale, after_operand
        if token == r"\frac":
            numerator = self._argument(fraction, _SMALLER[fraction], room)
            denominator = self._argument(fraction, _SMALLER[fraction], room)
            return max(numerator, denominator) + 2.4, True
        if token == r"\sqrt":
            return self._argument(scale, fraction, room) + 8.3 * scale, True
        if token in _DELIMITERS:
            self._next()  # the delimiter itself
            return _DELIMITERS[token] * scale, token.endswith(("right", "r"))
        if token in _ONE_ARGUMENT:
            return self._argument(scale, fraction, room), True
        if token in (r"\mathcal", r"\mathbf"):
            return 1.3 * self._argument(scale, fraction, room), True
        if token.startswith("\\") and token[1:] in _FUNCTIONS:
            return (4.6 * (len(token) - 1) + 1.67) * scale, False
        if token.startswith("\\") and token[1:].isalpha():  # a Greek letter or symbol
            return (5.9 + (1.5 if token[1].isupper() else 0.0)) * scale, True
        if token.startswith("\\"):  # \_ \{ \}
            return 5.0 * scale, True
        return _glyph(token) * scale, token not in "(["


def estimated_width(latex: str) -> float:
    """The width in pt that ``latex`` (math, display style, 10 pt) is estimated to print at."""
    return _WidthReader(latex).group(1.0, 1.0)


@lru_cache(maxsize=1 << 16)  # a line's text is measured again as it grows (lines, terms)
def _width_within(latex: str, cap: float) -> float:
    """estimated_width, or inf past ``cap`` pt. A long text is first read in part: printed
    math takes more than 1/6 pt a character, and a part wider than the cap settles it."""
    try:
        prefix = int(6 * cap) + 100
        if len(latex) > prefix:
            _WidthReader(latex[:prefix]).group(1.0, 1.0, cap)
        return _WidthReader(latex).group(1.0, 1.0, cap)
    except _TooWide:
        return math.inf


def fits(latex: str, width: float) -> bool:
    """Whether ``latex`` is estimated to print within ``width`` pt (read only that far)."""
    return _width_within(latex, width) <= width


# -- breaking sums over lines -------------------------------------------------------------------


class _Breaker:
    """Prints expressions as terms that a line may be broken between."""

    def __init__(self, printer: ModelLatexPrinter, width: float = LINE_WIDTH_PT):
        self.printer, self.width = printer, width

    def terms(self, expr: sp.Expr, width: float | None = None, whole: bool = True) -> Terms:
        """expr as terms (one, with ``whole``, when it all fits); a term wider than ``width``
        (pt) is opened at its widest sum."""
        width = self.width if width is None else width
        if whole:
            text = self.printer.doprint(expr)
            if fits(text, width):
                return [_signed(text)]
        out: Terms = []
        for term in self._ordered(expr):
            negative, text = _signed(self.printer.doprint(term))
            if fits(text, width):
                out.append((negative, text))
            else:
                out += self._opened(negative, -term if negative else term, text, width)
        return out

    def product_terms(self, pairs: Sequence[tuple[sp.Expr, sp.Symbol]], width: float) -> Terms:
        """coefficient * unknown terms; a coefficient too wide for a line opened at its
        widest sum, the unknown after the closing parenthesis."""
        out: Terms = []
        for pair, (negative, text) in zip([p for p in pairs if p[0] != 0],
                                          self.printer.product_terms(pairs), strict=True):
            if fits(text, width):
                out.append((negative, text))
                continue
            coefficient, unknown = pair
            magnitude = -coefficient if negative else coefficient
            out += self._opened(negative, magnitude, text, width,
                                " " + self.printer.doprint(unknown))
        return out

    def _ordered(self, expr: sp.Expr) -> list[sp.Expr]:
        return self.printer.terms_in_order(expr)

    def _opened(self, negative: bool, term: sp.Expr, text: str, width: float,
                suffix: str = "") -> Terms:
        """term = rest * (a + b + ...) as ``rest \\Bigl(a`` + ``b`` ... + ``c\\Bigr)``, then
        ``suffix``."""
        sums = [f for f in sp.Mul.make_args(term) if f.is_Add]
        if not sums:
            return [(negative, text)]  # nothing to open: a function's argument, a power
        widest = max(sums, key=lambda f: len(self.printer.doprint(f)))  # the longest
        rest = sp.Mul(*[f for f in sp.Mul.make_args(term) if f is not widest])
        inner = self.terms(widest, width, whole=False)  # the sum, to break inside
        big = r"\biggl(" if any(r"\frac" in t for _, t in inner) else r"\Bigl("
        close = r"\biggr)" if big == r"\biggl(" else r"\Bigr)"
        first_negative, first = inner[0]
        prefix = "" if rest == 1 else self.printer.doprint(rest) + " "
        opened = [(negative, f"{prefix}{big}{'- ' if first_negative else ''}{first}"),
                  *inner[1:]]
        last_negative, last = opened[-1]
        opened[-1] = (last_negative, last + close + suffix)
        return opened


def _signed(text: str) -> tuple[bool, str]:
    return (True, text[1:].lstrip()) if text.startswith("-") else (False, text)


def lines(terms: Terms, first_width: float, width: float) -> list[str]:
    """The terms filled greedily into lines: the first line ``first_width`` wide, the rest
    ``width``; a line after the first starts ``{} + `` or ``{} - `` (a binary sign)."""
    out: list[str] = []
    current: Terms = []
    room, used = first_width, 0.0
    for negative, text in terms:
        # a term's width once (each read no further than a line), plus its sign's
        sign = 0.0 if text.startswith("= ") else 12.2 if current or out else (
            7.8 if negative else 0.0)
        taken = _width_within(text, width + 1.0) + sign
        if current and used + taken > room:
            out.append(_joined(current, bool(out)))
            current, room, used = [(negative, text)], width, taken + (0.0 if sign else 12.2)
        else:
            current.append((negative, text))
            used += taken
    out.append(_joined(current, bool(out)))
    return out


def _joined(terms: Terms, continued: bool) -> str:
    """Terms as one line; a term that begins with '= ' (the right side) follows with no sign."""
    text = ""
    for negative, term in terms:
        if term.startswith("= "):
            text = f"{text} {term}" if text else term
        elif not text:
            text = ("{} - " if continued else "- ") + term if negative else (
                "{} + " + term if continued else term)
        else:
            text += f" - {term}" if negative else f" + {term}"
    return text or "0"


# -- the document -------------------------------------------------------------------------------


class _Handout:
    def __init__(self, eom: EquationsOfMotion, width: float = LINE_WIDTH_PT,
                 expand: bool = False):
        self.eom, self.model = eom, eom.model
        self.printer = model_latex_printer(eom.model)
        self.display = _Display(eom, expand)
        self.breaker = _Breaker(self.printer, width)
        self.width = width
        self.letters = _latex_letters(eom.model)

    def tex(self, expr) -> str:
        return self.printer.doprint(expr)

    def row(self, label: str, expr: sp.Expr, lead: str = "") -> list[str]:
        """``label &= lead expr`` in align, broken into continuation rows ``&\\quad {} + ...``."""
        room = self.width - estimated_width(label) - estimated_width(lead) - 14.0
        rest = self.width - estimated_width(label) - 24.0
        parts = lines(self.breaker.terms(expr, min(room, rest)), room, rest)
        rows = [f"{label} &= {lead}{parts[0]}"]
        rows += [rf"&\quad {part}" for part in parts[1:]]
        return rows

    def definitions(self) -> list[str]:
        eom, k, form = self.eom, self.letters, self.display.form
        rows = self.coordinate_rows()
        rows += self.row(k["T"], form(eom.kinetic_energy))
        rows += self.row(k["V"], form(eom.potential_energy))
        if eom.dissipation != 0:
            rows += self.row(k["D"], form(eom.dissipation))
        rows += self.row(k["L"], self.display.lagrangian(eom), lead=f"{k['T']} - {k['V']} = ")
        for c, total in zip(self.model.coordinates, eom.generalized_forces, strict=True):
            rows += self.row(f"{k['Q']}_{{{self.tex(c.symbol)}}}", form(total))
        return _environment("align", rows, notag=True)

    def intermediates(self) -> list[str]:
        """The named quantities the rest is written in (large equations only), one a row."""
        named = self.display.intermediates
        if named is None:
            return []
        rows = []
        for symbol, expr in named.definitions:
            rows += self.row(self.tex(symbol), expr)
        return _environment("align*", rows)

    def coordinate_rows(self) -> list[str]:
        """``q = (q_1, q_2, ...)``, continued on further rows when too long for one."""
        names = [self.tex(c.symbol) for c in self.model.coordinates]
        parts, current = [], []
        for name in names:
            if current and not fits(", ".join([*current, name]), self.width - 60.0):
                parts.append(", ".join(current) + ",")
                current = []
            current.append(name)
        parts.append(", ".join(current))
        if len(parts) == 1:
            return [rf"\mathbf{{q}} &= \left({parts[0]}\right)"]
        return [rf"\mathbf{{q}} &= \bigl({parts[0]}", *(rf"&\quad {p}" for p in parts[1:-1]),
                rf"&\quad {parts[-1]}\bigr)"]

    def equation_sides(self, i: int) -> tuple[list[tuple[sp.Expr, sp.Symbol]], sp.Expr]:
        """Row i as (coefficient, unknown) pairs, M_ij q_ddot_j then (Phi_q)_ki lambda_k, and
        the right side f_i, each in its readable form."""
        eom, form = self.eom, self.display.form
        pairs = [(form(eom.mass_matrix[i, j]), a) for j, a in enumerate(self.model.q_ddot)]
        pairs += [(self.display.plain(eom.constraint_jacobian[k, i]), eom.multipliers[k])
                  for k in range(eom.constraint_jacobian.rows)]
        return pairs, form(eom.forcing[i])

    def equations(self) -> list[str]:
        """One equation per coordinate, tagged with it: on one line where it fits, else rows
        with the right side's lines under the '=' (or, after a wide left side, the '='
        starting a row of its own)."""
        out = []
        for i, c in enumerate(self.model.coordinates):
            pairs, right = self.equation_sides(i)
            left = join_terms(self.printer.product_terms(pairs))
            tag = rf"\tag{{${self.tex(c.symbol)}$}}"
            single = f"{left} = {self.tex(right)}"
            if fits(single, self.width):
                out += [r"\begin{equation}", f"{single} {tag}", r"\end{equation}"]
                continue
            if fits(left, 0.45 * self.width):
                left_width = estimated_width(left)
                room = self.width - left_width - 14.0
                parts = lines(self.breaker.terms(right, room - 10.0), room, room - 10.0)
                rows = [f"{left} &= {parts[0]}", *(rf"&\quad {p}" for p in parts[1:])]
            else:
                room = self.width - 24.0
                left_lines = lines(self.breaker.product_terms(pairs, room), room, room)
                parts = lines(self.breaker.terms(right, room), room, room)
                rows = [f"&{left_lines[0]}", *(rf"&\quad {p}" for p in left_lines[1:]),
                        f"&= {parts[0]}", *(rf"&\quad {p}" for p in parts[1:])]
            # rows of an align, not a split: \allowdisplaybreaks may break a long one
            out += [r"\begin{align}", *(row + r" \notag \\" for row in rows[:-1]),
                    f"{rows[-1]} {tag}", r"\end{align}"]
        return out

    def matrix(self, label: str, matrix: sp.MatrixBase, symmetric: bool = False,
               plain: bool = False) -> list[str]:
        """``label &= [matrix]``, or its nonzero entries one per row when too wide."""
        form = self.display.matrix(matrix, plain)
        entries = [[self.tex(v) for v in form.row(i)] for i in range(form.rows)]
        room = self.width - 10.0 * (form.cols - 1) - 12.0 - estimated_width(label)
        if all(fits(entry, room) for row in entries for entry in row) and sum(
                max(estimated_width(row[j]) for row in entries) for j in range(form.cols)) <= room:
            body = r" \\ ".join(" & ".join(row) for row in entries)
            return [rf"{label} &= \begin{{bmatrix}} {body} \end{{bmatrix}}"]
        rows = []
        for i in range(form.rows):
            for j in range(form.cols):
                if form[i, j] != 0 and not (symmetric and j < i):
                    index = (f"{i + 1}" if form.cols == 1 else f"{i + 1}{j + 1}"
                             if max(form.shape) < 10 else f"{i + 1},{j + 1}")  # M_{9,21}
                    rows += self.row(f"{label}_{{{index}}}", form[i, j])
        return rows or [rf"{label} &= 0"]

    def matrices(self) -> list[str]:
        eom, k = self.eom, self.letters
        rows = self.matrix(k["M"], eom.mass_matrix, symmetric=True)
        rows += self.matrix(k["f"], eom.forcing)
        if self.model.constraints:
            rows += self.matrix(r"\Phi_q", eom.constraint_jacobian, plain=True)
            rows += self.matrix(r"\gamma", eom.acceleration_rhs, plain=True)
        return _environment("align*", rows)


def _environment(name: str, rows: Sequence[str], notag: bool = False) -> list[str]:
    end = r" \notag \\" if notag else r" \\"
    last = r" \notag" if notag else ""
    return [rf"\begin{{{name}}}", *(row + end for row in rows[:-1]), rows[-1] + last,
            rf"\end{{{name}}}"]


_PREAMBLE = r"""\documentclass[10pt,a4paper]{article}
\usepackage[margin=25mm]{geometry}
\usepackage{amsmath,amssymb}
\allowdisplaybreaks
"""


def handout_latex(eom: EquationsOfMotion, standalone: bool = False,
                  expand: bool = False) -> str:
    """The derivation as LaTeX (amsmath): a fragment to paste into a paper, or with
    ``standalone`` a complete document for pdflatex, titled with the model's name; large
    equations in named intermediate quantities, unless ``expand``."""
    try:
        return _handout_latex(eom, standalone, expand)
    finally:
        _width_within.cache_clear()  # the texts measured belong to this document only


def _handout_latex(eom: EquationsOfMotion, standalone: bool, expand: bool) -> str:
    handout = _Handout(eom, STANDALONE_WIDTH_PT if standalone else LINE_WIDTH_PT, expand)
    name = escape_text(eom.model.name)
    k = handout.letters
    constraint = r" + \Phi_q^T \lambda" if eom.model.constraints else ""
    convention = rf"{k['M']} \ddot{{\mathbf{{q}}}}{constraint} = {k['f']}"
    named = handout.intermediates()
    blocks = [
        *([("Intermediate quantities (each in the ones before it; the rest is written in "
            "them)", named)] if named else []),
        ("Energies, Lagrangian and generalized forces", handout.definitions()),
        (rf"Equations of motion, ${convention}$, one per coordinate", handout.equations()),
        ("Mass matrix and forcing" + (", constraints" if eom.model.constraints else ""),
         handout.matrices()),
    ]
    if not standalone:
        lines_ = [f"% {name}: equations of motion by Lagrange's method",
                  f"% Convention: {convention}"]
        for heading, block in blocks:
            lines_ += [f"% {heading}", *block]
        return "\n".join(lines_) + "\n"
    body = [_PREAMBLE.rstrip("\n"), rf"\title{{{name}}}",
            r"\author{Equations of motion by Lagrange's method}", r"\date{}",
            r"\begin{document}", r"\maketitle"]
    for heading, block in blocks:
        body += [rf"\section*{{{heading}}}", *block]
    body.append(r"\end{document}")
    if not "".join(body).isascii():  # Latin-1 text needs T1 (EC fonts); ASCII keeps Type 1 CM
        body.insert(1, r"\usepackage[T1]{fontenc}")
    return "\n".join(body) + "\n"
