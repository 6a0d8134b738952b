"""The model grammar: a whitelist parser (never eval) and a printer that it reads back."""

import pytest
import sympy as sp

from lagrangian.errors import ModelError
from lagrangian.model.expressions import format_expression, parse_expression

theta, m, L = sp.symbols("theta m L")
NAMES = {"theta": theta, "m": m, "L": L, "theta_dot": sp.Symbol("theta_dot")}


def parse(text):
    return parse_expression(text, NAMES, field="energy.T", source="model.toml")


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("1/2*m*L^2*theta_dot^2", m * L**2 * sp.Symbol("theta_dot") ** 2 / 2),
        ("-m*9.81*L*cos(theta)", -sp.Rational(981, 100) * m * L * sp.cos(theta)),
        ("L**2 + sqrt(L) - abs(theta)", L**2 + sp.sqrt(L) - sp.Abs(theta)),
        ("atan2(theta, L) + exp(1) + pi", sp.atan2(theta, L) + sp.E + sp.pi),
        ("2^3^2", sp.Integer(512)),  # right-associative like Python's **
        ("-theta^2", -(theta**2)),
    ],
)
def test_parses_the_grammar(text, expected):
    assert parse(text) == expected


def test_numbers_become_exact():
    assert parse(0.5) == sp.Rational(1, 2)
    assert parse(3) == 3
    assert parse("0.1") == sp.Rational(1, 10)


@pytest.mark.parametrize(
    "expr",
    [m * L**2 * sp.sin(theta) ** 2 / 2, sp.sqrt(L) + sp.E * sp.Abs(theta), sp.atan2(theta, L) / 3,
     1 / sp.sqrt(m + L), sp.Float(0.25) * theta],
)
def test_printer_round_trips(expr):
    assert parse(format_expression(expr)) == sp.nsimplify(expr)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("__import__('os')", "model.toml: energy.T: unknown function '__import__'"),
        ("__import__('os').system('x')", "model.toml: energy.T: only the functions sin, cos, tan, "
         "asin, acos, atan, atan2, sinh, cosh, tanh, exp, log, sqrt, abs, sign can be called"),
        ("theta.real", "model.toml: energy.T: attribute access ('.') is not allowed (in 'theta.real')"),
        ("m[0]", "model.toml: energy.T: indexing ('[...]') is not allowed (in 'm[0]')"),
        ("thetta*m", "model.toml: energy.T: unknown name 'thetta'; did you mean 'theta'?"),
        ("9**9**9", "model.toml: energy.T: the exponent 387420489 is too large (at most 1000)"),
        ("10**400", "model.toml: energy.T: the power '10**400' is too large a number (beyond 1e300)"),
        ("sin(theta, L)", "model.toml: energy.T: sin() takes 1 argument(s), got 2"),
        ("cosh", "model.toml: energy.T: 'cosh' is a function: call it as cosh(...)"),
        ("lambda: 1", "model.toml: energy.T: lambda is not allowed (in 'lambda: 1')"),
        ("m if L else theta", "model.toml: energy.T: 'if ... else' is not allowed (in 'm if L else theta')"),
        ("m < L", "model.toml: energy.T: comparisons are not allowed (in 'm < L')"),
        ("'text'", "model.toml: energy.T: only numbers are allowed as constants, got 'text'"),
        ("m % 2", "model.toml: energy.T: the operator '%' is not allowed (in 'm % 2')"),
        ("m/0", "model.toml: energy.T: division by zero in 'm/0'"),
        ("m +", "model.toml: energy.T: cannot parse 'm +' at column 4: the expression ends too early"),
        ("", "model.toml: energy.T: the expression is empty"),
        ("open('f')", "model.toml: energy.T: unknown function 'open'"),
    ],
)
def test_rejects_everything_outside_the_grammar(text, message):
    with pytest.raises(ModelError) as info:
        parse(text)
    assert str(info.value) == message


def test_rejects_non_expressions():
    with pytest.raises(ModelError, match="got a boolean"):
        parse(True)
    with pytest.raises(ModelError, match="got list"):
        parse([1, 2])
    with pytest.raises(ModelError, match="not finite"):
        parse(float("inf"))


def test_deep_nesting_is_refused_not_crashing():
    with pytest.raises(ModelError):
        parse("(" * 300 + "m" + ")" * 300)
    with pytest.raises(ModelError, match="longer than"):
        parse("m+" * 60000 + "m")


@pytest.mark.parametrize(
    ("text", "fault"),
    [("0od", "'d' is not an octal digit"), ("2*0o8 + m", "'8' is not an octal digit"),
     ("0b2", "'2' is not a binary digit"), ("0B1e", "'e' is not a binary digit"),
     ("0x_", "needs digits after '0x'"), ("0x1_", "single underscores"),
     ("0b1__0", "single underscores")],
)
def test_a_malformed_based_number_is_the_models_error_naming_the_field(text, fault):
    """Python's int(text, 0) refuses these with a bare ValueError: ours names field and digit."""
    with pytest.raises(ModelError) as info:
        parse(text)
    assert info.value.field == "energy.T" and fault in str(info.value)


def test_based_numbers_keep_their_value():
    assert parse("0o17 + 0x_ff + 0b1_01") == 15 + 255 + 5


def test_the_cli_refuses_a_malformed_number_in_one_line(cli, tmp_path):
    model = tmp_path / "bad.toml"
    model.write_text('[coordinates]\nx = "m"\n[parameters]\nm = 1\n[energy]\n'
                     'T = "m*x_dot^2/2"\nV = "0od*x^2"\n', encoding="utf-8")
    code, out, err = cli("derive", str(model))
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and "energy.V" in err and "octal digit" in err, err
