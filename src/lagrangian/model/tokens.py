"""The model grammar's tokens, and user text quoted for one-line messages (a window around the
fault, marked '>>>'): what parse_expression reads before it builds anything."""

from __future__ import annotations

import keyword
import re

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
        if match is None:
            raise fail(f"cannot parse {_at(text, position)} at column {position + 1}: "
                       f"unexpected character {text[position]!r}")
        kind, value = match.lastgroup, match.group()
        end = match.end()
        if kind == "number" and end < len(text) and (text[end].isalnum() or text[end] in "_."):
            if text[end] in "jJ" and not (text[end + 1:end + 2].isalnum()):
                yield "bad", f"only numbers are allowed as constants, got {value}{text[end]}", \
                    position, end + 1
                position = end + 1
                continue
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


def plain_names(text: str) -> list[str]:
    """The names in an expression that are not called as functions, in order of appearance
    ([] when the text does not even tokenize: the parser reports that)."""
    try:
        tokens = list(_tokens(text, lambda message: ModelError(message)))
    except ModelError:
        return []
    return [value for (kind, value, _, _), following in zip(tokens, tokens[1:], strict=False)
            if kind == "name" and following[:2] != ("op", "(") and not keyword.iskeyword(value)]
