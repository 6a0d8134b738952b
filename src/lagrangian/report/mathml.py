"""Math for HTML pages as MathML (presentation markup), which browsers render without JavaScript
(MathML Core: Chromium 109+, Firefox, Safari); see docs/dependencies.md for why MathML.

sympy's presentation printer builds the markup as a DOM; it is serialized here, not by sympy, so
that every piece of text (a symbol's name, a constraint's name) is escaped by construction:
sympy writes text nodes unescaped (``Symbol("a<b")`` gives ``<mi>a<b</mi>``). Velocities and
accelerations are written with dots over their coordinate (theta_dot as a dotted theta),
multipliers as lambda with their constraint's name below.
"""

from __future__ import annotations

import html
import re
from xml.dom import minidom

import sympy as sp
from sympy.printing.mathml import MathMLPresentationPrinter

from ..model.model import Model, multiplier_name

DOT, DOUBLE_DOT = "\u02d9", "\u00a8"  # the accents over a velocity and an acceleration
# Text that sympy's printer writes as an entity on purpose (&InvisibleTimes;, &#x221E;).
_ENTITY = re.compile(r"&(#x[0-9A-Fa-f]+|#[0-9]+|[A-Za-z]+);?")
# Tags sympy's printer may use that MathML Core leaves out, mapped to what Core renders.
_CORE_TAGS = {"mfenced": "mrow"}
_FENCES = {"(", ")", "[", "]", "{", "}", "|"}
_TALL = ("mfrac", "mtable", "msqrt", "mroot", "munderover", "munder")


def escape(text: str) -> str:
    """Text for HTML or MathML content or a quoted attribute: & < > " ' escaped."""
    return html.escape(str(text), quote=True)


def mi(text: str) -> str:
    return f"<mi>{escape(text)}</mi>"


def mo(text: str) -> str:
    return f"<mo>{escape(text)}</mo>"


def mn(value: float | int | str) -> str:
    return f"<mn>{escape(value)}</mn>"


def mtext(text: str) -> str:
    return f"<mtext>{escape(text)}</mtext>"


def mrow(*parts: str) -> str:
    return f"<mrow>{''.join(parts)}</mrow>"


def math_block(*parts: str) -> str:
    """A displayed formula of the given (already built) MathML parts."""
    return f'<math display="block">{"".join(parts)}</math>'


def math_inline(*parts: str) -> str:
    return f"<math>{''.join(parts)}</math>"


def _text(node: minidom.Text) -> str:
    data = node.data
    if _ENTITY.fullmatch(data):  # a character sympy wrote as an entity: the character itself
        data = html.unescape(data if data.endswith(";") else data + ";")
    return escape(data)


def serialize(node) -> str:
    """A DOM node as markup, every text and attribute escaped."""
    if node.nodeType == node.TEXT_NODE:
        if node.data == "-" and getattr(node.parentNode, "tagName", "") == "mo":
            return "\u2212"  # the minus sign, not a hyphen
        return _text(node)
    if node.nodeType != node.ELEMENT_NODE:
        return ""
    tag = _CORE_TAGS.get(node.tagName, node.tagName)
    children = "".join(serialize(child) for child in node.childNodes)
    if node.tagName == "mfenced":  # (a, b) as a row between its fences
        children = (mo(node.getAttribute("open") or "(") + children
                    + mo(node.getAttribute("close") or ")"))
        return f"<{tag}>{children}</{tag}>"
    attributes = "".join(f' {escape(name)}="{escape(value)}"'
                         for name, value in node.attributes.items())
    if tag == "mrow" and _fenced(node) and not _tall(node):
        # Parentheses around one line of math keep their text size: a stretched variant (Latin
        # Modern Math's) stands apart from what it encloses, as "( m1 + m2 )".
        first, last = serialize(node.firstChild), serialize(node.lastChild)
        middle = "".join(serialize(child) for child in node.childNodes[1:-1])
        children = (first.replace("<mo>", '<mo stretchy="false">', 1) + middle
                    + last.replace("<mo>", '<mo stretchy="false">', 1))
    return f"<{tag}{attributes}>{children}</{tag}>"


def _fenced(node) -> bool:
    """A row between two fences: (, [, { ... ), ], }."""
    items = [c for c in node.childNodes if c.nodeType == c.ELEMENT_NODE]
    return (len(items) >= 2 and len(items) == len(node.childNodes)
            and all(i.tagName == "mo" and i.firstChild is not None
                    and i.firstChild.nodeType == i.TEXT_NODE and i.firstChild.data in _FENCES
                    for i in (items[0], items[-1])))


def _tall(node) -> bool:
    """Whether a row holds something taller than a line (a fraction, a matrix, a root)."""
    return any(node.getElementsByTagName(tag) for tag in _TALL)


class _Printer(MathMLPresentationPrinter):
    """sympy's presentation printer with the model's symbols written as a reader expects."""

    def __init__(self, model: Model | None, settings: dict | None = None):
        super().__init__({"mat_delim": "[", **(settings or {})})
        self._dots: dict[sp.Symbol, tuple[sp.Symbol, str]] = {}
        self._multipliers: dict[sp.Symbol, str] = {}
        if model is not None:
            for c in model.coordinates:
                self._dots[c.velocity] = (c.symbol, DOT)
                self._dots[c.acceleration] = (c.symbol, DOUBLE_DOT)
            for constraint in model.constraints:
                self._multipliers[sp.Symbol(multiplier_name(constraint.name))] = constraint.name

    def _print_Symbol(self, sym, style="plain"):
        if sym in self._dots:
            base, accent = self._dots[sym]
            printed = super()._print_Symbol(base, style)
            # theta_1: the dot over theta, the index beside it (as in a textbook)
            target = printed.firstChild if printed.nodeName == "msub" else printed
            over = self.dom.createElement("mover")
            over.setAttribute("accent", "true")
            mark = self.dom.createElement("mo")
            mark.appendChild(self.dom.createTextNode(accent))
            if target is printed:
                over.appendChild(printed)
                over.appendChild(mark)
                return over
            printed.replaceChild(over, target)
            over.appendChild(target)
            over.appendChild(mark)
            return printed
        if sym in self._multipliers:
            sub = self.dom.createElement("msub")
            letter = self.dom.createElement("mi")
            letter.appendChild(self.dom.createTextNode("\u03bb"))
            name = self.dom.createElement("mtext")
            name.appendChild(self.dom.createTextNode(self._multipliers[sym]))
            sub.appendChild(letter)
            sub.appendChild(name)
            return sub
        return super()._print_Symbol(sym, style)

    _print_Dummy = _print_Symbol


class MathWriter:
    """Expressions of one model as MathML strings (``writer(expr)``), escaped throughout."""

    def __init__(self, model: Model | None = None):
        self._printer = _Printer(model)

    def __call__(self, expr) -> str:
        """The MathML of ``expr`` (a sympy expression or matrix, or a number)."""
        return serialize(self._printer._print(sp.sympify(expr)))  # safe: sympy objects or numbers

    def symbol(self, symbol: sp.Symbol) -> str:
        return self(symbol)


def row_vector(writer: MathWriter, entries) -> str:
    """A column of entries between brackets (q_ddot, lambda, f)."""
    return writer(sp.Matrix(list(entries)))
