"""Hostile inputs for the fuzzing campaign (issue 14), shared by tests/fuzz and
benchmarks/fuzz_campaign.py: hypothesis strategies for expressions, numbers, unit strings and
whole model files (from the grammar and by mutating the built-in examples), and the contract
each input must meet: accepted, or refused with the project's own error, within a time limit.
"""

from __future__ import annotations

import contextlib
import functools
import io
import json
import random
import re
import signal
import time
from dataclasses import dataclass, field
from pathlib import Path

import sympy as sp
from hypothesis import strategies as st

from lagrangian.errors import LagrangianError
from lagrangian.model.expressions import format_expression, parse_expression

EXAMPLES = Path(__file__).resolve().parents[2] / "src" / "lagrangian" / "model" / "examples"
EXAMPLE_TEXTS = {path.stem: path.read_text(encoding="utf-8")
                 for path in sorted(EXAMPLES.glob("*.toml"))}

# -- pieces of the grammar, hostile ones included --------------------------------------------

NAMES = ["theta", "x", "m", "L", "g", "k", "theta_dot", "x_dot", "t"]
UNKNOWN_NAMES = ["nope", "thetta", "__import__", "os", "θ", "_", "pi_", "True", "lambda"]
FUNCTIONS = ["sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh", "exp",
             "log", "sqrt", "abs", "sign"]
HOSTILE_NUMBERS = [
    "0", "1", "-1", "2", "0.5", "1e308", "1e-308", "1e300", "1e-300", "1e-400", "1e400",
    "9.99e299", "1.0000001", "16.369805884", "1" + "0" * 299, "1" + "0" * 400, "0.1", "1e-5",
    "123456789.123456789", "1_000", "0x1f", "1j", "00", "1.", ".5", "1e99999999999",
    "2.718281828459045", "3.141592653589793", "nan", "inf",
]
BINARY = ["+", "-", "*", "/", "^", "**"]
JUNK = ["%", "//", "@", "&", "|", "<<", ">>", "~", "<", "==", ".", "[", "]", "{", "}", ",", "=",
        ":=", "'", '"', "\\", ";", ":", "!", "$", "#", "lambda", "if", "not", "and", "f'x'", "\n"]
HOSTILE_EXPRESSIONS = [
    "(1.0000001^1000)^1000", "16.369805884^16.369805884^16.369805884^16.369805884",
    "exp(exp(exp(exp(10))))", "log(0)", "tan(pi/2)", "sqrt(-1)", "log(-1)", "asin(2)",
    "atan2(0, 0)", "0^-1", "pi/0", "theta^(0*log(0))", "9^9^9", "(-8)^(1/3)", "exp(700)",
    "1.0000001^1000", "2^1000", "10^299*100", "theta - theta", "log(theta - theta)",
    "1/(x - x)", "sinh(exp(7))", "(2*theta)^0.123456789",
]

# What students type (issue 20): Unicode spellings read as ASCII names, or refused with a hint;
# combining marks, superscripts and fractions in every position, and look-alikes.
UNICODE_PIECES = ["θ", "θ̇", "θ̈", "θ̇̇̇", "ẋ", "ẍ₁", "½", "¾", "²", "⁻¹", "⁻", "⁺²", "·", "×", "−", "÷",
                  "′", "″", "°", "√", "∂", "λ", "λ_rod", "ω", "ωₙ", "φ", "Ω", "π", "µ", "x̂", "é",
                  "\u0307", "\u0308", "\u20db", "₁", "ₙ", "\u00a0", "\u200b", "\u202e", "ｍ",
                  "а", "ⁿ", "⅟", "𝜃", "ǅ"]

UNIT_NAMES = ["m", "kg", "s", "rad", "deg", "N", "J", "W", "pi", "degC", "g", "km", "foo",
              "meter", "radian", "revolution", "percent", "dimensionless", "µm", "°"]
UNIT_OPS = ["*", "/", "^", "**", " ", "·", "(", ")", "-", "."]


def number_texts() -> st.SearchStrategy[str]:
    """Literal numbers: hostile picks, random floats and integers, and decimal forms."""
    return st.one_of(
        st.sampled_from(HOSTILE_NUMBERS),
        st.floats(allow_nan=False, allow_infinity=False).map(repr),
        st.integers(min_value=-(10**400), max_value=10**400).map(str),
        st.builds(lambda m, e: f"{m}e{e}", st.integers(-10**6, 10**6),
                  st.integers(-10**4, 10**4)),
    )


def expressions(names: list[str] | None = None) -> st.SearchStrategy[str]:
    """Expression text from the grammar (with wrong arities, unknown names and hostile
    constants mixed in), and grammar text with junk spliced in."""
    return _expressions(tuple(names or NAMES))


@functools.cache  # building the recursive strategy costs more than drawing from it
def _expressions(names: tuple[str, ...]) -> st.SearchStrategy[str]:
    names = list(names)
    leaves = st.one_of(
        st.sampled_from(names), number_texts(), st.just("pi"),
        st.sampled_from(UNKNOWN_NAMES), st.sampled_from(HOSTILE_EXPRESSIONS),
    )

    def extend(children):
        return st.one_of(
            st.tuples(children, st.sampled_from(BINARY), children).map(
                lambda t: f"{t[0]}{t[1]}{t[2]}"),
            st.tuples(children, st.sampled_from(BINARY), children).map(
                lambda t: f"({t[0]}) {t[1]} ({t[2]})"),
            children.map(lambda c: f"-{c}"),
            st.tuples(st.sampled_from(FUNCTIONS), st.lists(children, min_size=0, max_size=3)).map(
                lambda t: f"{t[0]}({', '.join(t[1])})"),
            st.tuples(children, st.integers(1, 40)).map(lambda t: "(" * t[1] + t[0] + ")" * t[1]),
            st.lists(children, min_size=2, max_size=60).map(" + ".join),
            st.lists(children, min_size=2, max_size=60).map("*".join),
        )

    grammar = st.recursive(leaves, extend, max_leaves=25)
    spliced = st.tuples(grammar, st.sampled_from(JUNK), st.integers(0, 10**6)).map(
        lambda t: t[0][: t[2] % (len(t[0]) + 1)] + t[1] + t[0][t[2] % (len(t[0]) + 1):])
    return st.one_of(grammar, grammar, spliced, st.text(max_size=40))


def unicode_expressions() -> st.SearchStrategy[str]:
    """Grammar text with Unicode spellings spliced in, and runs of the pieces alone."""
    spliced = st.tuples(expressions(), st.lists(st.sampled_from(UNICODE_PIECES), min_size=1,
                                                max_size=4), st.integers(0, 10**6)).map(
        lambda t: t[0][: t[2] % (len(t[0]) + 1)] + "".join(t[1]) + t[0][t[2] % (len(t[0]) + 1):])
    alone = st.lists(st.one_of(st.sampled_from(UNICODE_PIECES), st.sampled_from(NAMES),
                               st.sampled_from(BINARY)), min_size=1, max_size=12).map("".join)
    return st.one_of(spliced, alone)


def unit_strings() -> st.SearchStrategy[str]:
    """Unit strings: names, operators, numbers and powers, towers included."""
    part = st.one_of(st.sampled_from(UNIT_NAMES), st.sampled_from(UNIT_OPS),
                     st.sampled_from(["2", "-1", "0.5", "9", "1e300", "(1/2)", "(-pi)", "9^9"]))
    return st.one_of(
        st.lists(part, min_size=1, max_size=8).map("".join),
        st.tuples(st.sampled_from(UNIT_NAMES), st.sampled_from(["^", "**"]),
                  number_texts()).map("".join),
    )


def quantities() -> st.SearchStrategy[str]:
    """Values with a unit as on the command line (--set, --initial, --at)."""
    return st.tuples(number_texts(), st.sampled_from(["", " "]), unit_strings()).map("".join)


# -- whole model files ------------------------------------------------------------------------

def _toml_string(text: str) -> str:
    return json.dumps(text, ensure_ascii=False)  # a JSON string is a valid TOML basic string


@st.composite
def grammar_models(draw) -> str:
    """A model file written from the grammar: coordinates, parameters and energies."""
    count = draw(st.integers(1, 3))
    coordinates = [f"q{i}" for i in range(count)]
    units = draw(st.lists(st.one_of(st.sampled_from(["rad", "m"]), unit_strings()),
                          min_size=count, max_size=count))
    names = coordinates + [f"{q}_dot" for q in coordinates] + ["m", "k", "g", "t"]
    lines = ["[coordinates]"]
    for q, unit in zip(coordinates, units, strict=True):
        initial = draw(st.one_of(st.none(), number_texts()))
        value = f", initial = {initial}" if initial and re.fullmatch(r"[-+]?[\d.e]+", initial) else ""
        lines.append(f"{q} = {{ unit = {_toml_string(unit)}{value} }}")
    lines.append("[parameters]")
    for name in ("m", "k", "g"):
        value = draw(st.one_of(number_texts(), st.none()))
        if value and re.fullmatch(r"[-+]?\d+(\.\d+)?(e[-+]?\d+)?", value):
            lines.append(f"{name} = {value}")
        else:
            lines.append(f"{name} = {{ unit = {_toml_string(draw(unit_strings()))} }}")
    lines.append("[energy]")
    T = " + ".join(f"1/2*m*{q}_dot^2" for q in coordinates)
    lines.append(f"T = {_toml_string(draw(st.one_of(st.just(T), expressions(names))))}")
    for key in draw(st.sets(st.sampled_from(["V", "D"]))):
        lines.append(f"{key} = {_toml_string(draw(expressions(names)))}")
    return "\n".join(lines) + "\n"


_STRING_VALUE = re.compile(r'"((?:[^"\\\n]|\\.)*)"')
_NUMBER_VALUE = re.compile(r"(?<=[=\[, ])(-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?)(?=[\s,\]}])")


@st.composite
def mutated_examples(draw) -> str:
    """A built-in example with one to three mutations: a string value (expression, unit,
    name) or a number replaced by a hostile one, junk spliced in, a line dropped or doubled."""
    text = EXAMPLE_TEXTS[draw(st.sampled_from(sorted(EXAMPLE_TEXTS)))]
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(st.sampled_from(["string", "string", "number", "splice", "drop", "double"]))
        if kind == "string":
            spans = [m.span(1) for m in _STRING_VALUE.finditer(text)]
            if not spans:
                continue
            start, end = draw(st.sampled_from(spans))
            old = text[start:end]
            choice = draw(st.integers(0, 7))
            if choice == 0:
                new = draw(expressions())
            elif choice == 1:
                new = draw(unit_strings())
            elif choice == 2:
                new = draw(st.sampled_from(HOSTILE_EXPRESSIONS))
            elif choice == 3:
                new = old + "^" + draw(number_texts())
            elif choice == 4:
                new = f"{old}*{draw(st.sampled_from(HOSTILE_EXPRESSIONS))}"
            elif choice == 5:
                new = f"({old}) + ({old})"
            elif choice == 6:
                new = old[::-1]
            else:
                new = ""
            text = text[:start] + json.dumps(new, ensure_ascii=False)[1:-1] + text[end:]
        elif kind == "number":
            spans = [m.span(1) for m in _NUMBER_VALUE.finditer(text)]
            if not spans:
                continue
            start, end = draw(st.sampled_from(spans))
            new = draw(st.one_of(
                st.sampled_from(["1e308", "-1e308", "1e-400", "0", "-1", "inf", "-inf", "nan",
                                 "1e5000", '"x"', "[]", "{}", "true", "1e300"]),
                number_texts().filter(lambda s: re.fullmatch(r"-?\d+(\.\d+)?(e-?\d+)?", s)),
            ))
            if new == "1e5000":
                new = "1" + "0" * 5000  # over Python's 4300-digit limit
            text = text[:start] + new + text[end:]
        elif kind == "splice":
            where = draw(st.integers(0, len(text)))
            text = text[:where] + draw(st.sampled_from(JUNK + ["[[particles]]\n", "= 1\n"])) \
                + text[where:]
        else:
            lines = text.splitlines()
            index = draw(st.integers(0, max(0, len(lines) - 1)))
            if kind == "drop" and lines:
                del lines[index]
            elif lines:
                lines.insert(index, lines[index])
            text = "\n".join(lines) + "\n"
    return text


def model_files() -> st.SearchStrategy[str]:
    return st.one_of(grammar_models(), mutated_examples())


@st.composite
def answer_files(draw) -> str:
    """A hand derivation (ANSWER.toml) for the pendulum example, with hostile expressions,
    equations with several '=' and wrong multiplier counts."""
    names = ["theta", "theta_dot", "theta_ddot", "m", "L", "g", "t", "N", "T_rod"]
    lines = ["[energy]"]
    for key in draw(st.sets(st.sampled_from(["T", "V", "D", "X"]), min_size=1)):
        lines.append(f"{key} = {_toml_string(draw(expressions(names)))}")
    if draw(st.booleans()):
        lhs, rhs = draw(expressions(names)), draw(expressions(names))
        sep = draw(st.sampled_from([" = ", "=", " == ", " <= ", " = = "]))
        lines += ["[equations]", f"theta = {_toml_string(lhs + sep + rhs)}"]
    if draw(st.booleans()):
        count = draw(st.sampled_from(["0", "1", "-1", "1e3", "true", '"x"', "99999999999999999999"]))
        lines += ["[multipliers]", f"count = {count}"]
    return "\n".join(lines) + "\n"


def read_answer_text(text: str) -> None:
    from lagrangian.model.answer import parse_answer

    parse_answer(text, _pendulum(), source="ANSWER.toml")


def _pendulum():
    global _PENDULUM
    if _PENDULUM is None:
        from lagrangian.model.reader import parse_model

        _PENDULUM = parse_model(EXAMPLE_TEXTS["pendulum"], source="pendulum.toml")
    return _PENDULUM


_PENDULUM = None


# -- the contract ----------------------------------------------------------------------------

class InputTimeout(BaseException):
    """An input ran past its time limit (a hang, for the campaign). A BaseException, so that a
    library's ``except Exception`` (pint's parser has one) cannot swallow it."""


@contextlib.contextmanager
def time_limit(seconds: float):
    """Interrupt the block after ``seconds`` (SIGALRM; no limit where there is none)."""
    if not hasattr(signal, "setitimer"):
        yield
        return

    def expire(signum, frame):
        raise InputTimeout(f"over {seconds} s")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


@dataclass
class Outcome:
    """What one input did: 'accepted', 'refused' (with a kind), 'timeout' or 'crash'."""

    status: str
    kind: str = ""
    message: str = ""
    seconds: float = 0.0

    @property
    def ok(self) -> bool:
        return self.status in ("accepted", "refused")


def refusal_kind(message: str) -> str:
    """A refusal's kind for the counts: its message without file, field, quotes and numbers."""
    while True:
        head = re.match(r"(?:[^\s:]+|line \d+(?: \([^)]*\))?|--[\w-]+ \S+): ", message)
        if not head:
            break
        message = message[head.end():]
    message = re.sub(r"(got|unexpected|followed by) .*", r"\1 ...", message)
    message = re.sub(r"\b\w+\(\) takes", "a function takes", message)
    text = re.sub(r"'(?:[^'\\]|\\.)*'|\"(?:[^\"\\]|\\.)*\"", "'...'", message)
    text = re.sub(r"\d+(\.\d+)?(e[-+]?\d+)?", "N", text)
    return re.split(r"[:;(]", text)[0].strip()[:70]


def run_input(action, seconds: float) -> Outcome:
    """Run ``action`` under the contract: accepted, or a one-line LagrangianError, in time."""
    start = time.perf_counter()
    try:
        with time_limit(seconds):
            action()
    except LagrangianError as exc:
        message = str(exc)  # the whole line, file and field included
        elapsed = time.perf_counter() - start
        if "\n" in message:
            return Outcome("crash", "multi-line message", message, elapsed)
        return Outcome("refused", refusal_kind(message), message, elapsed)
    except InputTimeout:
        return Outcome("timeout", "time limit", "", time.perf_counter() - start)
    except BaseException as exc:  # everything else breaks the contract, even SystemExit
        if isinstance(exc, KeyboardInterrupt):
            raise
        return Outcome("crash", type(exc).__name__, f"{type(exc).__name__}: {exc}"[:300],
                       time.perf_counter() - start)
    return Outcome("accepted", "", "", time.perf_counter() - start)


EXPRESSION_NAMES = {name: sp.Symbol(name) for name in NAMES}


def read_expression(text: str) -> None:
    """Parse; an accepted expression must print back to text that parses to itself."""
    expr = parse_expression(text, EXPRESSION_NAMES, field="energy.V", source="fuzz.toml")
    printed = format_expression(expr)
    again = parse_expression(printed, EXPRESSION_NAMES, field="printed", source="fuzz")
    if again != expr and not _same_value(again, expr):
        raise AssertionError(f"printed {printed!r} reads back as {again}, not {expr}")


def _same_value(a: sp.Expr, b: sp.Expr) -> bool:
    """Equal as functions: sympy distributes a number over a sum when it reads Q*(p/Q + pi),
    so the printed text may read back in another (equal) form."""
    if sp.expand(a - b) == 0:
        return True
    rng = random.Random(1)
    for _ in range(3):
        point = {s: sp.Float(rng.uniform(0.2, 1.3), 30) for s in (a.free_symbols | b.free_symbols)}
        x, y = complex(a.xreplace(point).evalf(30)), complex(b.xreplace(point).evalf(30))
        if abs(x - y) > 1e-12 * max(1.0, abs(x), abs(y)):
            return False
    return True


def read_model_text(text: str) -> None:
    from lagrangian.model.reader import parse_model

    parse_model(text, source="fuzz.toml")


def derive_json(text: str, folder: Path) -> None:
    """`lagrangian derive FILE --format json` in-process: exit 0 with JSON without NaN, or
    exit 2 with one line `error: ...`; the error is re-raised as a LagrangianError."""
    from lagrangian.cli import main

    path = folder / "fuzz.toml"
    path.write_text(text, encoding="utf-8")
    out, err = io.StringIO(), io.StringIO()
    code = 0
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            main(["derive", str(path), "--format", "json"])
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else 1
    if code == 0:
        json.loads(out.getvalue(), parse_constant=_no_constants)
        return
    lines = err.getvalue().strip().splitlines()
    if code == 2 and len(lines) == 1 and lines[0].startswith("error: "):
        raise _CliRefusal(lines[0].removeprefix("error: "))
    raise AssertionError(f"exit {code}: {err.getvalue()[-300:]!r}")


def _no_constants(name: str):
    raise AssertionError(f"JSON output contains {name}")


class _CliRefusal(LagrangianError):
    """The CLI's one-line refusal, as the error it stands for."""


@dataclass
class Tally:
    """Counts of a campaign: inputs tried, accepted, refusals by kind, failures, slowest."""

    tried: int = 0
    accepted: int = 0
    refusals: dict[str, int] = field(default_factory=dict)
    failures: list[tuple[str, str, str]] = field(default_factory=list)  # (target, input, what)
    slowest_refusal: tuple[float, str, str] = (0.0, "", "")
    slowest_accept: tuple[float, str] = (0.0, "")

    def add(self, target: str, text: str, outcome: Outcome) -> None:
        self.tried += 1
        if outcome.status == "accepted":
            self.accepted += 1
            if outcome.seconds > self.slowest_accept[0]:
                self.slowest_accept = (outcome.seconds, f"{target}: {text[:200]}")
        elif outcome.status == "refused":
            self.refusals[outcome.kind] = self.refusals.get(outcome.kind, 0) + 1
            if outcome.seconds > self.slowest_refusal[0]:
                self.slowest_refusal = (outcome.seconds, f"{target}: {text[:200]}",
                                        outcome.message[:200])
        else:
            self.failures.append((target, text, f"{outcome.status}: {outcome.kind} "
                                                f"{outcome.message}"))
