"""The model-file reference (docs/model-file.md) is generated from the reader's own schema
(model/reader.py, ``model_file_schema``): a key the reader accepts and the page does not list,
or one the page lists and the reader refuses, fails here. The table of answer-file keys below it
(``lagrangian check``) comes from model/answer.py's ``answer_file_schema`` the same way. The
page's example model reads and its example error is what the CLI prints.

Regenerate the tables after changing a reader:  python tests/test_readme_model_keys.py --write
(rewrites the tables between the page's markers; without --write it prints them; the meanings
are below).
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import lagrangian
from lagrangian.model.answer import answer_file_schema
from lagrangian.model.reader import model_file_schema

PAGE = Path(__file__).resolve().parents[1] / "docs" / "model-file.md"
BEGIN, END = "<!-- BEGIN model-keys (generated: python tests/test_readme_model_keys.py) -->", \
    "<!-- END model-keys -->"
ANSWER_BEGIN, ANSWER_END = ("<!-- BEGIN answer-keys (generated: python "
                            "tests/test_readme_model_keys.py) -->", "<!-- END answer-keys -->")

# What each table is for; the keys themselves come from the reader.
MEANINGS = {
    "": "`name`, `description`: strings; `definitions`: `name = \"expression\"`, substituted "
        "everywhere; `generalized_forces`: `coordinate = \"Q\"` added to Q; `control`: "
        "`input = \"law\"`, u(t, q, q_dot) on a coordinate's generalized force, a parameter or "
        "a load, run by `simulate --control model` (docs/control.md); the other keys are the "
        "tables below",
    "coordinates.<name>": "a unit string, or this table: `unit` (default m), `initial` value, "
                          "`rate` (initial q_dot), `range = [low, high]` (searched by "
                          "equilibria; a printed abs() whose sign it fixes is dropped)",
    "parameters.<name>": "a number (SI), or this table (`value` converted to SI from `unit`); "
                         "no value: symbolic only; `range = [low, high]` (inclusive, `inf` "
                         "allowed) and `integer = true` (a count) bound every value given, "
                         "the file's, `--set`'s, `with_parameters`' and a study's",
    "energy": "T, V, D as expressions, added to what the components contribute",
    "gravity": "`g` its magnitude (a number or a parameter), `direction` a vector (default "
               "[0, -1])",
    "particles": "a point mass at `position` (a vector of expressions)",
    "bodies": "a planar rigid body (`inertia` about the centre of mass, `position`, `angle`), or "
              "a body in space (`inertia` a list; `rotation`, `origin`, `center`, `parent`, "
              "`joint`: see Bodies in space)",
    "springs": "V = 1/2 k (length - rest_length)^2: `length` an expression, or `between = "
               "[pointA, pointB]`; `rest_length` default 0",
    "dampers": "D = 1/2 c rate^2: `rate` an expression, or `between = [pointA, pointB]`",
    "loads": "`point` + `force` (a vector), or `torque` + `angle`; on a body in space `body` + "
             "`moment` (`axes = \"body\"` for body axes)",
    "constraints": "one of `holonomic = \"Phi(q, t)\"` (= 0) or `velocity = \"A(q, t) q_dot + "
                   "b\"` (= 0)",
    "contacts": "a wheel rolling without slipping on the ground: `body`, `radius`, `axle` (body "
                "axes); the ground `normal` (default against gravity)",
    "impacts": "an impact when `guard` g(q, t) falls through 0: the striking `point` (a vector, "
               "a particle or body, or {body, offset}), the surface `normal`, `restitution` e in "
               "[0, 1] (default 0), `tangential` \"slip\" (default) or \"stick\"; `release = "
               "\"pivot\"` lets the pin at the origin go, `relabel = { q = \"expr\" }` the "
               "coordinates after (see Impacts)",
    "steady": "the steady motion `speeds` linearizes about by default: `speed` a parameter "
              "(m/s), `rates = { x_dot = \"v\" }` in the parameters, `keep` the coordinates "
              "whose equations stay, `about` coordinate values",
}


# The tables of an answer file (lagrangian check MODEL ANSWER.toml); keys from the answer reader.
ANSWER_MEANINGS = {
    "": "`coordinates = [\"x2\", \"x1\"]` (or a `[coordinates]` table): your order of rows, "
        "columns and shape components (default the model's); the other keys are the tables below",
    "energy": "your T, V, D as expressions; `L` the Lagrangian, checked as T - V",
    "generalized_forces": "`coordinate = \"Q\"` expressions; with `at = { theta = \"30deg\" }`, "
                          "values at that configuration (at rest): `theta = \"43.3 N*m\"`, item "
                          "`Q_theta`",
    "equations": "one per coordinate, `\"lhs = rhs\"` or an expression equal to zero",
    "multipliers": "`count = N` or `names = [...]`",
    "matrices": "`M`, `K`, `C` as lists of rows (expressions, or numbers read at the model's "
                "values), about the equilibrium of `[linearized]` or the one `modes` takes",
    "frequencies": "one of `omega = [\"4.43 rad/s\"]`, `f = [...]` (Hz), `period = [...]` (s), any "
                   "order; `zeta = [...]` damping ratios in ascending frequency",
    "mode_shapes": "`shapes = [[1, 1], [1, -1]]`, one per mode in ascending frequency, any scale "
                   "and sign",
    "linearized": "`about = { theta = 0 }`, one equation per coordinate (per independent "
                  "coordinate of a constrained model; any factor; in q or in its deviation from "
                  "`about`)",
    "statics": "`at = { theta = \"30deg\" }` and each load magnitude solved for (a parameter: "
               "`F = \"7.48 N\"`), optionally reactions `lambda_<constraint>`: `statics "
               "--solve-for`, item `statics.F`",
    "equilibria": "`theta = [\"0\", \"pi\"]` positions, any order (several coordinates: the i-th "
                  "entries make the i-th equilibrium)",
    "momenta": "`coordinate = \"p\"`, p = dL/dq_dot, item `p[x]`",
    "conserved": "`cyclic = [\"phi\"]` and `quantities = [\"...\"]` constant along every motion",
    "routhian": "`cyclic = [\"phi\"]` and `R` (= sum p q_dot - L) or `L_R` (= -R), in p_<name>",
    "hamiltonian": "`H` in the coordinates and momenta p_<coordinate>",
}


def _keys(keys) -> str:
    return ", ".join(f"`{k}`" for k in sorted(keys)) or "-"


def table() -> str:
    """The README table, one row per table of a model file, keys from the reader's schema."""
    lines = ["| table | required keys | optional keys | meaning |", "|---|---|---|---|"]
    for name, (required, optional) in model_file_schema().items():
        shown = "(top level)" if not name else f"`[{name}]`" if "<" in name else (
            f"`[[{name}]]`" if name not in ("energy", "gravity", "steady") else f"`[{name}]`")
        lines.append(f"| {shown} | {_keys(required)} | {_keys(optional)} | "
                     f"{MEANINGS.get(name, '**undocumented**')} |")
    return "\n".join(lines) + "\n"


def answer_table() -> str:
    """The README table of an answer file's tables, keys from the answer reader's schema."""
    lines = ["| table | required keys | optional keys | meaning |", "|---|---|---|---|"]
    for name, (required, optional) in answer_file_schema().items():
        shown = "(top level)" if not name else f"`[{name}]`"
        lines.append(f"| {shown} | {_keys(required)} | {_keys(optional)} | "
                     f"{ANSWER_MEANINGS.get(name, '**undocumented**')} |")
    return "\n".join(lines) + "\n"


def _readme_table(begin: str = BEGIN, end: str = END) -> str:
    text = PAGE.read_text(encoding="utf-8")
    assert begin in text and end in text, f"docs/model-file.md lost its markers {begin}"
    return text.split(begin, 1)[1].split(end, 1)[0].strip("\n") + "\n"


def test_every_table_of_the_reader_has_a_meaning():
    assert set(model_file_schema()) == set(MEANINGS)


def test_readme_lists_exactly_the_keys_the_reader_accepts():
    assert _readme_table() == table(), (
        "docs/model-file.md's model-file keys differ from model/reader.py: run "
        "python tests/test_readme_model_keys.py --write")


def test_every_table_of_the_answer_reader_has_a_meaning():
    assert set(answer_file_schema()) == set(ANSWER_MEANINGS)


def test_readme_lists_exactly_the_answer_keys_the_reader_accepts():
    assert _readme_table(ANSWER_BEGIN, ANSWER_END) == answer_table(), (
        "docs/model-file.md's answer-file keys differ from model/answer.py: run "
        "python tests/test_readme_model_keys.py --write")


def test_the_example_model_reads_and_derives(tmp_path):
    text = PAGE.read_text(encoding="utf-8")
    example = re.findall(r"```toml\n(.*?)```", text, re.S)[0]
    (tmp_path / "cart.toml").write_text(example, encoding="utf-8")
    system = lagrangian.load(tmp_path / "cart.toml")
    assert system.model.name == "Cart with a pendulum"
    assert [q.name for q in system.model.coordinates] == ["x", "theta"]
    # The push acts on the cart's coordinate only: Q = (F, 0).
    assert [str(q) for q in system.equations_of_motion().generalized_forces] == ["F", "0"]


def test_the_example_error_is_what_the_cli_prints(cli, tmp_path, monkeypatch):
    text = PAGE.read_text(encoding="utf-8")
    command, shown = re.search(r"```console\n\$ lagrangian (derive bad.toml)\n(.*?)```", text, re.S).groups()
    monkeypatch.chdir(tmp_path)
    (tmp_path / "bad.toml").write_text(
        '[coordinates]\ntheta = "rad"\n[parameters]\nL = 1.0\n[energy]\nT = "theta_dot^2"\n'
        'V = "Ln*cos(theta)"\n', encoding="utf-8")
    code, _, err = cli(*command.split())
    assert (code, err) == (2, shown)


def test_a_planar_body_point_is_offset_in_the_body_axes_as_the_page_says(tmp_path):
    assert "turned counterclockwise\nby `angle`" in PAGE.read_text(encoding="utf-8")
    # A link turned by theta, a vertical force F at offset [l, 0]: the point is at
    # (l cos(theta), l sin(theta)), so delta W = F l cos(theta) delta theta.
    (tmp_path / "link.toml").write_text(
        '[coordinates]\ntheta = "rad"\n[parameters]\nm = 1.0\nI = 0.1\nl = 0.5\nF = 2.0\n'
        '[[bodies]]\nname = "link"\nmass = "m"\ninertia = "I"\nposition = [0, 0]\n'
        'angle = "theta"\n[[loads]]\nname = "lift"\npoint = { body = "link", offset = ["l", 0] }\n'
        'force = [0, "F"]\n', encoding="utf-8")
    (q,) = lagrangian.load(tmp_path / "link.toml").equations_of_motion().generalized_forces
    assert str(q) == "F*l*cos(theta)"


def _rewritten(text: str) -> str:
    for begin, end, rows in ((BEGIN, END, table()), (ANSWER_BEGIN, ANSWER_END, answer_table())):
        head, rest = text.split(begin, 1)
        text = head + begin + "\n" + rows + end + rest.split(end, 1)[1]
    return text


if __name__ == "__main__":
    if sys.argv[1:] == ["--write"]:
        PAGE.write_text(_rewritten(PAGE.read_text(encoding="utf-8")), encoding="utf-8")
        sys.exit(0)
    print(BEGIN)
    print(table(), end="")
    print(END)
    print()
    print(ANSWER_BEGIN)
    print(answer_table(), end="")
    print(ANSWER_END)
