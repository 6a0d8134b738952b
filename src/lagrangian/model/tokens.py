"""The model grammar's tokens, and user text quoted for one-line messages (a window around the
fault, marked '>>>'): what parse_expression reads before it builds anything."""

from __future__ import annotations

import keyword
import re
import unicodedata

from ..errors import ModelError
from ..spelling import FRACTIONS as _FRACTIONS
from ..spelling import GREEK as _GREEK
from ..spelling import MARKS as _MARKS
from ..spelling import OPERATORS as _OPERATORS
from ..spelling import REFUSED as _REFUSED
from ..spelling import SUBSCRIPTS as _SUBSCRIPTS
from ..spelling import SUPERSCRIPTS as _SUPERSCRIPTS

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
            end = _superscripts_end(text, position)
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


def _superscripts_end(text: str, position: int) -> int:
    while position < len(text) and text[position] in _SUPERSCRIPTS:
        position += 1
    return position


def _power(text: str, start: int, end: int, fail) -> list[tuple[str, str, int, int]]:
    """A run of superscripts (², ⁻¹) as ** and its exponent."""
    run = "".join(_SUPERSCRIPTS[c] for c in text[start:end])
    digits = run[1:] if run[0] in "+-" else run
    if not digits.isdigit():
        raise fail(f"cannot parse {_at(text, start)} at column {start + 1}: the superscript "
                   f"{text[start:end]!r} is not a power (write **2 or **(-1))")
    signed = [("(", "op"), (run[0], "op"), (digits, "number"), (")", "op")]
    return [("op", "**", start, end), *((kind, value, start, end) for value, kind in (
        signed if digits != run else [(digits, "number")]))]


def _spelled_name(text: str, start: int, end: int, fail) -> list[tuple[str, str, int, int]]:
    """A name written with Greek letters, dots above, subscripts, superscripts or a vulgar
    fraction, as the grammar's tokens (positions: the whole spelling's)."""
    tokens: list[tuple[str, str, int, int]] = []
    name, dots = "", 0

    def refuse(reason: str) -> ModelError:
        return fail(f"cannot parse {_at(text, start)} at column {start + 1}: {reason}")

    def flush() -> None:
        nonlocal name, dots
        spelled = name + ("", "_dot", "_ddot")[dots]
        if keyword.iskeyword(spelled):
            raise refuse(f"{text[start:end]!r} is read as {spelled!r}, a reserved word (a "
                         "multiplier is lambda_<constraint>, e.g. lambda_rod)")
        tokens.extend([("name", spelled, start, end)] if name else [])
        name, dots = "", 0

    spelling = unicodedata.normalize("NFD", text[start:end])
    index = 0
    while index < len(spelling):
        char = spelling[index]
        folded = unicodedata.normalize("NFKC", char)  # a mathematical italic 𝜃, a fullwidth ｍ
        if folded != char and len(folded) == 1 and char not in _SUBSCRIPTS and (
                folded in _GREEK or folded.isascii() and folded.isalpha()):
            char = folded
        if char in _SUPERSCRIPTS:
            stop = _superscripts_end(spelling, index)
            flush()  # a power with nothing before it in the spelling raises what precedes it
            tokens += _power(spelling, index, stop, fail)
            if stop < len(spelling):
                raise refuse(f"the power {spelling[index:stop]!r} is directly followed by "
                             f"{spelling[stop]!r} (write * to multiply)")
            index = stop
            continue
        if char in _FRACTIONS:
            if name or index + 1 < len(spelling):
                raise refuse(f"{char!r} touches a name (write {_FRACTIONS[char]}*... to multiply)")
            numerator, _, denominator = _FRACTIONS[char].partition("/")
            tokens += [("op", "(", start, end), ("number", numerator, start, end),
                       ("op", "/", start, end), ("number", denominator, start, end),
                       ("op", ")", start, end)]
        elif char in _GREEK or char.isascii() and (char.isalnum() or char == "_"):
            if tokens and not name:
                raise refuse(f"{text[start:end]!r} is directly followed by {char!r} (write * "
                             "to multiply)")
            name += _GREEK.get(char, char)
        elif char in _SUBSCRIPTS and name:
            name += _SUBSCRIPTS[char]
        elif char in _MARKS and name:
            dots += _MARKS[char]
            if dots > 2:
                raise refuse("only a rate (one dot, theta_dot) and an acceleration (two, "
                             "theta_ddot) are read")
        else:
            shown = unicodedata.normalize("NFC", spelling[index - 1:index + 1]) \
                if index and unicodedata.combining(char) else char
            raise refuse(_refusal(shown))
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
