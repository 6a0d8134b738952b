"""`codegen --lang c` of a model file with a [control] table: <prefix>_control and
<prefix>_control_forces, compiled with -std=c99 -pedantic -Werror, give the law's closed form
and what simulate(controller="model") applied; without a table the C is what it was."""

from __future__ import annotations

import ctypes
import shutil
import subprocess

import numpy as np
import pytest

import lagrangian
from control_models import PENDULUM
from lagrangian.dynamics.standalone.standalone import standalone_c, standalone_tree_c
from lagrangian.model.examples import example_path
from lagrangian.output.files import write_c

COMPILER = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
needs_compiler = pytest.mark.skipif(COMPILER is None, reason="no C compiler")

LAW = '[control]\ntheta = "-Kp*(theta - theta_ref) - Kd*theta_dot"\n'
PUSH = '\n[control]\npush = "-5*x - 3*x_dot + 10*theta + sin(2*t)"\n'


def _load(tmp_path, text: str, name: str):
    path = tmp_path / f"{name}.toml"
    path.write_text(text, encoding="utf-8")
    return lagrangian.load(path)


def _library(tmp_path, system, prefix: str):
    """The standalone C written, compiled as strictly as a controller's build would, loaded."""
    write_c(system.to_c(prefix), tmp_path / "gen")
    library = tmp_path / f"{prefix}.so"
    subprocess.run([COMPILER, "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-pedantic",
                    "-shared", "-fPIC", str(tmp_path / "gen" / f"{prefix}.c"), "-o",
                    str(library), "-lm"], check=True)
    return ctypes.CDLL(str(library))


def _call(function, params, size: int, t: float, q, v) -> np.ndarray:
    out = (ctypes.c_double * size)()
    function(ctypes.c_double(t), (ctypes.c_double * len(q))(*q),
             (ctypes.c_double * len(v))(*v), params, out)
    return np.array(out)


@needs_compiler
def test_a_pd_law_in_c_is_its_closed_form_and_the_simulated_law(tmp_path):
    system = _load(tmp_path, PENDULUM + LAW, "pd")
    c = _library(tmp_path, system, "pd")
    params = (ctypes.c_double * 6).in_dll(c, "pd_parameters")
    rng = np.random.default_rng(3)
    for t, theta, rate in rng.uniform(-3, 3, (6, 3)):
        closed = -4.0 * (theta - 0.2 * np.sin(t)) - 2.0 * rate
        u = _call(c.pd_control, params, 1, t, [theta], [rate])
        tau = _call(c.pd_control_forces, params, 1, t, [theta], [rate])
        assert abs(u[0] - closed) <= 1e-14 * max(1.0, abs(closed))
        assert abs(tau[0] - closed) <= 1e-14 * max(1.0, abs(closed))
    # what simulate(controller="model") applied at its samples, from the C at the same states
    run = system.simulate(2, controller="model", samples=9, rtol=1e-10, atol=1e-10)
    for t, q, v, u in zip(run.t, run.q, run.q_dot, run.controls, strict=True):
        assert np.abs(_call(c.pd_control, params, 1, t, q, v) - u).max() <= 1e-14 * max(
            1.0, np.abs(u).max())


@needs_compiler
def test_a_law_on_a_load_gives_its_generalized_forces(tmp_path):
    # the cart's push force F (a load's parameter): B = df/dF = [1, 0] (horizontal, on the cart)
    text = example_path("cart_pendulum").read_text(encoding="utf-8") + PUSH
    system = _load(tmp_path, text, "cart")
    c = _library(tmp_path, system, "cart")
    params = (ctypes.c_double * 5).in_dll(c, "cart_parameters")
    rng = np.random.default_rng(4)
    for t, x, theta, xd, thd in rng.uniform(-2, 2, (5, 5)):
        law = -5 * x - 3 * xd + 10 * theta + np.sin(2 * t)
        u = _call(c.cart_control, params, 1, t, [x, theta], [xd, thd])
        tau = _call(c.cart_control_forces, params, 2, t, [x, theta], [xd, thd])
        assert abs(u[0] - law) <= 1e-14 * max(1.0, abs(law))
        np.testing.assert_allclose(tau, [law, 0.0], rtol=0, atol=1e-14 * max(1.0, abs(law)))
    run = system.simulate(1, controller="model", samples=5, rtol=1e-10, atol=1e-10)
    for t, q, v, u in zip(run.t, run.q, run.q_dot, run.controls, strict=True):
        assert np.abs(_call(c.cart_control, params, 1, t, q, v) - u).max() <= 1e-13


def test_without_a_control_table_the_c_is_unchanged(tmp_path):
    plain = _load(tmp_path, PENDULUM, "plain")
    values = dict(plain.parameters)
    assert plain.to_c("pd") == standalone_c(plain.equations_of_motion(), values, "pd")
    arm = lagrangian.load("two_link_arm")  # a URDF robot: its recursive C
    model = arm.model
    assert arm.to_c("arm") == standalone_tree_c(model, model.kinematic_tree, dict(arm.parameters),
                                                "arm")
    with_law = _load(tmp_path, PENDULUM + LAW, "pd").to_c("pd")
    code = plain.to_c("pd")
    assert "_control" not in code.header + code.source
    assert with_law.source.startswith(code.source.rstrip("\n"))


def test_a_law_on_an_inertia_is_one_line(tmp_path, cli):
    path = tmp_path / "bad.toml"
    path.write_text(PENDULUM + '[control]\nm = "1"\n', encoding="utf-8")
    code, out, err = cli("codegen", str(path), "--out", str(tmp_path / "gen"))
    assert code == 2 and "enters the mass matrix" in err and "control" in err
    assert err.startswith("error: ") and err.strip().count("\n") == 0
    assert not (tmp_path / "gen").exists()


def test_the_command_writes_the_control_functions(tmp_path, cli):
    path = tmp_path / "pd.toml"
    path.write_text(PENDULUM + LAW, encoding="utf-8")
    code, out, err = cli("codegen", str(path), "--out", str(tmp_path / "gen"), "--name", "pd")
    assert code == 0, err
    header = (tmp_path / "gen" / "pd.h").read_text(encoding="utf-8")
    assert "#define PD_NU 1" in header and "void pd_control(double t," in header
    assert "void pd_control_forces(double t," in header


@needs_compiler
def test_a_model_files_tree_takes_laws_on_its_coordinates_and_refuses_one_on_a_parameter(
        tmp_path):
    from lagrangian.dynamics.recursive import TREE_PATH_BODIES
    from lagrangian.errors import InputError
    from lagrangian.model.builder import ModelBuilder

    def chain(law_input: str) -> lagrangian.System:  # the chain codegen writes as a tree
        b = ModelBuilder("chain")
        b.parameter("g", 9.81)
        b.set_gravity("g", (0, 0, -1))
        for i in range(TREE_PATH_BODIES):
            b.coordinate(f"q{i}", "rad")
            joint = {"type": "revolute", "axis": "xy"[i % 2], "angle": f"q{i}",
                     **({"at": [0, 0, -1]} if i else {})}
            b.add_rigid_body(f"link{i}", 1.0, [0.1, 0.1, 0.02], center=[0, 0, -0.5],
                             parent=f"link{i - 1}" if i else None, joint=joint)
        b.add_control_law(law_input, "-3*q1 - q1_dot + cos(t)")
        return lagrangian.System(b.build_model())

    c = _library(tmp_path, chain("q1"), "chain")
    params = (ctypes.c_double * 1).in_dll(c, "chain_parameters")
    n = TREE_PATH_BODIES
    rng = np.random.default_rng(6)
    for _ in range(4):
        t, q, v = rng.uniform(-2, 2), rng.uniform(-2, 2, n), rng.uniform(-2, 2, n)
        law = -3 * q[1] - v[1] + np.cos(t)
        tau = _call(c.chain_control_forces, params, n, t, q, v)
        np.testing.assert_allclose(tau, np.eye(n)[1] * law, rtol=0, atol=1e-14 * max(1, abs(law)))
    with pytest.raises(InputError, match="on a parameter or a load need the derived") as caught:
        chain("g").to_c()
    assert "\n" not in str(caught.value)
