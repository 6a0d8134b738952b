"""The README's table of model-file keys is generated from the reader's own schema
(model/reader.py, ``model_file_schema``): a key the reader accepts and the README does not list,
or one the README lists and the reader refuses, fails here.

Regenerate the table after changing the reader:  python tests/test_readme_model_keys.py
(prints the table to paste between the README's model-keys markers; the meanings are below).
"""

from __future__ import annotations

from pathlib import Path

from lagrangian.model.reader import model_file_schema

README = Path(__file__).resolve().parents[1] / "README.md"
BEGIN, END = "<!-- BEGIN model-keys (generated: python tests/test_readme_model_keys.py) -->", \
    "<!-- END model-keys -->"

# What each table is for; the keys themselves come from the reader.
MEANINGS = {
    "": "`name`, `description`: strings; `definitions`: `name = \"expression\"`, substituted "
        "everywhere; `generalized_forces`: `coordinate = \"Q\"` added to Q; the other keys are "
        "the tables below",
    "coordinates.<name>": "a unit string, or this table: `unit` (default m), `initial` value, "
                          "`rate` (initial q_dot), `range = [low, high]` (searched by "
                          "equilibria; a printed abs() whose sign it fixes is dropped)",
    "parameters.<name>": "a number (SI), or this table (`value` converted to SI from `unit`); "
                         "no value: symbolic only",
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
    "steady": "the steady motion `speeds` linearizes about by default: `speed` a parameter "
              "(m/s), `rates = { x_dot = \"v\" }` in the parameters, `keep` the coordinates "
              "whose equations stay, `about` coordinate values",
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


def _readme_table() -> str:
    text = README.read_text(encoding="utf-8")
    assert BEGIN in text and END in text, "README lost its model-keys markers"
    return text.split(BEGIN, 1)[1].split(END, 1)[0].strip("\n") + "\n"


def test_every_table_of_the_reader_has_a_meaning():
    assert set(model_file_schema()) == set(MEANINGS)


def test_readme_lists_exactly_the_keys_the_reader_accepts():
    assert _readme_table() == table(), (
        "README's model-file keys differ from model/reader.py: run "
        "python tests/test_readme_model_keys.py and paste the table between the markers")


if __name__ == "__main__":
    print(BEGIN)
    print(table(), end="")
    print(END)
