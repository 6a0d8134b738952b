"""The printed working (output/steps.py, output/crosscheck_steps.py): labels that never clash
with the model's own symbols, names escaped in LaTeX, user text clean on a terminal."""

from __future__ import annotations

import json

import pytest
import sympy as sp

from lagrangian import SystemBuilder
from lagrangian.output.crosscheck_steps import crosscheck_steps_text
from lagrangian.output.steps import steps_document, steps_latex, steps_text

CONTROLS = {chr(c) for c in [*range(0x00, 0x09), *range(0x0B, 0x20), 0x7F, 0x202E]}


def _link(load_name: str = "tip_force", length: str = "l"):
    """A link pinned at one end, a horizontal force at its tip (the seed's worked example 2)."""
    b = SystemBuilder("link")
    theta = b.coordinate("theta", unit="rad")
    m, l, F = (b.parameter(n, v, u) for n, v, u in
               (("m", 2.0, "kg"), (length, 0.5, "m"), ("F", 100.0, "N")))
    b.add_body("bar", m, m * l**2 / 12, (l / 2 * sp.sin(theta), -l / 2 * sp.cos(theta)), theta)
    b.add_force(load_name, (l * sp.sin(theta), -l * sp.cos(theta)), (F, 0))
    return b.build()


def test_the_lagrangian_is_L_unless_the_model_has_an_L():
    plain = steps_text(_link().steps())
    assert "  L = T - V = " in plain and "dL/dtheta_dot = " in plain
    clash = steps_text(_link(length="L").steps())
    assert "dL/d" not in clash and "d(T - V)/dtheta_dot = L**2*m*theta_dot/3" in clash
    latex = steps_latex(_link(length="L").steps())
    assert r"\frac{\partial \mathcal{L}}{\partial \dot{\theta}}" in latex


def test_load_names_are_escaped_in_latex_and_kept_in_json():
    steps = _link("tip_force&co").steps()
    latex = steps_latex(steps)
    assert r"\delta W_{\mathrm{tip\_force\&co}}" in latex
    assert r"\delta \theta" in latex  # delta q written as a variation, not a subscript
    assert steps_document(steps)["loads"][0]["load"] == "tip_force&co"
    assert r"\mathrm{tip\_force\&co}" in steps._repr_latex_()


def test_virtual_work_is_F_dot_delta_r_in_every_format():
    steps = _link().steps()
    text = steps_text(steps)
    assert "delta r = sum_i dr/dq_i delta q_i = (delta_theta*l*cos(theta), " \
           "delta_theta*l*sin(theta))" in text
    assert "delta W = F . delta r = F*delta_theta*l*cos(theta)" in text
    (load,) = steps_document(steps)["loads"]
    assert load["kind"] == "force" and load["Q"] == {"theta": "F*l*cos(theta)"}
    assert json.dumps(load)  # plain JSON


def test_free_body_text_names_each_force_and_the_reaction_moment():
    text = crosscheck_steps_text(_link().crosscheck_steps())
    assert "bar (body, m = m, I_G = l**2*m/12):" in text
    assert "tip_force: F = (F, 0), moment about G F*l*cos(theta)/2" in text
    assert "about G: l**2*m*theta_ddot/12 = F*l*cos(theta)/2 + M_R" in text


def test_hostile_names_reach_the_terminal_clean(cli, tmp_path):
    hostile = json.dumps("evil\x1b[2J\u202e name")
    path = tmp_path / "evil.toml"
    path.write_text(f"""name = {hostile}
[coordinates]
theta = {{ unit = "rad", initial = 0.3 }}
[parameters]
m = 1.0
L = 0.5
g = 9.81
[gravity]
g = "g"
direction = [0, -1]
[[particles]]
name = "bob"
mass = "m"
position = ["L*sin(theta)", "-L*cos(theta)"]
""", encoding="utf-8")
    for args in (["derive", str(path), "--steps"], ["derive", str(path), "--steps", "-f", "latex"],
                 ["crosscheck", str(path), "--steps"]):
        code, out, err = cli(*args)
        assert code == 0, err
        assert not CONTROLS & set(out + err), args


# -- large models: a step over STEP_NODES nodes is given by its size (--steps-full prints it) --

def test_a_step_too_large_to_follow_is_given_by_its_size(monkeypatch):
    import lagrangian
    from lagrangian.output import steps as steps_module

    steps = lagrangian.load("double_pendulum").steps()
    full = steps_text(steps, full=True)
    assert steps_text(steps) == full  # every step of the examples is under the limit
    monkeypatch.setattr(steps_module, "STEP_NODES", 20)
    short = steps_text(steps)
    assert "steps over 20 nodes are given by their size; derive --steps-full prints" in short
    assert "nodes: derive --steps-full prints it>" in short
    assert steps_text(steps, full=True) == full
    assert len(short) < len(full)
    assert r"nodes: derive --steps-full prints it)}" in steps_latex(steps)
    document = json.dumps(steps_document(steps))
    assert "nodes" not in document and "derive --steps-full" not in document  # always complete


def test_steps_full_flag(cli):
    code, out, err = cli("derive", "double_pendulum", "--steps-full")
    assert code == 0, err
    assert out == cli("derive", "double_pendulum", "--steps").out


@pytest.mark.slow
def test_the_bicycle_steps_are_a_few_pages_not_megabytes(cli):
    # the cheap proxy of size and time: the characters the working adds to derive's output
    # (2.75 million before the cap, its printing 13 s of the 14)
    plain = cli("derive", "whipple_bicycle").out
    code, out, err = cli("derive", "whipple_bicycle", "--steps")
    assert code == 0, err
    assert out.startswith(plain)
    working = out[len(plain):]
    assert len(working) < 50_000
    assert working.count("derive --steps-full prints it>") >= 25
    assert "dL/dthetaR_dot = IRyy*(psi_dot*sin(phi) + thetaR_dot + theta_dot)" in working
