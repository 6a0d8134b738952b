"""Hostile numbers (issue 14): bounded by value, not by syntax; refused with the field named.

Every case once hung, crashed with a traceback or was silently turned into nonsense.
"""

import pytest
import sympy as sp

from lagrangian.errors import ModelError
from lagrangian.model.answer import parse_answer
from lagrangian.model.expressions import format_expression, parse_expression
from lagrangian.model.reader import parse_model
from lagrangian.model.units import check_unit, parse_quantity

theta, m = sp.symbols("theta m")
NAMES = {"theta": theta, "m": m, "theta_dot": sp.Symbol("theta_dot")}


def refusal(text) -> str:
    with pytest.raises(ModelError) as info:
        parse_expression(text, NAMES, field="energy.V", source="m.toml")
    return str(info.value).removeprefix("m.toml: energy.V: ")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        # exact rationals whose digits grow without bound (hung for minutes)
        ("(1.0000001^1000)^1000", "the exact value of '(1.0000001^1000)' has about 7000 digits "
         "(at most 1000): write it as a decimal number (about 1.0001)"),
        # over Python's 4300-digit printing limit (was a ValueError traceback)
        ("1.0000001^1000", "the exact value of '1.0000001^1000' has about 7000 digits "
         "(at most 1000): write it as a decimal number (about 1.0001)"),
        # irrational power towers (hung: sympy factors 10**9-th powers)
        ("16.369805884^16.369805884^16.369805884^16.369805884",
         "the exact value of '16.369805884^16.369805884' is too costly to compute (a rational "
         "power with a 9-digit denominator): write it as a decimal number (about 7.47579e+19)"),
        # names are checked before any arithmetic (took 9 s)
        ("(1.0000001^1000)^1000*nope", "unknown name 'nope'"),
        # NaN inside the reader (was a TypeError traceback)
        ("theta^(0*log(0))", "'log(0)' is infinite"),
        # OverflowError in the reader and in derive
        ("exp(exp(exp(exp(10))))",
         "the value of 'exp(exp(10))' is too large a number (beyond 1e300)"),
        # infinities were accepted as sympy's zoo (KeyError in the C printer)
        ("log(0)*theta", "'log(0)' is infinite"),
        ("tan(pi/2)*theta", "'tan(pi/2)' is infinite"),
        ("log(theta - theta)", "'log(theta - theta)' is infinite"),
        ("atan2(0, 0)*theta", "'atan2(0, 0)' is undefined (0/0, infinity - infinity, "
         "0*infinity or similar)"),
        ("pi/0", "division by zero in 'pi/0'"),
        ("0^-1", "division by zero in '0^-1'"),
        ("1e308*pi*theta", "the number 1e308 is too large (every number must be below 1e300 "
                           "in size)"),
        ("1e200*theta*1e200", "a number in '1e200*theta*1e200' is too large (beyond 1e300)"),
        ("10^299*100", "the product '10^299*100' is too large a number (beyond 1e300)"),
        # silently 0 before
        ("1e-400*theta", "the number 1e-400 is too small (below 1e-300, it would be read as 0): "
         "write 0 or a larger number"),
        # non-real where a real is needed (m*theta_ddot = -I was derived)
        ("sqrt(-1)*theta", "'sqrt(-1)' is not a real number"),
        ("log(-1)", "'log(-1)' is not a real number"),
        ("asin(2)*theta", "'asin(2)' is not a real number"),
        ("(-8)^(1/3)*theta", "'(-8)^(1/3)' is not a real number"),
        ("sinh(1000)", "the value of 'sinh(1000)' is too large a number (beyond 1e300)"),
        ("1" + "0" * 400, "the number has more than 300 digits"),
    ],
)
def test_hostile_numbers_are_refused_with_the_field(text, message):
    assert refusal(text) == message


@pytest.mark.parametrize(
    ("text", "value"),
    [
        ("1.05^500", sp.Rational(21, 20) ** 500),  # 1010 digits in all, each part below 1000
        ("0.95^200", sp.Rational(19, 20) ** 200),
        ("9.81^0.5", sp.sqrt(sp.Rational(981, 100))),
        ("exp(690)", sp.exp(690)),  # 1e299.7: just inside
        ("-2^2", -4),
        ("2^-1", sp.Rational(1, 2)),
        ("(-8)^(2/2)", -8),
        ("sqrt(sin(pi))", 0),  # the float twin says sqrt(1.2e-16), the exact value is 0
        ("1e-300", sp.Rational(1, 10**300)),
        ("0.0000", 0),
    ],
)
def test_numbers_inside_the_bounds_stay_exact(text, value):
    assert parse_expression(text, NAMES) == value


def test_flat_sums_and_products_of_any_length_parse():
    # 500 coordinates and a T of 500 terms: the nesting limit counts depth, not length
    names = {f"x{i}_dot": sp.Symbol(f"x{i}_dot") for i in range(500)} | {"m": m}
    T = " + ".join(f"1/2*m*x{i}_dot^2" for i in range(500))
    assert parse_expression(T, names) == sp.Add(*(m * names[f"x{i}_dot"] ** 2 / 2 for i in range(500)))
    product = "*".join(f"x{i}_dot" for i in range(500))
    assert parse_expression(product, names) == sp.Mul(*(names[f"x{i}_dot"] for i in range(500)))
    assert parse_expression("m - " * 3000 + "m", NAMES) == -2999 * m


def test_multi_line_expressions_read_as_one():
    assert parse_expression("1/2*m*theta_dot^2\n  + m*theta", NAMES) == \
        m * sp.Symbol("theta_dot") ** 2 / 2 + m * theta


def test_long_inputs_are_quoted_as_a_window_around_the_fault():
    text = "m + " * 3000 + ") + theta"
    message = refusal(text)
    assert message == ("cannot parse '...+ m + m + m + m + m + m + m + >>>) + theta' "
                       "at column 12001: unexpected ')'")
    text = "m*" * 4000 + "m % 2 + " + "m*" * 4000 + "m"  # no parse error: a forbidden operator
    assert refusal(text) == ("the operator '%' is not allowed (in "
                             "'...m*m*m*m*m*m*m*m*m*m*m*m*m*m*m >>>% 2 + m*m*m*m*m*m*m*m*m*m*m*m*...')")


def test_no_python_warning_leaks(recwarn):
    for text in ("'\\d'", "1if 1 else 2", "2(3)", "0x1for"):
        with pytest.raises(ModelError):
            parse_expression(text, NAMES)
    assert not [w for w in recwarn.list if issubclass(w.category, SyntaxWarning | DeprecationWarning)]


# -- unit strings: checked before the unit library evaluates them --------------------------

@pytest.mark.parametrize(
    ("unit", "message"),
    [
        ("kg*9^9^9", "f: unit 'kg*9^9^9': powers of powers are not allowed in a unit"),
        ("(-pi)^(1e300)", "f: unit '(-pi)^(1e300)': the power is too large (at most 100)"),
        ("m^(theta)", "f: unit 'm^(theta)': a power in a unit must be a plain number "
                      "(like m^2 or s^-1)"),
        # '··' is '**' once '·' means '*': a tower pint spent minutes on (fuzzing find)
        ("9^9··9^9", "f: unit '9^9··9^9': powers of powers are not allowed in a unit"),
        ("((9^100)^100)^100", "f: unit '((9^100)^100)^100': powers of powers are not allowed "
                              "in a unit"),
    ],
)
def test_unit_strings_with_hostile_powers_are_refused(unit, message):
    with pytest.raises(ModelError) as info:
        check_unit(unit, "f", None)
    assert str(info.value) == message


@pytest.mark.parametrize("unit", ["m^-2", "s^(-1)", "m**0.5", "m^(1/2)", "kg*m^2/s^2", "kg m",
                                  "kg·m^2", "(m/s)^2"])
def test_ordinary_unit_strings_pass(unit):
    assert check_unit(unit, "f", None) == unit


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("1 rad*9^9^9", "--at theta: unit 'rad*9^9^9': powers of powers are not allowed in a unit"),
        ("1e308pi", "--at theta: '1e308pi' is not a finite number in SI units"),
        ("1e-400", "--at theta: '1e-400' is too small for a floating-point number (it would be "
                   "read as 0)"),
    ],
)
def test_values_with_units_are_bounded_after_conversion(text, message):
    with pytest.raises(ModelError) as info:
        parse_quantity(text, "rad", "--at theta")
    assert str(info.value) == message


@pytest.mark.parametrize(
    ("text", "value"),
    [("pi/2", 1.5707963267948966), ("-pi/4 rad", -0.7853981633974483), ("pi", 3.141592653589793),
     ("3*pi/4 deg", 0.041123351671205656), ("30deg", 0.5235987755982988)],
)
def test_values_may_be_constant_expressions_of_pi(text, value):
    assert parse_quantity(text, "rad", "--about theta") == value


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("pi/0", "--about theta: division by zero in 'pi/0'"),  # a ZeroDivisionError traceback
        ("sqrt(-1)", "--about theta: 'sqrt(-1)' is not a real number"),
        ("exp(exp(10))", "--about theta: the value of 'exp(exp(10))' is too large a number "
                         "(beyond 1e300)"),
        ("abc", "--about theta: expected a number with an optional unit (like 30deg), got 'abc'"),
    ],
)
def test_constant_expressions_in_values_are_bounded(text, message):
    with pytest.raises(ModelError) as info:
        parse_quantity(text, "rad", "--about theta")
    assert str(info.value) == message


# -- whole files ---------------------------------------------------------------------------

MODEL = """
[coordinates]
theta = { unit = "rad" }
[parameters]
m = 1.0
[energy]
T = "1/2*m*theta_dot^2"
V = "m*theta"
"""


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (("m = 1.0", "m = 1e-400"), "bad.toml: line 5 (m): the number 1e-400 is too small "
         "(below 1e-300, it would be read as 0): write 0 or a larger number"),
        (("m = 1.0", "m = 1" + "0" * 5000), "bad.toml: invalid TOML: a number has far too many "
         "digits"),
        (("m = 1.0", "m = 1" + "0" * 400), "bad.toml: parameters.m: the number is too large for a "
         "floating-point number"),  # an OverflowError traceback (fuzzing find)
        (("m = 1.0", 'm = { value = 1' + "0" * 400 + ', unit = "kg" }'), "bad.toml: "
         "parameters.m.value: the number is too large for a floating-point number"),
        (('theta = { unit = "rad" }', 'theta = { unit = "rad", initial = 1' + "0" * 400 + " }"),
         "bad.toml: coordinates.theta.initial: the number is too large for a floating-point number"),
        (('unit = "rad"', 'unit = "\\n"'), "bad.toml: coordinates.theta.unit: unknown unit "
         "'\\n'"),  # was a message of two lines (fuzzing find)
        (('unit = "rad"', 'unit = "(-pi)^(1e300)"'), "bad.toml: coordinates.theta.unit: unit "
         "'(-pi)^(1e300)': the power is too large (at most 100)"),
        (("m = 1.0", 'm = { value = 1e308, unit = "pi" }'), "bad.toml: parameters.m.value: "
         "'1e+308 pi' is not a finite number in SI units"),
        (('V = "m*theta"', 'V = "1.0000001^1000*theta"'), "bad.toml: energy.V: the exact value "
         "of '1.0000001^1000' has about 7000 digits (at most 1000): write it as a decimal number "
         "(about 1.0001)"),
    ],
)
def test_model_files_with_hostile_numbers(change, message):
    with pytest.raises(ModelError) as info:
        parse_model(MODEL.replace(*change), source="bad.toml")
    assert str(info.value) == message


def test_answer_files_are_bounded_like_models():
    model = parse_model(MODEL)
    with pytest.raises(ModelError) as info:
        parse_answer('[energy]\nV = "1.0000001^1000*theta"', model, source="ANSWER.toml")
    assert str(info.value) == ("ANSWER.toml: energy.V: the exact value of '1.0000001^1000' has "
                               "about 7000 digits (at most 1000): write it as a decimal number "
                               "(about 1.0001)")
    with pytest.raises(ModelError) as info:
        parse_answer("[energy]\nV = 1e-400", model, source="ANSWER.toml")
    assert str(info.value).startswith("ANSWER.toml: line 2 (V): the number 1e-400 is too small")
    # a foreign name in a long flat sum is still found (it once needed Python's parser)
    answer = parse_answer('[energy]\nV = "' + "m*theta + " * 2000 + 'N*theta"', model)
    assert answer.foreign_symbols("V") == {sp.Symbol("N")}


def test_nesting_is_limited_to_what_sympy_can_still_print():
    # sympy's printer spends about five frames per level: depth 199 was accepted, then
    # `str` of it died with RecursionError (fuzzing find)
    deep = "sin(" * 99 + "theta" + ")" * 99
    expr = parse_expression(deep, NAMES)
    assert parse_expression(format_expression(expr), NAMES) == expr
    assert refusal("sin(" * 100 + "theta" + ")" * 100) == "the expression is nested too deeply"
    assert refusal("-" * 5000 + "theta") == "the expression is nested too deeply"
    assert refusal("2^" * 5000 + "2") == "the expression is nested too deeply"


def test_a_model_of_500_coordinates_reads():
    # a chain of 500 masses and springs: T and V are flat sums of 500 terms (refused as
    # "nested too deeply" beyond 200 terms before)
    n = 500
    text = ("[coordinates]\n" + "".join(f'x{i} = "m"\n' for i in range(n))
            + "[parameters]\nm = 1.0\nk = 2.0\n[energy]\n"
            + 'T = "' + " + ".join(f"1/2*m*x{i}_dot^2" for i in range(n)) + '"\n'
            + 'V = "' + " + ".join(f"1/2*k*(x{i} - x{i + 1})^2" for i in range(n - 1)) + '"\n')
    model = parse_model(text)
    assert len(model.coordinates) == n
    x = [c.symbol for c in model.coordinates]
    k = sp.Symbol("k")
    assert model.potential_energy == sp.Add(*(k * (x[i] - x[i + 1]) ** 2 / 2 for i in range(n - 1)))
