"""Handout LaTeX (`derive --format latex [--standalone]`): dots on the symbol as
sympy.physics.mechanics writes them, each equation M q_ddot + Phi_q^T lambda = f read back from
the LaTeX and compared with the derived M, Phi_q and f, and the standalone document compiled by
pdflatex without errors or overfull lines."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest
import sympy as sp
from sympy.physics.vector import dynamicsymbols, vlatex

import lagrangian
from lagrangian.model.notation import model_latex_printer
from lagrangian.output.derivation import derivation_latex
from lagrangian.output.latex import escape_text, estimated_width

# -- reading the LaTeX back ---------------------------------------------------------------------

_TOKEN = re.compile(r"\\[A-Za-z]+|\\.|\d+|\S")
_OPEN = {r"\left(": r"\right)", r"\Bigl(": r"\Bigr)", r"\biggl(": r"\biggr)", "(": ")"}
_FUNCTIONS = {r"\sin": sp.sin, r"\cos": sp.cos, r"\tan": sp.tan}


def _tokens(text: str) -> list[str]:
    """Tokens with \\left( and its kin kept as one, and empty groups dropped."""
    raw = _TOKEN.findall(text.replace("{}", ""))
    out, i = [], 0
    while i < len(raw):
        if raw[i] in (r"\left", r"\right", r"\Bigl", r"\Bigr", r"\biggl", r"\biggr"):
            out.append(raw[i] + raw[i + 1])
            i += 2
        else:
            out.append(raw[i])
            i += 1
    return out


class _Reader:
    """The LaTeX subset sympy's printer writes (sums, implicit products, \\frac, powers,
    sin/cos, parentheses), back to sympy; the model's symbols matched by their LaTeX."""

    def __init__(self, text: str, symbols: dict[tuple[str, ...], sp.Symbol]):
        self.tokens, self.symbols, self.i = _tokens(text), symbols, 0

    def peek(self):
        return self.tokens[self.i] if self.i < len(self.tokens) else None

    def take(self, expected=None):
        token = self.tokens[self.i]
        assert expected is None or token == expected, (token, expected, self.tokens[self.i:])
        self.i += 1
        return token

    def sum(self, stop=None):
        total, sign = sp.S.Zero, 1
        if self.peek() in ("+", "-"):
            sign = -1 if self.take() == "-" else 1
        while True:
            total += sign * self.product(stop)
            if self.peek() not in ("+", "-"):
                return total
            sign = -1 if self.take() == "-" else 1

    def product(self, stop):
        value = self.power()
        while self.peek() not in (None, "+", "-", "}", "=", stop, *_OPEN.values()):
            value *= self.power()
        return value

    def power(self):
        base = self.atom()
        if self.peek() == "^":
            self.take()
            base = base ** self.group()
        return base

    def group(self):
        if self.peek() != "{":
            return sp.Integer(self.take())
        self.take("{")
        value = self.sum()
        self.take("}")
        return value

    def atom(self):
        for length in range(64, 0, -1):  # the longest symbol whose tokens start here
            key = tuple(self.tokens[self.i:self.i + length])
            if key in self.symbols:
                self.i += length
                return self.symbols[key]
        token = self.take()
        if token.isdigit():
            return sp.Integer(token)
        if token == "{":
            value = self.sum()
            self.take("}")
            return value
        if token in _OPEN:
            value = self.sum(_OPEN[token])
            self.take(_OPEN[token])
            return value
        if token == r"\frac":
            return self.group() / self.group()
        if token in _FUNCTIONS:
            exponent = 1
            if self.peek() == "^":
                self.take()
                exponent = self.group()
            return _FUNCTIONS[token](self.group()) ** exponent
        raise AssertionError(f"unread token {token!r} in {' '.join(self.tokens)}")


def _symbols(eom) -> dict[tuple[str, ...], sp.Symbol]:
    printer = model_latex_printer(eom.model)
    model = eom.model
    symbols = [*model.q, *model.q_dot, *model.q_ddot, *eom.multipliers,
               *(p.symbol for p in model.parameters)]
    return {tuple(_tokens(printer.doprint(s))): s for s in symbols}


def _equations(latex: str) -> dict[str, tuple[str, str]]:
    """Tag (the coordinate's LaTeX) -> (left, right) of each equation environment."""
    out = {}
    for _, body in re.findall(r"\\begin\{(equation|align)\}\n(.*?)\\end\{\1\}", latex, re.S):
        if r"\tag{$" not in body:
            continue  # the energies and forces
        tag = re.search(r"\\tag\{\$(.*?)\$\}", body).group(1)
        body = re.sub(r"\\tag\{\$.*?\$\}", "", body)
        for noise in (r"\notag", r"\\", "&", r"\quad"):
            body = body.replace(noise, " ")
        left, right = body.split("=")
        out[tag] = (left, right)
    return out


def _vanishes(expr) -> bool:
    return sp.simplify(sp.expand_trig(expr)) == 0


# -- dots on the symbol ---------------------------------------------------------------------


def test_dots_sit_on_the_symbol_as_sympy_mechanics_writes_them():
    t = dynamicsymbols._t
    theta1 = dynamicsymbols("theta1")
    latex = derivation_latex(lagrangian.load("double_pendulum").equations_of_motion())
    assert vlatex(theta1.diff(t) ** 2) in latex  # \dot{\theta}_{1}^{2}
    assert vlatex(theta1.diff(t, 2)) in latex  # \ddot{\theta}_{1}
    assert r"\dot{\theta_{1}}" not in latex and r"\ddot{\theta_{1}}" not in latex
    pendulum = derivation_latex(lagrangian.load("pendulum").equations_of_motion())
    assert vlatex(dynamicsymbols("theta").diff(t) ** 2) in pendulum  # \dot{\theta}^{2}


def test_dots_on_greek_with_letters_and_on_words():
    eom = lagrangian.System(lagrangian.parse_model("""
name = "Wheel"
[coordinates]
phi_R = "rad"
lean = "rad"
[parameters]
I = 1.0
[energy]
T = "I*phi_R_dot^2/2 + I*lean_dot^2/2"
V = "0"
""")).equations_of_motion()
    printer = model_latex_printer(eom.model)
    phi_dot, lean_dot = eom.model.q_dot
    assert printer.doprint(phi_dot ** 2) == r"\dot{\phi}_{R}^{2}"
    assert printer.doprint(eom.model.q_ddot[0]) == r"\ddot{\phi}_{R}"
    # a dotted word's exponent at a letter's height, not raised above the dot
    assert printer.doprint(lean_dot ** 2) == r"\dot{lean}{}^{2}"
    assert r"\ddot{lean}" in derivation_latex(eom)


def test_jupyter_shows_dots_in_matrices_and_equations():
    eom = lagrangian.load("double_pendulum").equations_of_motion()
    forcing = eom.forcing._repr_latex_()
    assert r"\dot{\theta}_{2}^{2}" in forcing and "dot}" not in forcing
    assert r"\ddot{\theta}_{1}" in eom.equations._repr_latex_()
    assert eom.forcing == sp.ImmutableMatrix(eom.forcing) and hash(eom.forcing) == hash(
        sp.ImmutableMatrix(eom.forcing))
    shown = eom._repr_latex_()
    assert shown.startswith("$") and r"&= - g l_{1}" in shown  # accelerations left, f right
    assert shown.index(r"\ddot{\theta}_{1}") < shown.index(r"\ddot{\theta}_{2}")


def test_jupyter_shows_dots_in_the_reactions():
    reaction = lagrangian.load("double_pendulum").crosscheck().reactions[0]._repr_latex_()
    assert r"\ddot{\theta}_{1}" in reaction and r"\dot{\theta}_{1}^{2}" in reaction
    assert "dot}" not in reaction and r"\dot{d}" not in reaction


# -- M q_ddot + Phi_q^T lambda = f --------------------------------------------------------------


@pytest.mark.parametrize("name", ["double_pendulum", "rolling_coin", "cartesian_pendulum"])
def test_each_equation_reads_back_as_mass_matrix_times_accelerations(name):
    """Left side: the accelerations' coefficients are the row of M, the multipliers' the
    column of Phi_q, and nothing else; right side: f. Accelerations in coordinate order."""
    eom = lagrangian.load(name).equations_of_motion()
    latex = derivation_latex(eom)
    equations = _equations(latex)
    printer = model_latex_printer(eom.model)
    symbols = _symbols(eom)
    M, A, f = eom.mass_matrix, eom.constraint_jacobian, eom.forcing
    assert len(equations) == len(eom.model.coordinates)
    for i, c in enumerate(eom.model.coordinates):
        left_text, right_text = equations[printer.doprint(c.symbol)]
        left = _Reader(left_text, symbols).sum()
        right = _Reader(right_text, symbols).sum()
        unknowns = [*eom.model.q_ddot, *eom.multipliers]
        for j, a in enumerate(eom.model.q_ddot):
            assert _vanishes(left.diff(a) - M[i, j]), (c.name, a)
        for k, lam in enumerate(eom.multipliers):
            assert _vanishes(left.diff(lam) - A[k, i]), (c.name, lam)
        assert left.xreplace({u: 0 for u in unknowns}) == 0
        assert _vanishes(right - f[i]), c.name
        places = [left_text.find(printer.doprint(a)) for a in eom.model.q_ddot
                  if M[i, eom.model.q_ddot.index(a)] != 0]
        assert places == sorted(places) and -1 not in places


def test_tags_name_the_coordinate_and_fit():
    latex = derivation_latex(lagrangian.load("double_pendulum").equations_of_motion())
    assert r"\tag{$\theta_{1}$}" in latex and r"\tag{$\theta_{2}$}" in latex
    assert r"\text{(" not in latex and "&& " not in latex


def test_long_rows_are_broken_and_a_wide_matrix_listed_by_entries():
    latex = derivation_latex(lagrangian.load("rolling_coin").equations_of_motion())
    assert r"\notag \\" + "\n&= " in latex and r"&\quad {} + " in latex  # a long equation
    assert "M_{11} &= " in latex and "M_{21}" not in latex  # symmetric: the upper triangle
    for line in latex.splitlines():
        row = re.sub(r"\\(notag|tag\{.*?\})|\\\\$|&", "", line)
        if not line.startswith(("%", r"\begin", r"\end")):
            assert estimated_width(row) < 400, line


def test_the_width_estimate_tracks_the_glyphs():
    assert estimated_width("m") < estimated_width("m + m") < estimated_width(r"m + m + m")
    assert estimated_width(r"\frac{a b c d}{2}") == pytest.approx(
        estimated_width("a b c d") + 2.4)
    assert estimated_width(r"x^{2}") < estimated_width("x 2")


# -- user text never reaches LaTeX unescaped --------------------------------------------------

HOSTILE = (r"Evil } \input{/etc/passwd} $x$ 100% #1 a_b ^^5c ~ & \end{document}"
           " Pendule à ressort – “q” ☺")


def test_escape_text_neutralises_every_special_character():
    escaped = escape_text(HOSTILE + "\nnext \x00 \u263a")
    assert r"\input" not in escaped.replace(r"\textbackslash{}input", "")
    assert "\n" not in escaped and "\x00" not in escaped and "\u263a" not in escaped
    assert "Pendule à ressort -- ``q'' ?" in escaped
    unescaped = re.sub(r"\\ensuremath\{(\\backslash|<|>|\|)\}|\\[\^~]\{\}|\\[{}$&%#_]", "",
                       escaped)
    assert not set(unescaped) & set("\\{}$&%#_^~")


def _hostile_system():
    return lagrangian.System(lagrangian.parse_model(
        'name = ' + _toml_string(HOSTILE) + '\n' + """
[coordinates]
x = "m"
[parameters]
m = 1.0
k = 1.0
[energy]
T = "m*x_dot^2/2"
V = "k*x^2/2"
"""))


def _toml_string(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def test_a_hostile_name_is_text_in_the_document():
    document = _hostile_system().to_latex(standalone=True)
    assert r"\input" not in document and r"\title{Evil \} \ensuremath{\backslash}input\{" in document
    assert document.count(r"\end{document}") == 1
    fragment = _hostile_system().to_latex()
    assert fragment.startswith("% Evil \\} ") and r"\input" not in fragment


# -- the standalone document ------------------------------------------------------------------


def test_cli_writes_the_standalone_document(cli):
    result = cli("derive", "pendulum", "--format", "latex", "--standalone")
    assert result.code == 0 and result.out.startswith(r"\documentclass")
    assert r"\usepackage{amsmath,amssymb}" in result.out and r"\title{Simple pendulum}" in result.out
    assert result.out.rstrip().endswith(r"\end{document}")
    assert result.out == lagrangian.load("pendulum").to_latex(standalone=True)


def test_standalone_without_latex_is_refused(cli):
    code, out, err = cli("derive", "pendulum", "--standalone")
    assert code == 2 and out == ""
    assert err.strip() == ("error: --standalone: --standalone writes a LaTeX document; "
                           "give it with --format latex")


_INSTALL_LATEX = Path(__file__).resolve().parents[2] / ".ci" / "install-latex"


def _pdflatex():
    """pdflatex, installed first by the project's own .ci/install-latex where it is missing
    (Debian's texlive-latex-base; the README's test command then needs nothing more)."""
    found = shutil.which("pdflatex")
    if found is None and _INSTALL_LATEX.exists():
        subprocess.run(["bash", str(_INSTALL_LATEX)], capture_output=True, timeout=900,
                       check=False)
        found = shutil.which("pdflatex")
    if found is None:
        pytest.skip("pdflatex is missing (Debian: apt-get install texlive-latex-base; "
                    ".ci/install-latex installs it where it can)")
    return found


def _chain(n: int) -> lagrangian.System:
    """The n-link pendulum (point masses on massless rods): equations pages long."""
    b = lagrangian.SystemBuilder(f"{n}-link pendulum")
    g = b.parameter("g", 9.81)
    x, y = sp.S.Zero, sp.S.Zero
    for i in range(1, n + 1):
        theta = b.coordinate(f"theta{i}", unit="rad")
        mass, length = b.parameter(f"m{i}", 1.0), b.parameter(f"l{i}", 1.0)
        x, y = x + length * sp.sin(theta), y - length * sp.cos(theta)
        b.add_particle(f"bob{i}", mass, (x, y))
    b.set_gravity(g, (0, -1))
    return b.build()


@pytest.mark.parametrize("name", ["pendulum", "double_pendulum", "rolling_coin", "torque_free_body",
                                  "<12 links>", "<hostile>"])
def test_pdflatex_compiles_the_handout_without_overfull_lines(name, tmp_path):
    """No error, no overfull line and no overfull page: long equations break between rows."""
    pdflatex = _pdflatex()
    system = (_hostile_system() if name == "<hostile>" else _chain(12) if name == "<12 links>"
              else lagrangian.load(name))
    (tmp_path / "handout.tex").write_text(system.to_latex(standalone=True), encoding="utf-8")
    run = subprocess.run([pdflatex, "-interaction=nonstopmode", "-halt-on-error", "-no-shell-escape",
                          "handout.tex"], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    log = (tmp_path / "handout.log").read_text(encoding="latin-1")
    assert run.returncode == 0, log[-3000:]
    assert not re.search(r"^! ", log, re.M), log[-3000:]
    assert "Overfull" not in log, re.findall(r"Overfull .*", log)
    assert "/etc/passwd" not in log  # the hostile name's \input was never run
    assert (tmp_path / "handout.pdf").stat().st_size > 1000


# -- docs/handouts.md ---------------------------------------------------------------------------

DOCS = Path(__file__).resolve().parents[2] / "docs" / "handouts.md"


def _docs_section() -> str:
    text = DOCS.read_text(encoding="utf-8")
    return text[text.index("<!-- BEGIN handout -->"):text.index("<!-- END handout -->")]


def test_docs_python_example_prints_what_it_says(capsys):
    code = re.findall(r"```python\n(.*?)```", _docs_section(), re.S)[0]
    exec(compile(code, "docs/handouts.md", "exec"), {})
    shown = re.findall(r"```text\n(.*?)```", _docs_section(), re.S)[0]
    assert capsys.readouterr().out == shown


def test_docs_commands_run(cli, tmp_path):
    commands = re.findall(r"^\$ (.*)$", _docs_section(), re.M)
    engineers = (DOCS.parent / "getting-started" / "engineers.md").read_text(encoding="utf-8")
    assert f"$ {commands[0]}   #" in engineers  # the engineers' page shows this command
    derive = commands[0].split(" > ")[0].split()[1:]
    result = cli(*derive)
    assert commands[0].startswith("lagrangian derive") and result.code == 0
    assert result.out == lagrangian.load("double_pendulum").to_latex(standalone=True)
    if shutil.which("pdflatex"):
        (tmp_path / "handout.tex").write_text(result.out, encoding="utf-8")
        program, *arguments = commands[1].split()
        run = subprocess.run([program, "-interaction=nonstopmode", *arguments], cwd=tmp_path,
                             capture_output=True, text=True, timeout=120)
        assert run.returncode == 0 and (tmp_path / "handout.pdf").exists()
