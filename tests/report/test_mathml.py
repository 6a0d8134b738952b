"""MathML for the report page: text escaped by construction, dots over velocities, MathML Core
tags only (what Chromium renders without a script)."""

from __future__ import annotations

import re
from xml.dom import minidom

import sympy as sp

import lagrangian
from lagrangian.report.mathml import DOT, DOUBLE_DOT, MathWriter, math_block, mi, mtext

# The presentation elements of MathML Core (https://w3c.github.io/mathml-core/).
CORE = {"math", "mrow", "mi", "mn", "mo", "mtext", "mspace", "ms", "mfrac", "msqrt", "mroot",
        "msub", "msup", "msubsup", "munder", "mover", "munderover", "mmultiscripts",
        "mprescripts", "mtable", "mtr", "mtd", "mstyle", "mpadded", "mphantom", "merror",
        "semantics", "annotation", "none"}


def _parse(markup: str):
    return minidom.parseString(markup)  # well-formed XML, or it raises


def test_hostile_symbol_names_are_escaped():
    hostile = sp.Symbol("</math><script>alert(1)</script>&amp;")
    markup = MathWriter()(hostile + 1)
    assert "<script>" not in markup and "</math>" not in markup
    document = _parse(math_block(markup))
    texts = "".join(n.data for n in document.getElementsByTagName("mi")[0].childNodes)
    assert "<script>" in texts  # the name itself survives, as text
    assert "&lt;script&gt;" in mi("<script>") and "&lt;/math&gt;" in mtext("</math>")


def test_entities_sympy_writes_become_characters():
    markup = MathWriter()(sp.pi * sp.Symbol("x") - sp.oo)
    assert "&amp;" not in markup
    assert "\u03c0" in markup and "\u221e" in markup


def test_velocities_and_accelerations_get_dots_over_their_coordinate():
    pendulum = lagrangian.load("double_pendulum")
    write = MathWriter(pendulum.model)
    theta1 = pendulum.symbol("theta1")
    velocity, acceleration = pendulum.symbol("theta1_dot"), pendulum.symbol("theta1_ddot")
    dotted = _parse(math_block(write(velocity ** 2)))
    over = dotted.getElementsByTagName("mover")[0]
    assert over.parentNode.tagName == "msub"  # the dot on theta, the index 1 beside it
    assert over.lastChild.firstChild.data == DOT
    assert "dot" not in write(velocity)
    assert DOUBLE_DOT in write(acceleration)
    assert write(theta1) in write(theta1 + 0)  # the coordinate itself undotted


def test_multipliers_are_lambda_with_their_constraint():
    crank = lagrangian.load("slider_crank")
    markup = MathWriter(crank.model)(crank.equations_of_motion().multipliers[0])
    assert "\u03bb" in markup and "<mtext>loop_y</mtext>" in markup


def test_only_mathml_core_elements_and_a_real_minus():
    pendulum = lagrangian.load("double_pendulum")
    eom = pendulum.equations_of_motion()
    write = MathWriter(pendulum.model)
    markup = math_block(write(eom.mass_matrix), write(eom.forcing), write(sp.Abs(sp.Symbol("x"))))
    tags = set(re.findall(r"<([a-z]+)", markup))
    assert tags <= CORE, tags - CORE
    assert "<mo>-</mo>" not in markup and "<mo>\u2212</mo>" in markup


def test_parentheses_stretch_only_around_something_taller_than_a_line():
    x, y = sp.symbols("x y")
    flat = MathWriter()(sp.cos(x + y))
    assert flat.count('<mo stretchy="false">') == 2
    tall = MathWriter()(sp.cos(x / (y + 1) + 1))  # the fraction inside: fences grow
    assert "stretchy" not in tall
    matrix = MathWriter()(sp.Matrix([[x], [y]]))
    assert "stretchy" not in matrix.split("<mtable>")[0]  # a matrix's brackets grow
