"""The model grammar's tokens, and user text quoted for one-line messages (a window around the
fault, marked '>>>'): what parse_expression reads before it builds anything."""

from __future__ import annotations

import keyword
import re
import unicodedata
from fractions import Fraction

from ..errors import ModelError

# -- quoting ------------------------------------------------------------------------------

_WINDOW = 30


def _quote(text: str, start: int = 0, end: int | None = None) -> str:
    """A piece of user text for a one-line message: whole when short, else cut with '...'."""
    piece = text[start:end]
    if len(piece) <= 2 * _WINDOW + 3:
        return repr(piece)
    return repr(piece[:_WINDOW] + "..." + piece[-_WINDOW:])


def _at(text: str, position: int) -> str:
    """The text around ``position``: whole when short; a window marked '>>>' at the fault."""
    if len(text) <= 2 * _WINDOW + 20:
        return repr(text)
    lo, hi = max(0, position - _WINDOW), min(len(text), position + _WINDOW)
    window = ("..." if lo else "") + text[lo:position] + ">>>" + text[position:hi] \
        + ("..." if hi < len(text) else "")
    return repr(window)


# -- tokens -------------------------------------------------------------------------------

_TOKEN = re.compile(r"""
    (?P<space>\s+)
  | (?P<number>0[xXoObB][0-9a-fA-F_]+
      | (?:\d(?:_?\d)*(?:\.(?:\d(?:_?\d)*)?)?|\.\d(?:_?\d)*)(?:[eE][+-]?\d(?:_?\d)*)?)
  | (?P<string>(?:[rRbBuUfF]{1,2})?(?:'(?:[^'\\\n]|\\.)*'?|"(?:[^"\\\n]|\\.)*"?))
  | (?P<name>[^\W\d]\w*)
  | (?P<op>\*\*|//|<<|>>|<=|>=|==|!=|:=|->|[-+*/^%@&|~<>()\[\]{},.:;=!])
""", re.VERBOSE)
_FORBIDDEN_OPERATORS = {"%", "//", "@", "&", "|", "<<", ">>"}
_COMPARISONS = {"<", ">", "<=", ">=", "==", "!="}
_PRECEDENCE = {"+": 1, "-": 1, "*": 2, "/": 2, "neg": 3, "pos": 3, "^": 4}


def _tokens(text: str, fail):
    position = 0
    while position < len(text):
        match = _TOKEN.match(text, position)
        if match is None or match.lastgroup == "name":
            spelled = _unicode_tokens(text, position, match, fail)
            if spelled is not None:
                tokens, position = spelled
                yield from tokens
                continue
        if match is None:
            raise fail(f"cannot parse {_at(text, position)} at column {position + 1}: "
                       f"unexpected character {text[position]!r}")
        kind, value = match.lastgroup, match.group()
        end = match.end()
        if kind == "number" and end < len(text) and (text[end].isalnum() or text[end] in "_.") \
                and text[end] not in _SUPERSCRIPTS:
            if text[end] in "jJ" and not (text[end + 1:end + 2].isalnum()):
                yield "bad", f"only numbers are allowed as constants, got {value}{text[end]}", \
                    position, end + 1
                position = end + 1
                continue
            if text[end] in _FRACTIONS:
                share = _FRACTIONS[text[end]]
                raise fail(f"cannot parse {_at(text, end)} at column {end + 1}: a number is "
                           f"directly followed by {text[end]!r} (write {value} + {share}, or "
                           f"{value}*{share} to multiply)")
            raise fail(f"cannot parse {_at(text, end)} at column {end + 1}: a number is "
                       f"directly followed by {text[end]!r} (write {value}*... to multiply)")
        if kind == "string":
            message = "strings are not allowed" if "f" in value.split("'")[0].split('"')[0].lower() \
                else f"only numbers are allowed as constants, got {value}"
            yield "bad", message, position, end
        elif kind != "space":
            yield kind, value, position, end
        position = end
    yield "end", "", len(text), len(text)


# -- what students type: Unicode spellings read as the grammar's ASCII names --------------------

# Greek letters by their ASCII names (theta, Omega); variants and the micro sign as their letter.
_GREEK = {chr(0x3B1 + i): name for i, name in enumerate(
    "alpha beta gamma delta epsilon zeta eta theta iota kappa lambda mu nu xi omicron pi rho "
    "sigma sigma tau upsilon phi chi psi omega".split())}
_GREEK.update({letter.upper(): name.capitalize() for letter, name in _GREEK.items()
               if letter != "\u03c2"})
_GREEK.update({"\u03d1": "theta", "\u03d5": "phi", "\u03f5": "epsilon", "\u03f1": "rho",
               "\u03d6": "pi", "\u00b5": "mu"})
_SUBSCRIPTS = {chr(0x2080 + d): str(d) for d in range(10)}
_SUBSCRIPTS.update({c: f"_{letter}" for c, letter in zip(
    "\u2090\u2091\u2092\u2093\u2095\u2096\u2097\u2098\u2099\u209a\u209b\u209c"
    "\u1d62\u2c7c\u1d63\u1d64\u1d65", "aeoxhklmnpstijruv", strict=True)})
_SUPERSCRIPTS = {"\u2070": "0", "\u00b9": "1", "\u00b2": "2", "\u00b3": "3",
                 **{chr(0x2070 + d): str(d) for d in range(4, 10)}, "\u207b": "-", "\u207a": "+"}
_FRACTIONS = {c: str(Fraction(unicodedata.numeric(c)).limit_denominator(10))
              for c in "\u00bd\u2153\u2154\u00bc\u00be\u2155\u2156\u2157\u2158\u2159"
                       "\u215a\u2150\u215b\u215c\u215d\u215e\u2151\u2152"}
_OPERATORS = {"\u00b7": "*", "\u22c5": "*", "\u2217": "*", "\u2219": "*", "\u00d7": "*", "\u2715": "*",
              "\u2212": "-", "\u2013": "-", "\u2010": "-", "\u2012": "-", "\u00f7": "/",
              "\u2215": "/", "\u2044": "/"}
_MARKS = {"\u0307": 1, "\u0308": 2}  # a dot above: the rate (theta_dot); two: theta_ddot
# Characters refused with the ASCII spelling to use instead.
_REFUSED = {
    "\u2032": "a prime is not read: write theta_dot for a rate",
    "\u2033": "a double prime is not read: write theta_ddot for an acceleration",
    "\u221a": "write sqrt(...) for a square root",
    "\u2202": "write the derivative out (the answer holds expressions, not operators)",
    "\u00b0": "write an angle in radians (30 degrees is 30*pi/180)",
    "\u221e": "infinity is not a value",
}
_WORD = re.compile(r"\w")


def _unicode_tokens(text: str, position: int, match, fail):
    """Tokens of the non-ASCII spelling at ``position`` (θ̇₁ is theta1_dot, ½ is (1/2), ² is
    **2, · and × are *, − is -), and where they end; None when the text there is plain ASCII.
    What cannot be read is refused with the ASCII spelling to use."""
    char = text[position]
    if match is None:
        if char in _OPERATORS:
            return [("op", _OPERATORS[char], position, position + 1)], position + 1
        if char in _SUPERSCRIPTS:
            end = position
            while end < len(text) and text[end] in _SUPERSCRIPTS:
                end += 1
            return _power(text, position, end, fail), end
        if not char.isascii() and not char.isspace():
            raise fail(f"cannot parse {_at(text, position)} at column {position + 1}: "
                       f"{_refusal(char)}")
        return None
    end = match.end()
    while end < len(text) and (unicodedata.combining(text[end]) or _WORD.match(text[end])
                               or text[end] in _SUPERSCRIPTS):
        end += 1
    if text[position:end].isascii():
        return None
    return _spelled_name(text, position, end, fail), end


def _refusal(char: str) -> str:
    name = unicodedata.name(char, "").lower() if len(char) == 1 else ""
    hint = _REFUSED.get(char) or (
        "accents are not read: write a plain name (theta_dot for a rate)"
        if any(unicodedata.combining(c) for c in unicodedata.normalize("NFD", char)) else
        "names are ASCII letters, digits and _ (theta, omega_n, x1_dot), operators + - * / **")
    return f"unexpected character {char!r}{f' ({name})' if name else ''}: {hint}"


def _power(text: str, start: int, end: int, fail) -> list[tuple[str, str, int, int]]:
    """A run of superscripts (², ⁻¹) as ** and its exponent."""
    run = "".join(_SUPERSCRIPTS[c] for c in text[start:end])
    sign, digits = (run[0], run[1:]) if run[0] in "+-" else ("", run)
    if not digits.isdigit():
        raise fail(f"cannot parse {_at(text, start)} at column {start + 1}: the superscript "
                   f"{text[start:end]!r} is not a power (write **2 or **(-1))")
    if not sign:
        return [("op", "**", start, end), ("number", digits, start, end)]
    return [("op", "**", start, end), ("op", "(", start, end), ("op", sign, start, end),
            ("number", digits, start, end), ("op", ")", start, end)]


def _spelled_name(text: str, start: int, end: int, fail) -> list[tuple[str, str, int, int]]:
    """A name written with Greek letters, dots above, subscripts, superscripts or a vulgar
    fraction, as the grammar's tokens (positions: the whole spelling's)."""
    tokens: list[tuple[str, str, int, int]] = []
    name, dots = "", 0

    def flush() -> None:
        nonlocal name, dots
        if not name:
            return
        spelled = name + ("_dot" if dots == 1 else "_ddot" if dots == 2 else "")
        if keyword.iskeyword(spelled):
            raise fail(f"cannot parse {_at(text, start)} at column {start + 1}: "
                       f"{text[start:end]!r} is read as {spelled!r}, a reserved word (a "
                       f"multiplier is lambda_<constraint>, e.g. lambda_rod)")
        tokens.append(("name", spelled, start, end))
        name, dots = "", 0

    def directly_after(what: str, char: str) -> ModelError:
        return fail(f"cannot parse {_at(text, start)} at column {start + 1}: {what} is directly "
                    f"followed by {char!r} (write * to multiply)")

    spelling = unicodedata.normalize("NFD", text[start:end])
    index = 0
    while index < len(spelling):
        char = spelling[index]
        folded = unicodedata.normalize("NFKC", char)  # a mathematical italic 𝜃, a fullwidth ｍ
        if folded != char and len(folded) == 1 and char not in _SUBSCRIPTS and (
                folded in _GREEK or folded.isascii() and folded.isalpha()):
            char = folded
        if char in _SUPERSCRIPTS:
            stop = index
            while stop < len(spelling) and spelling[stop] in _SUPERSCRIPTS:
                stop += 1
            flush()  # a power with nothing before it in the spelling raises what precedes it
            tokens += _power(spelling, index, stop, fail)
            if stop < len(spelling):
                raise directly_after(f"the power {spelling[index:stop]!r}", spelling[stop])
            index = stop
            continue
        if char in _FRACTIONS:
            if name or index + 1 < len(spelling):
                raise fail(f"cannot parse {_at(text, start)} at column {start + 1}: {char!r} "
                           f"touches a name (write {_FRACTIONS[char]}*... to multiply)")
            numerator, _, denominator = _FRACTIONS[char].partition("/")
            tokens += [("op", "(", start, end), ("number", numerator, start, end),
                       ("op", "/", start, end), ("number", denominator, start, end),
                       ("op", ")", start, end)]
        elif char.isascii() and (char.isalnum() or char == "_"):
            if tokens and not name:
                raise directly_after(repr(text[start:end]), char)
            name += char
        elif char in _GREEK:
            if tokens and not name:
                raise directly_after(repr(text[start:end]), char)
            name += _GREEK[char]
        elif char in _SUBSCRIPTS and name:
            name += _SUBSCRIPTS[char]
        elif char in _MARKS and name:
            dots += _MARKS[char]
            if dots > 2:
                raise fail(f"cannot parse {_at(text, start)} at column {start + 1}: only a "
                           "rate (one dot, theta_dot) and an acceleration (two, theta_ddot) "
                           "are read")
        else:
            shown = unicodedata.normalize("NFC", spelling[index - 1:index + 1]) \
                if index and unicodedata.combining(char) else char
            raise fail(f"cannot parse {_at(text, start)} at column {start + 1}: "
                       f"{_refusal(shown)}")
        index += 1
    flush()
    return tokens


def plain_names(text: str) -> list[str]:
    """The names in an expression that are not called as functions, in order of appearance
    ([] when the text does not even tokenize: the parser reports that)."""
    try:
        tokens = list(_tokens(text, lambda message: ModelError(message)))
    except ModelError:
        return []
    return [value for (kind, value, _, _), following in zip(tokens, tokens[1:], strict=False)
            if kind == "name" and following[:2] != ("op", "(") and not keyword.iskeyword(value)]
