"""Every diagnosis code on a real system of the seed, and correct answers written differently."""

from __future__ import annotations

import pytest
from check_helpers import check_file, check_text, finding

import lagrangian
from lagrangian.check.diagnose import CODES

# -- potential energy ---------------------------------------------------------------------


def test_pendulum_potential_with_the_wrong_sign():
    report = check_file("pendulum", "pendulum_wrong_potential.toml")
    assert report.verdict == "incorrect"
    v = finding(report, "V")
    assert (v.status, v.code) == ("wrong", "potential_sign")
    assert "Does V increase as the body rises?" in v.message
    assert v.expected == "-L*g*m*cos(theta)"
    # The equation built from that V has the gravity term with the wrong sign.
    eq = finding(report, "equation[theta]")
    assert eq.code == "equation_wrong"
    # the gravity term on the right-hand side with the sign of V flipped, each term stated with
    # the sign it has there
    assert "yours has L*g*m*sin(theta) where ours has -L*g*m*sin(theta)" in eq.message


def test_other_datum_is_fine_and_said_so():
    report = check_file("pendulum", "pendulum_other_datum.toml")
    assert report.verdict == "correct"
    v = finding(report, "V")
    assert (v.status, v.code) == ("equivalent", "potential_datum")
    assert "L*g*m" in v.message and "datum" in v.message
    assert finding(report, "T").status == "correct"


def test_sign_of_one_part_of_V_is_named():
    # A hanging mass on a spring: gravity written with the wrong sign, the spring right.
    text = """
[energy]
V = "-m*g*y + 1/2*k*(y - l0)^2"
"""
    from lagrangian import SystemBuilder

    b = SystemBuilder("Hanging spring")
    y = b.coordinate("y", unit="m")
    m, g, k, l0 = (b.parameter(n, v, u) for n, v, u in
                   (("m", 1.0, "kg"), ("g", 9.81, "m/s^2"), ("k", 40.0, "N/m"), ("l0", 0.3, "m")))
    b.set_gravity(g, (0, -1)).add_particle("mass", m, (0, y))
    b.add_spring("spring", k, l0, length=y)
    from lagrangian.model.answer import parse_answer

    s = b.build()
    report = s.check(parse_answer(text, s.model))
    v = finding(report, "V")
    assert v.code == "potential_sign"
    assert "gravity potential of 'mass'" in v.message


# -- kinetic energy -----------------------------------------------------------------------


def test_forgotten_half_is_a_kinetic_factor():
    t = finding(check_file("pendulum", "pendulum_forgot_half.toml"), "T")
    assert (t.status, t.code) == ("wrong", "kinetic_factor")
    assert "T is 2 times" in t.message and "1/2" in t.message


def test_missing_mass_is_a_kinetic_factor_and_a_units_mismatch():
    report = check_file("two_mass", "two_mass_missing_coupling.toml")
    assert "kinetic_factor" in report.codes("T")
    assert "1/m times" in finding(report, "T").message
    assert "units_mismatch" in report.codes("T")


def test_missing_rotational_term_of_the_link_is_named():
    t = finding(check_file("virtual_work_link", "link_missing_rotation.toml"), "T")
    assert t.code == "kinetic_term"
    assert "rotational energy 1/2 I w^2 of body 'link'" in t.message
    assert "L**2*m*theta_dot**2/24" in t.message  # 1/2 (m L^2/12) theta_dot^2
    assert t.expected == "L**2*m*theta_dot**2/6"


def test_missing_slider_term_of_the_slider_crank():
    report = check_file("slider_crank", "slider_crank_answers.toml")
    t = finding(report, "T")
    assert t.code == "kinetic_term" and "particle 'slider'" in t.message
    assert "m3*x_dot**2/2" in t.message
    assert finding(report, "V").status == "correct"


def test_link_T_about_the_pin_is_accepted():
    report = check_file("virtual_work_link", "link_correct.toml")
    assert report.verdict == "correct"
    assert [f.status for f in report.findings] == ["correct", "correct"]


# -- generalized forces --------------------------------------------------------------------


def test_tip_force_projected_with_sin_instead_of_cos():
    q = finding(check_file("virtual_work_link", "link_misprojected.toml"), "Q[theta]")
    assert q.code == "generalized_force_projection"
    assert "dr = dr/dtheta dtheta = (L*cos(theta), L*sin(theta)) dtheta" in q.message
    assert q.expected == "F*L*cos(theta)"


@pytest.mark.parametrize("wrong", ["-F*L*cos(theta)", "F*L/2*cos(theta)"])
def test_wrong_sign_or_lever_arm_is_a_projection_error(wrong):
    report = check_text("virtual_work_link", f'[generalized_forces]\ntheta = "{wrong}"\n')
    assert finding(report, "Q[theta]").code == "generalized_force_projection"


def test_forgotten_load_is_named_with_its_virtual_work():
    q = finding(check_file("virtual_work_link", "link_missing_force.toml"), "Q[theta]")
    assert q.code == "generalized_force_missing"
    assert "'F'" in q.message and "dW = (F*L*cos(theta)) dtheta" in q.message


def test_cart_push_left_out():
    report = check_file("cart_pendulum", "cart_pendulum_missing_push.toml")
    assert finding(report, "Q[x]").code == "generalized_force_missing"
    assert "'push'" in finding(report, "Q[x]").message
    assert finding(report, "Q[theta]").status == "correct"  # the push does no work on theta


def test_gravity_put_in_Q_instead_of_V_is_equivalent():
    report = check_text("ladder_pendulum",
                        '[generalized_forces]\ntheta = "-m*g*L*sin(theta)"\n')
    q = finding(report, "Q[theta]")
    assert q.status == "equivalent"
    assert report.verdict == "correct"


def test_Q_in_newton_metres_for_an_angle():
    report = check_text("virtual_work_link", '[generalized_forces]\ntheta = "F*cos(theta)"\n')
    assert "units_mismatch" in report.codes("Q[theta]")
    unit = [f for f in report.findings if f.code == "units_mismatch"][0]
    assert "N*m" in unit.message and "F*cos(theta)" in unit.message


# -- reactions and multipliers --------------------------------------------------------------


def test_rod_tension_in_minimal_coordinates():
    report = check_file("pendulum", "pendulum_rod_tension.toml")
    eq = finding(report, "equation[theta]")
    assert eq.code == "reaction_in_minimal_coordinates"
    assert "T_rod" in eq.message and "Without them the equation matches ours" in eq.message
    q = finding(report, "Q[theta]")
    assert q.code == "reaction_in_minimal_coordinates" and "N" in q.message


def test_one_multiplier_for_two_loop_constraints():
    m = finding(check_file("slider_crank", "slider_crank_answers.toml"), "multipliers")
    assert m.code == "multiplier_count"
    assert m.expected == "lambda_loop_y, lambda_loop_x"


def test_two_multipliers_for_one_rod():
    report = check_file("cartesian_pendulum", "cartesian_pendulum_two_multipliers.toml")
    assert report.codes("multipliers") == ["multiplier_count"]
    assert "N_x" in finding(report, "multipliers").message


def test_rod_tension_as_a_scaled_multiplier_is_accepted():
    report = check_file("cartesian_pendulum", "cartesian_pendulum_tension.toml")
    assert report.verdict == "correct", report
    assert finding(report, "equation[x]").code == "equation_equivalent"
    assert finding(report, "multipliers").status == "correct"


def test_cartesian_pendulum_with_gravity_sign_wrong():
    report = check_text("cartesian_pendulum", """
[equations]
x = "m*x_ddot + 2*x*lambda_rod = 0"
y = "m*y_ddot + 2*y*lambda_rod = m*g"
""")
    assert finding(report, "equation[x]").status == "correct"
    y = finding(report, "equation[y]")
    assert y.code == "equation_wrong" and "2*g*m" in y.message.replace("-", "")


# -- equations ----------------------------------------------------------------------------


def test_equation_times_minus_m_L_squared_is_accepted():
    report = check_file("pendulum", "pendulum_times_minus_mL2.toml")
    assert report.verdict == "correct"
    eq = finding(report, "equation[theta]")
    assert eq.code == "equation_equivalent" and "-L**2*m" in eq.message


def test_missing_coupling_term_is_named():
    eq = finding(check_file("two_mass", "two_mass_missing_coupling.toml"), "equation[x1]")
    assert eq.code == "equation_wrong"
    # the coupling spring's force k_c (x1 - x2), stated once, with the sign it has in ours
    assert "right-hand side (the forcing f) lacks the term k_c*(-x1 + x2)" in eq.message
    assert eq.expected == "m*x1_ddot = -(k*x1 + k_c*(x1 - x2))"


def test_sum_and_difference_of_the_equations_are_accepted():
    report = check_file("two_mass", "two_mass_recombined.toml")
    assert report.verdict == "correct"
    assert report.codes() == ["potential_datum", "equation_equivalent", "equation_equivalent"]


def test_a_singular_combination_is_not_accepted():
    # Both equations the same combination: not invertible, so not equivalent.
    report = check_text("two_mass", """
[equations]
x1 = "m*(x1_ddot + x2_ddot) + k*(x1 + x2) = 0"
x2 = "2*m*(x1_ddot + x2_ddot) + 2*k*(x1 + x2) = 0"
""")
    assert report.verdict == "incorrect"
    assert set(report.codes()) == {"equation_wrong"}


def test_units_of_an_equation_are_checked():
    report = check_file("pendulum", "pendulum_units.toml")
    assert "units_mismatch" in report.codes("equation[theta]")
    assert "units_mismatch" in report.codes("T")


def test_every_code_is_exercised_by_this_file():
    import inspect
    import sys

    source = inspect.getsource(sys.modules[__name__])
    for code in CODES:
        assert f'"{code}"' in source or f"'{code}'" in source, code


def test_double_pendulum_energies_by_hand_are_accepted():
    # The textbook form with cos(theta1 - theta2), not the component form we derive.
    report = check_text("double_pendulum", '''
[energy]
T = """(1/2*(m1 + m2)*l1^2*theta1_dot^2 + 1/2*m2*l2^2*theta2_dot^2
     + m2*l1*l2*theta1_dot*theta2_dot*cos(theta1 - theta2))"""
V = "-(m1 + m2)*g*l1*cos(theta1) - m2*g*l2*cos(theta2)"
''')
    assert report.verdict == "correct", report
    assert [f.status for f in report.findings] == ["correct", "correct"]


def _slider_crank_equations(transform):
    from check_helpers import system

    from lagrangian.model.expressions import format_expression

    s = system("slider_crank")
    equations = transform(list(s.equations_of_motion().equations), s)
    lines = [f'{c.name} = "{format_expression(e)}"'
             for c, e in zip(s.model.coordinates, equations, strict=True)]
    return "[equations]\n" + "\n".join(lines) + "\n[multipliers]\ncount = 2\n"


def test_slider_crank_equations_times_minus_three_are_accepted():
    report = check_text("slider_crank", _slider_crank_equations(lambda e, s: [-3 * x for x in e]))
    assert report.verdict == "correct", report
    assert report.codes() == ["equation_equivalent"] * 3


def test_slider_crank_spring_left_out_of_the_slider_equation():
    def drop_spring(equations, s):
        return equations[:2] + [equations[2].subs(s.symbol("k"), 0)]

    report = check_text("slider_crank", _slider_crank_equations(drop_spring))
    assert [f.status for f in report.findings[:2]] == ["correct", "correct"]
    x = finding(report, "equation[x]")
    assert x.code == "equation_wrong" and "k*(-x + x0)" in x.message


def test_parallel_axis_double_count_is_a_kinetic_term():
    # I about the pin (m L^2/3) and the centre's translation as well: translation counted twice.
    report = check_text("virtual_work_link",
                        '[energy]\nT = "1/2*(m*L^2/3)*theta_dot^2 + 1/2*m*(L/2)^2*theta_dot^2"\n')
    t = finding(report, "T")
    assert t.code == "kinetic_term"
    assert "counts the translational energy 1/2 m v_G^2 of body 'link' twice" in t.message


def test_a_missing_mass_is_said_so():
    t = finding(check_text("pendulum", '[energy]\nT = "1/2*L^2*theta_dot^2"\n'), "T")
    assert t.code == "kinetic_factor" and "a missing mass m?" in t.message


def test_numbers_in_place_of_parameters_are_compared_at_the_model_values():
    # Worked example 2 with its numbers: Q = 100 N x 0.5 m x cos(theta).
    report = check_text("virtual_work_link", '[generalized_forces]\ntheta = "100*0.5*cos(theta)"\n')
    assert report.verdict == "correct", report
    assert "model's parameter values" in finding(report, "Q[theta]").message
    report = check_text("pendulum", '[energy]\nV = "-m*9.81*L*cos(theta)"\n')
    assert finding(report, "V").status == "correct"
    wrong = check_text("pendulum", '[energy]\nV = "9.81*0.5*cos(theta)"\n')
    assert finding(wrong, "V").code == "potential_sign"
    # Plain factors like 1/2 are not numbers standing in for parameters: a missing m is wrong
    # even though the model's m is 1 kg.
    missing_m = check_text("pendulum", '[energy]\nT = "1/2*L^2*theta_dot^2"\n')
    assert finding(missing_m, "T").code == "kinetic_factor"


@pytest.mark.parametrize("name", lagrangian.examples())
def test_every_example_accepts_its_own_derivation_and_rejects_a_changed_one(name):
    from lagrangian.model.answer import answer_from_mapping
    from lagrangian.model.expressions import MAX_LENGTH, format_expression

    s = lagrangian.load(name)
    eom, model = s.equations_of_motion(), s.model
    names = [c.name for c in model.coordinates]
    data = {
        "energy": {"T": format_expression(eom.kinetic_energy),
                   "V": format_expression(eom.potential_energy)},
        "equations": {n: format_expression(-2 * e) for n, e in zip(names, eom.equations,
                                                                    strict=True)},
    }
    if model.constraints:
        data["multipliers"] = {"count": len(model.constraints)}
    if max(len(text) for text in data["equations"].values()) > MAX_LENGTH:
        # No one writes the bicycle's equations by hand (they are past what an answer file
        # may hold): its energies are checked, and a V of the wrong sign is found.
        del data["equations"]
        report = s.check(answer_from_mapping(data, model))
        assert report.verdict == "correct", report
        flipped = {**data, "energy": {**data["energy"],
                                      "V": format_expression(-eom.potential_energy)}}
        wrong = s.check(answer_from_mapping(flipped, model))
        assert finding(wrong, "V").code == "potential_sign", wrong
        return
    report = s.check(answer_from_mapping(data, model))
    assert report.verdict == "correct", report
    # The first equation with its velocity-independent forcing doubled is wrong.
    changed = dict(data["equations"])
    first = eom.equations[0]
    extra = -eom.forcing[0].xreplace({v: 0 for v in model.q_dot})
    if extra == 0:
        extra = eom.mass_matrix[0, 0] * model.q[0]  # a spring that is not there
    changed[names[0]] = format_expression(-2 * (first + extra))
    wrong = s.check(answer_from_mapping({**data, "equations": changed}, model))
    assert finding(wrong, f"equation[{names[0]}]").code == "equation_wrong", wrong


def test_python_api_takes_the_tables_as_a_dict():
    report = lagrangian.load("pendulum").check({"energy": {"V": "m*g*L*cos(theta)"}})
    assert report.codes() == ["potential_sign"] and not report.correct
    with pytest.raises(lagrangian.ModelError, match="unknown key 'U'"):
        lagrangian.load("pendulum").check({"energy": {"U": "0"}})


def test_small_angle_equation_is_named_a_linearization():
    # worked example 1's own step: correct about theta = 0, not the equation of motion
    report = check_text("pendulum", '[equations]\ntheta = "theta_ddot + g/L*theta = 0"\n')
    eq = finding(report, "equation[theta]")
    assert (eq.status, eq.code) == ("wrong", "equation_linearized")
    assert "small-angle" in eq.message and "theta = 0" in eq.message
    assert "dividing" not in eq.message


def test_each_item_has_its_own_code_where_no_misconception_names_the_slip():
    """The codes of T, V, D, Q and L rows fit the item (a class's CSV reads them)."""
    report = check_text("damped_oscillator", '''
[energy]
V = "k*x^2"
D = "c*x_dot^2"
''')
    assert report.codes("V") == ["potential_term"]
    assert report.codes("D") == ["dissipation_term"]
    Q = check_text("pendulum", '[generalized_forces]\ntheta = "m*g*L"\n')
    assert Q.codes("Q[theta]") == ["generalized_force_wrong"]
    assert check_text("pendulum", '[energy]\nT = "1/2*m*l^2*theta_dot^2"\n').codes("T") == \
        ["unknown_name"]
    assert check_text("pendulum", '[energy]\nL = "m*L^2*theta_dot^2 + m*g*L"\n').codes("L") == \
        ["lagrangian_wrong"]


@pytest.mark.parametrize("coupling", ["- 1/2*k_c*(x2 - x1)^2", "- 1/2*k_c*(x1 - x2)^2"])
def test_a_flipped_coupling_spring_is_a_potential_sign_naming_the_spring(coupling):
    report = check_text("two_mass", f'''
[energy]
V = "1/2*k*x1^2 {coupling} + 1/2*k*x2^2"
''')
    V = finding(report, "V")
    assert V.code == "potential_sign"
    assert "spring k_c coupling x1 and x2" in V.message
    assert "spring store" in V.message and "rises" not in V.message


def test_a_spring_sign_slip_gets_the_springs_question():
    V = finding(check_text("ladder_spring_mass", '[energy]\nV = "-1/2*k*x^2"\n'), "V")
    assert V.code == "potential_sign" and "spring store" in V.message
    assert "rises" not in V.message
