"""The Whipple bicycle built from parts (whipple_bicycle) against the benchmark of Meijaard,
Papadopoulos, Ruina and Schwab, "Linearized dynamics equations for the balance and steer of a
bicycle: a benchmark and review", Proc. R. Soc. A 463 (2007): the lean-steer matrices of their
eq. (5.4) (the same values as sympy's sympy/physics/mechanics/tests/test_kane3.py), the
eigenvalues of their Table 2 (as reproduced in sympy's bicycle example,
doc/src/modules/physics/mechanics/examples/bicycle_example.rst) and the weave and capsize
speeds of their section 6; and the nonlinear model, linearized by finite differences, against
the symbolic linearization."""

import json

import numpy as np
import pytest

import lagrangian
from lagrangian.analysis.speed_form import speed_sweep
from lagrangian.analysis.steady import steady_linear_model
from lagrangian.errors import ModelError

# Meijaard et al. 2007, eq. (5.4)
M = [[80.81722, 2.31941332208709], [2.31941332208709, 0.29784188199686]]
C1 = [[0.0, 33.86641391492494], [-0.85035641456978, 1.68540397397560]]
K0 = [[-80.95, -2.59951685249872], [-2.59951685249872, -0.80329488458618]]
K2 = [[0.0, 76.59734589573222], [0.0, 2.65431523794604]]
# Table 2: eigenvalues at v = 0, 4, 5, 10 m/s
TABLE_2 = {
    0.0: [-5.53094371765393, -3.13164324790656, 3.13164324790656, 5.53094371765393],
    4.0: [-12.15861426576447, -1.42944427361326, 0.41325331521125 - 3.07910818603206j,
          0.41325331521125 + 3.07910818603206j],
    5.0: [-14.07838969279822, -0.32286642900409, -0.77534188219585 - 4.46486771378823j,
          -0.77534188219585 + 4.46486771378823j],
    10.0: [-24.62459635017404, 0.16105338653172, -3.72016840437287 - 10.90681139476287j,
           -3.72016840437287 + 10.90681139476287j],
}
WEAVE, CAPSIZE = 4.29238253634111, 6.02426201538837
RATES = {"x_dot": "v", "thetaR_dot": "-v/rR", "thetaF_dot": "-v/rF"}
UPRIGHT = {"psi": 0, "phi": 0, "delta": 0, "x": 0, "y": 0, "thetaR": 0, "thetaF": 0}


@pytest.fixture(scope="module")
def bicycle():
    return lagrangian.load("whipple_bicycle")


@pytest.fixture(scope="module")
def form(bicycle):
    return bicycle.speed_form(RATES, "v", ["phi", "delta"], about=UPRIGHT)


def _close(got, want, rel=1e-10):
    """Entrywise to ``rel`` of the matrix's largest entry (the zero entries included)."""
    want = np.array(want)
    assert np.abs(np.array(got) - want).max() <= rel * np.abs(want).max(), (got, want)


@pytest.mark.slow
def test_lean_steer_matrices_equal_the_benchmark(form):
    assert form.coordinates == ("phi", "delta")
    assert form.g == 9.81
    _close(form.M, M)
    _close(form.C1, C1)
    _close(form.K0, K0)
    _close(form.K2, K2)
    assert not form.C0.any() and not form.K1.any()
    # each matrix entry to 1e-10 of itself where it is not zero
    for got, want in ((form.M, M), (form.C1, C1), (form.K0, K0), (form.K2, K2)):
        want = np.array(want)
        mask = want != 0
        assert np.abs(got[mask] / want[mask] - 1).max() < 1e-10


@pytest.mark.slow
@pytest.mark.parametrize("speed", sorted(TABLE_2))
def test_eigenvalues_equal_table_2(form, speed):
    got = np.sort_complex(form.eigenvalues(speed))
    assert got == pytest.approx(np.sort_complex(TABLE_2[speed]), abs=1e-10)


@pytest.mark.slow
def test_weave_and_capsize_speeds(form):
    sweep = speed_sweep(form, np.linspace(0, 10, 101))
    assert sweep.speed_of("oscillatory", stabilizing=True) == pytest.approx(WEAVE, abs=1e-6)
    assert sweep.speed_of("real", stabilizing=False) == pytest.approx(CAPSIZE, abs=1e-6)
    ((lo, hi),) = sweep.stable
    assert (lo, hi) == pytest.approx((WEAVE, CAPSIZE), abs=1e-6)


@pytest.mark.slow
def test_the_full_steady_linearization_has_the_benchmark_eigenvalues(bicycle):
    """modes about steady rolling (all eight coordinates, constraints kept by multipliers):
    the lean-steer eigenvalues at 5 m/s plus neutral ones."""
    eom = bicycle.equations_of_motion()
    linear = steady_linear_model(eom, UPRIGHT, {"x_dot": 5.0, "thetaR_dot": -5.0 / 0.3,
                                                "thetaF_dot": -5.0 / 0.35})
    values = np.linalg.eigvals(linear.A)
    moving = np.sort_complex(values[np.abs(values) > 1e-6])
    assert moving == pytest.approx(np.sort_complex(TABLE_2[5.0]), abs=1e-8)


@pytest.mark.slow
def test_nonlinear_model_linearized_numerically_agrees_with_the_symbolic_linearization(bicycle):
    """Central differences of the nonlinear accelerations (the DAE solved for q_ddot) about
    steady rolling at 5 m/s against the symbolic linearization's state matrix."""
    eom = bicycle.equations_of_motion()
    v = 5.0
    linear = steady_linear_model(eom, UPRIGHT, {"x_dot": v, "thetaR_dot": -v / 0.3,
                                                "thetaF_dot": -v / 0.35})
    numeric = bicycle.numeric(backend="numpy")
    n = 8
    names = [c.name for c in bicycle.model.coordinates]
    q0 = np.array([linear.equilibrium[name] for name in names])
    v0 = np.zeros(n)
    v0[names.index("x")], v0[names.index("thetaR")], v0[names.index("thetaF")] = \
        v, -v / 0.3, -v / 0.35
    h = 1e-6
    jacobian = np.zeros((n, 2 * n))
    for j in range(2 * n):
        step = np.zeros(2 * n)
        step[j] = h
        plus = numeric.accelerations_and_multipliers(q0 + step[:n], v0 + step[n:])[0]
        minus = numeric.accelerations_and_multipliers(q0 - step[:n], v0 - step[n:])[0]
        jacobian[:, j] = (np.ravel(plus) - np.ravel(minus)) / (2 * h)
    symbolic = linear.A[n:]
    assert np.abs(jacobian - symbolic).max() < 1e-6 * np.abs(symbolic).max()


@pytest.mark.slow
def test_speeds_json_document_and_plot(form, tmp_path):
    from lagrangian.output.speed_form import speed_form_document, write_speed_plot

    sweep = speed_sweep(form, np.linspace(0, 10, 101))
    document = json.loads(json.dumps(speed_form_document("whipple_bicycle", form, sweep)))
    _close(document["M"], M)
    _close(document["K2"], K2)
    kinds = {c["kind"]: c["speed"] for c in document["crossings"]}
    assert kinds["oscillatory"] == pytest.approx(WEAVE, abs=1e-6)
    assert kinds["real"] == pytest.approx(CAPSIZE, abs=1e-6)
    assert document["stable"] == [pytest.approx([WEAVE, CAPSIZE], abs=1e-6)]
    plot = write_speed_plot(form, sweep, tmp_path / "sweep.png")
    assert plot.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.slow
def test_bad_speed_form_input_is_named(bicycle, cli):
    with pytest.raises(ModelError, match="'roll' is not a coordinate") as info:
        bicycle.speed_form(RATES, "v", ["roll", "delta"])
    assert info.value.field == "keep"
    with pytest.raises(ModelError, match="'speed' is not a parameter"):
        bicycle.speed_form(RATES, "speed", ["phi", "delta"])
    code, _, err = cli("speeds", "whipple_bicycle", "--speed", "v", "--steady",
                       "x_dot=v,thetaR_dot=-v/rR,thetaF_dot=-v/rF", "--keep", "phi,steer")
    assert code == 2 and err == "error: --keep: 'steer' is not a coordinate\n"


def _rolling(v, lean_rate=0.5):
    """Upright straight rolling at v with a lean-rate kick (the wheels' rates roll them)."""
    return {"x_dot": v, "thetaR_dot": -v / 0.3, "thetaF_dot": -v / 0.35, "phi_dot": lean_rate}


@pytest.mark.slow
def test_inside_the_self_stable_range_a_lean_kick_dies_out(bicycle):
    run = bicycle.simulate(10.0, initial=_rolling(5.0), samples=201)
    table = run.to_pandas()
    lean = table["phi"].abs()
    early, late = lean[table["t"] <= 2].max(), lean[table["t"] >= 9].max()
    assert early > 0.03 and late < early / 10  # weave at -0.775 1/s: e^(-0.775 * 7) ~ 0.004
    assert run.max_residual < 1e-8  # the four rolling constraints and the front contact


@pytest.mark.slow
def test_below_the_weave_speed_the_bicycle_falls(bicycle):
    run = bicycle.simulate(10.0, initial=_rolling(2.0), samples=201, stop_when="phi^2 > 0.64")
    table = run.to_pandas()
    assert run.status == "stopped" and table["t"].iloc[-1] < 3.0  # the weave grows at 2.68 1/s at 2 m/s
    assert run.max_residual < 1e-8


@pytest.mark.slow
def test_readme_console_lines_are_real_output(form):
    import re

    import docs_blocks
    from lagrangian.output.speed_form import speed_form_text

    section = docs_blocks.block("bicycle")   # docs/getting-started/engineers.md
    shown = re.findall(r"```console\n\$ lagrangian speeds [^\n]*\n(.*?)```", section, re.S)[0]
    text = speed_form_text(lagrangian.load("whipple_bicycle").model.name, form,
                           speed_sweep(form, np.linspace(0, 10, 101)))
    for line in shown.splitlines():
        if line != "...":
            assert line in text.splitlines(), line
