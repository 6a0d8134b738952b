"""Hostile inputs for the seams of issue 21, shared by tests/fuzz/test_fuzz_seams.py: URDF files
(malformed XML, entity expansion, duplicate names, NaN/inf/negative masses and inertias, missing
attributes), [[contacts]], [steady] and [control] tables, names with special characters through the
generated C, sweep options and answer files for `check`. The contract is the CLI's: exit 0 (or
a verdict, exit 1, where the command has one), or exit 2 with exactly one line `error: ...`;
never a traceback, never a hang (each input runs under a time limit).
"""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

from fuzz_inputs import EXAMPLE_TEXTS, HOSTILE_NUMBERS, LagrangianError, expressions, run_input
from hypothesis import strategies as st

EXAMPLES = Path(__file__).resolve().parents[2] / "src" / "lagrangian" / "model" / "examples"
URDF_TEXT = (EXAMPLES / "two_link_arm.urdf").read_text(encoding="utf-8")


class CliRefusal(LagrangianError):
    """The CLI's one-line refusal, as the error it stands for (counted as 'refused')."""


class CliBroke(AssertionError):
    """The CLI broke its contract: a traceback, several lines, a wrong exit status."""


def run_cli(args: list[str], verdicts: tuple[int, ...] = (0,)) -> str:
    """Run the CLI in-process: return stdout on an exit in ``verdicts``; raise CliRefusal on
    exit 2 with one line `error: ...` (nothing else on stderr but `warning:` lines); raise
    CliBroke otherwise."""
    from lagrangian.cli import main

    out, err = io.StringIO(), io.StringIO()
    code = 0
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            main(args)
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else 1
    lines = [line for line in err.getvalue().splitlines() if line.strip()]
    if "Traceback" in err.getvalue():
        raise CliBroke(f"traceback: {err.getvalue()[-600:]!r}")
    if code in verdicts:
        return out.getvalue()
    errors = [line for line in lines if line.startswith("error: ")]
    others = [line for line in lines if not line.startswith(("error: ", "warning: "))]
    if code == 2 and len(errors) == 1 and not others:
        raise CliRefusal(errors[0].removeprefix("error: "))
    raise CliBroke(f"exit {code}: {err.getvalue()[-600:]!r}")


def contract(args: list[str], seconds: float, verdicts: tuple[int, ...] = (0,)):
    """The Outcome of one CLI run (fuzz_inputs.run_input: accepted, refused, timeout, crash)."""
    return run_input(lambda: run_cli(args, verdicts), seconds)


# -- URDF files -------------------------------------------------------------------------------

_LAUGHS = """<?xml version="1.0"?>
<!DOCTYPE robot [
<!ENTITY a "lol">
<!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">
<!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;">
<!ENTITY d "&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;">
<!ENTITY e "&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;">
<!ENTITY f "&e;&e;&e;&e;&e;&e;&e;&e;&e;&e;">
<!ENTITY g "&f;&f;&f;&f;&f;&f;&f;&f;&f;&f;">
<!ENTITY h "&g;&g;&g;&g;&g;&g;&g;&g;&g;&g;">
<!ENTITY i "&h;&h;&h;&h;&h;&h;&h;&h;&h;&h;">
]>
"""
_EXTERNAL = """<?xml version="1.0"?>
<!DOCTYPE robot [<!ENTITY x SYSTEM "file:///etc/passwd">]>
"""
URDF_NUMBERS = ["nan", "NaN", "inf", "-inf", "-1", "0", "-0", "1e308", "1e-320", "1e400", "",
                "abc", "1 2", "0x10", "1,5", "2.0 nan 0", "1e-300", "-2.5"]
_ATTRIBUTE = r'(\b(?:value|ixx|iyy|izz|ixy|ixz|iyz|xyz|rpy|multiplier|offset|lower|upper|' \
             r'damping|friction|effort|velocity)=")([^"]*)(")'


@st.composite
def urdf_files(draw) -> str:
    """The two-link arm with one to three mutations: a number replaced by a hostile one, an
    element or attribute dropped, a link or joint doubled (a duplicate name), junk spliced,
    the header replaced by entity expansion, or a whole element dropped."""
    import re

    text = URDF_TEXT
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(st.sampled_from(["number", "number", "drop_attribute", "duplicate", "splice",
                                     "laughs", "drop_element", "name", "mimic"]))
        if kind == "number":
            spans = [m.span(2) for m in re.finditer(_ATTRIBUTE, text)]
            start, end = draw(st.sampled_from(spans))
            parts = text[start:end].split()
            new = draw(st.sampled_from(URDF_NUMBERS))
            if len(parts) > 1 and draw(st.booleans()):
                parts[draw(st.integers(0, len(parts) - 1))] = new
                new = " ".join(parts)
            text = text[:start] + new + text[end:]
        elif kind == "drop_attribute":
            spans = [m.span() for m in re.finditer(r'\s\w+="[^"]*"', text)]
            start, end = draw(st.sampled_from(spans))
            text = text[:start] + text[end:]
        elif kind == "duplicate":
            blocks = [m.group(0) for m in re.finditer(r"<(link|joint) name=[^>]*?(/>|>.*?</\1>)",
                                                         text, re.S)]
            block = draw(st.sampled_from(blocks))
            text = text.replace("</robot>", block + "\n</robot>")
        elif kind == "splice":
            where = draw(st.integers(0, len(text)))
            junk = draw(st.sampled_from(["<", ">", "&", "&amp;", "]]>", "<!--", "<link>", "</joint>",
                                         '"', "\x00", "<robot>", "<?xml?>", "&a;"]))
            text = text[:where] + junk + text[where:]
        elif kind == "laughs":
            body = text.split("?>", 1)[-1]
            header = draw(st.sampled_from([_LAUGHS, _EXTERNAL]))
            entity = "&i;" if header is _LAUGHS else "&x;"
            text = header + body.replace('name="two_link_arm"', f'name="{entity}"')
        elif kind == "drop_element":
            spans = [m.span() for m in re.finditer(r"<(origin|axis|mass|inertia|limit|parent|"
                                                   r"child|inertial)\b[^>]*?/>", text)]
            start, end = draw(st.sampled_from(spans))
            text = text[:start] + text[end:]
        elif kind == "name":
            spans = [m.span(1) for m in re.finditer(r'name="([^"]*)"', text)]
            start, end = draw(st.sampled_from(spans))
            name = draw(special_names()).replace("&", "&amp;").replace("<", "&lt;")
            text = text[:start] + name.replace('"', "&quot;") + text[end:]
        else:  # a mimic joint with a hostile multiplier or offset
            value = draw(st.sampled_from(URDF_NUMBERS))
            text = text.replace(
                '<limit lower="-3.1" upper="3.1" effort="30" velocity="5"/>',
                f'<limit lower="-3.1" upper="3.1" effort="30" velocity="5"/>'
                f'<mimic joint="shoulder" multiplier="{value}" offset="0"/>', 1)
    return text


# -- names with special characters ------------------------------------------------------------

C_SEQUENCES = ["*/", "/*", "//", "\\", '"', "'", "\n", "\r\n", "??/", "??=", "??'", "#include",
               "%:", "<:", "\x00", "\x1b[2J", "\u202e", "\\u0041", "\\x41", "${", "$(", "`id`",
               "';", "\"); system(\"id\"); //", "*/ int x; /*", "\ufeff", "\U0001f600", "é",
               "\\\n", "\x7f", "\x85", "\u2028"]


def special_names() -> st.SearchStrategy[str]:
    """Names from the whole Unicode range and C's special sequences (comments, escapes,
    trigraphs, line splices), mixed."""
    piece = st.one_of(st.sampled_from(C_SEQUENCES), st.text(min_size=1, max_size=6),
                      st.characters(codec=None, exclude_categories=["Cs"]).map(str))
    return st.lists(piece, min_size=1, max_size=6).map("".join).filter(lambda s: s.strip())


def named_model(name: str, example: str = "pendulum") -> str:
    """A built-in example with its name replaced (as a TOML basic string)."""
    import re

    text = EXAMPLE_TEXTS[example]
    return re.sub(r'^name = ".*"$', lambda _: "name = " + json.dumps(name), text, count=1,
                  flags=re.M)


# -- [[contacts]] and [steady] tables ---------------------------------------------------------

def _values() -> st.SearchStrategy[str]:
    """A TOML value: a hostile number, a string expression, a list or a table."""
    return st.one_of(
        st.sampled_from(HOSTILE_NUMBERS[:12] + ["true", "[]", "{}", '""', "[0, 0, 1]",
                                                "[0, 0, 1e-290]", "[0, 0, 0]", "[1, 2]",
                                                '"x"', '"y"', '"z"', '"w"', '"-y"']),
        expressions(["r", "m", "g", "x", "lean", "yaw", "spin", "V"]).map(json.dumps),
    )


@st.composite
def contact_models(draw) -> str:
    """The rolling coin with its [[contacts]] table changed: a key's value replaced, a key
    dropped or added, a second contact, a contact on a body that does not exist."""
    lines = ['name = "rolling"', 'body = "disc"', 'radius = "r"', 'axle = "y"']
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(st.sampled_from(["value", "value", "drop", "add", "twice"]))
        if kind == "value":
            i = draw(st.integers(0, len(lines) - 1))
            key = lines[i].split(" = ")[0]
            lines[i] = f"{key} = {draw(_values())}"
        elif kind == "drop" and lines:
            del lines[draw(st.integers(0, len(lines) - 1))]
        elif kind == "add":
            key = draw(st.sampled_from(["normal", "ground", "friction", "body", "radius"]))
            lines.append(f"{key} = {draw(_values())}")
        else:
            lines += ["[[contacts]]", *lines]
    head = EXAMPLE_TEXTS["rolling_coin"].split("[[contacts]]")[0]
    return head + "[[contacts]]\n" + "\n".join(lines) + "\n"


COIN_STEADY = (Path(__file__).resolve().parents[1] / "cli" / "conformance_models"
               / "coin_steady.toml").read_text(encoding="utf-8")


@st.composite
def steady_models(draw) -> str:
    """The coin with a [steady] table: speed, rates, keep and about, each valid, hostile or
    missing, with unknown keys and names."""
    head = COIN_STEADY.split("[steady]")[0]
    lines = ["[steady]"]
    if draw(st.booleans()):
        names = st.sampled_from(["V", "m", "spin", "nope", "V_dot"]).map(json.dumps)
        lines.append(f"speed = {draw(st.one_of(names, _values()))}")
    if draw(st.booleans()):
        rates = draw(st.dictionaries(
            st.sampled_from(["spin_dot", "x_dot", "yaw_dot", "lean_dot", "spin", "nope_dot",
                             "V"]), _values(), max_size=3))
        lines.append("rates = {" + ", ".join(f"{k} = {v}" for k, v in rates.items()) + "}")
    if draw(st.booleans()):
        keep = draw(st.lists(st.sampled_from(["lean", "yaw", "spin", "x", "nope", "V", ""]),
                             max_size=4))
        lines.append(f"keep = {json.dumps(keep)}")
    if draw(st.booleans()):
        about = draw(st.dictionaries(st.sampled_from(["lean", "yaw", "x", "V", "nope"]),
                                     _values(), max_size=2))
        lines.append("about = {" + ", ".join(f"{k} = {v}" for k, v in about.items()) + "}")
    if draw(st.integers(0, 5)) == 0:
        lines.append(f"{draw(st.sampled_from(['extra', 'rate', 'speeds']))} = 1")
    return head + "\n".join(lines) + "\n"


# -- [control] tables -------------------------------------------------------------------------

@st.composite
def control_models(draw) -> str:
    """The cart-pole with a [control] table: keys that are inputs (a coordinate, a parameter,
    a load) or not (a rate, an unknown name, an inertia, an empty or quoted key), values that
    are laws, hostile numbers, lists or tables, sometimes no table at all or a table twice."""
    inputs = st.sampled_from(["x", "theta", "F", "push", "g"])
    keys = st.one_of(inputs, inputs, inputs, st.sampled_from(["m", "x_dot", "nope", "t", '""',
                                                              '"a b"', "bob"]))
    valid = st.sampled_from(["-5*x - 3*x_dot + 10*theta", "0", "sin(t) - theta_dot",
                             "-g*theta", "1e6*x", "x/theta"]).map(json.dumps)
    names = ["x", "theta", "x_dot", "theta_dot", "t", "F", "g", "l", "m"]
    laws = st.one_of(valid, valid, valid, valid, expressions(names).map(json.dumps), _values())
    table = draw(st.dictionaries(keys, laws, min_size=1, max_size=2))
    lines = [f"{k} = {v}" for k, v in table.items()]
    kind = draw(st.sampled_from(["table"] * 6 + ["none", "twice", "value"]))
    text = EXAMPLE_TEXTS["cart_pendulum"]
    if kind == "none":
        return text
    if kind == "value":
        return f"control = {draw(_values())}\n" + text  # a top-level key, not a table
    body = "\n[control]\n" + "\n".join(lines) + "\n"
    return text + body + (body if kind == "twice" else "")


# -- sweep options ----------------------------------------------------------------------------

def vary_options() -> st.SearchStrategy[str]:
    """--vary NAME=START:STOP:COUNT, NAME=V1,V2,..., NAME=VALUE, hostile ones included."""
    names = st.sampled_from(["k", "m", "k_c", "x1", "x1_dot", "nope", "t", "", "k=", "k k"])
    numbers = st.one_of(st.sampled_from(HOSTILE_NUMBERS[:14] + ["1kg", "2 N/m", "3deg", "-0"]),
                        st.floats(allow_nan=True, allow_infinity=True).map(repr))
    counts = st.one_of(st.integers(-3, 12).map(str),
                       st.sampled_from(["1e9", "10000000000", "2.5", "nan", "", "x"]))
    value = st.one_of(
        st.tuples(numbers, numbers, counts).map(":".join),
        st.lists(numbers, min_size=1, max_size=4).map(",".join),
        numbers,
        st.text(max_size=12),
    )
    return st.tuples(names, value).map(lambda t: f"{t[0]}={t[1]}")
