"""The recursive algorithms in numpy (dynamics/recursive_numpy.py), the fallback of the
generated C for URDF trees: equal to the derived equations (Lagrange's method, lambdified) on
the test URDFs, the two-link arm's textbook M, T = 1/2 v.M v, d(T + V)/dt = v.tau, forward
undoes inverse; a 30-link chain without RecursionError; the dispatch without a compiler."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

import lagrangian
from lagrangian.compile import compiled
from lagrangian.compile.compiled import BackendUnavailable
from lagrangian.compile.functions import numeric
from lagrangian.dynamics.joint_space import Dynamics
from lagrangian.errors import DerivationError, ModelError

pytest.importorskip("yourdfpy")
needs_c = pytest.mark.skipif(not compiled.available(), reason="no C compiler / Python headers")
HERE = Path(__file__).resolve().parent


def _cases(path: Path):
    """The URDF strings of another test module (loaded by path: no package needed)."""
    spec = importlib.util.spec_from_file_location(f"_urdf_cases_{path.stem}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


RECURSIVE = _cases(HERE / "test_recursive_dynamics.py")
URDF = _cases(HERE.parent / "model" / "test_urdf.py")
FUNCTIONS = [("mass_matrix", "q"), ("bias_forces", "qv"), ("gravity", "q"),
             ("inverse_dynamics", "qva"), ("forward_dynamics", "qvt"),
             ("kinetic_energy", "qv"), ("potential_energy", "q")]


@pytest.fixture
def no_compiler(monkeypatch, tmp_path):
    """CC names no program, an empty module cache, none loaded: as on a machine without C."""
    monkeypatch.setenv("CC", "/nonexistent/cc")
    monkeypatch.setenv("LAGRANGIAN_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(compiled, "_LOADED", {})


def arm(tmp_path, text, lock=None, name="arm.urdf"):
    path = tmp_path / name
    path.write_text(text)
    return lagrangian.load(path, lock=lock)


def states(n, count=6, seed=5):
    rng = np.random.default_rng(seed)
    q, v, a, t = (rng.uniform(-1.5, 1.5, (count, n)) for _ in range(4))
    return {"q": q, "v": v, "a": a, "t": t}


def assert_same(ours, theirs, n, rtol=1e-12, seed=5):
    x = states(n, seed=seed)
    for name, inputs in FUNCTIONS:
        mine = getattr(ours, name)(*(x[k] for k in inputs))
        other = getattr(theirs, name)(*(x[k] for k in inputs))
        scale = np.abs(other).max()
        np.testing.assert_allclose(mine, other, rtol=rtol, atol=rtol * scale, err_msg=name)


@pytest.mark.slow
@pytest.mark.parametrize(("case", "lock"), [
    ("tree", {"grip": 0.01}),  # a mimic joint: M and b of both joints on one coordinate
    ("tree", {"grip": 0.01, "wrist": -0.3}),
    ("spatial", None),
    ("two_link", None),
    ("two_link", {"elbow": 0.7}),
])
def test_numpy_recursions_equal_the_derived_equations(tmp_path, case, lock):
    text = {"tree": RECURSIVE.TREE, "spatial": URDF.SPATIAL, "two_link": URDF.TWO_LINK}[case]
    system = arm(tmp_path, text, lock)
    ours = system.dynamics(backend="numpy")
    assert ours.kernel == "numpy"
    # Lagrange's method on the model's rigid bodies, lambdified: no code shared with the tree
    theirs = Dynamics(numeric(system.equations_of_motion(), backend="numpy"))
    assert ours.coordinates == theirs.coordinates
    assert_same(ours, theirs, ours.n)


def test_two_link_textbook_mass_matrix(tmp_path):
    """Spong's planar arm: M11 = I1 + I2 + m1 c1^2 + m2 (l1^2 + c2^2 + 2 l1 c2 cos q2),
    M12 = I2 + m2 (c2^2 + l1 c2 cos q2), M22 = I2 + m2 c2^2 (kg m^2)."""
    f = arm(tmp_path, URDF.TWO_LINK).dynamics(backend="numpy")
    m1, m2, l1, c1, c2, i1, i2 = (URDF.M1, URDF.M2, URDF.L1, URDF.C1, URDF.C2, URDF.I1,
                                  URDF.I2)
    q2 = np.linspace(-3, 3, 7)
    mass = f.mass_matrix(np.column_stack([np.full_like(q2, 0.3), q2]))
    np.testing.assert_allclose(mass[:, 0, 0], i1 + i2 + m1 * c1**2
                               + m2 * (l1**2 + c2**2 + 2 * l1 * c2 * np.cos(q2)), rtol=1e-13)
    np.testing.assert_allclose(mass[:, 0, 1], i2 + m2 * (c2**2 + l1 * c2 * np.cos(q2)),
                               rtol=1e-13)
    np.testing.assert_allclose(mass[:, 1, 0], mass[:, 0, 1], rtol=0, atol=0)
    np.testing.assert_allclose(mass[:, 1, 1], i2 + m2 * c2**2, rtol=1e-13)
    # at rest, the holding torques of a horizontal arm: the weights times their lever arms
    g = f.gravity([0.0, 0.0])
    np.testing.assert_allclose(g, [9.81 * (m1 * c1 + m2 * (l1 + c2)), 9.81 * m2 * c2],
                               rtol=1e-13)


def test_a_state_beyond_1e154_overflows_without_numpys_warning(tmp_path):
    """Spong's arm on the numpy recursions at rates of 1e300 rad/s: the bias forces overflow
    to inf as the compiled engine's do, forward dynamics' row is NaN with the one
    DynamicsWarning, M (which no rate enters) stays finite; no RuntimeWarning."""
    import warnings

    f = arm(tmp_path, URDF.TWO_LINK).dynamics(backend="numpy")
    q, v = np.array([0.3, 0.5]), np.array([1e300, -1e300])
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        assert not np.isfinite(f.bias_forces(q, v)).all()
        with pytest.warns(lagrangian.DynamicsWarning, match="1 of 1 states"):
            assert np.isnan(f.forward_dynamics(q, v, np.zeros(2))).all()
        assert np.isfinite(f.mass_matrix(q)).all()


@pytest.mark.parametrize("lock", [{"grip": 0.01}, {"grip": 0.01, "wrist": -0.3}])
def test_laws_of_the_numpy_recursions(tmp_path, lock):
    f = arm(tmp_path, RECURSIVE.TREE, lock).dynamics(backend="numpy")
    n = f.n
    x = states(n, count=4, seed=11)
    q, v, a = x["q"], x["v"], x["a"]
    mass = f.mass_matrix(q)
    np.testing.assert_allclose(mass, np.swapaxes(mass, -1, -2), rtol=0, atol=1e-15)
    assert np.all(np.linalg.eigvalsh(mass) > 0)
    # T = 1/2 v.M v: the velocity recursion against the composite-rigid-body M
    np.testing.assert_allclose(f.kinetic_energy(q, v), 0.5 * np.einsum("ki,kij,kj->k", v, mass, v),
                               rtol=1e-12)
    # g(q) = dV/dq (central differences, error ~ h^2)
    h = 1e-6
    for i in range(n):
        step = np.eye(n)[i] * h
        slope = (f.potential_energy(q + step) - f.potential_energy(q - step)) / (2 * h)
        np.testing.assert_allclose(f.gravity(q)[:, i], slope, rtol=1e-6, atol=1e-7)
    # the work-energy theorem: d(T + V)/dt = v.tau along q' = v, v' = a, tau = M a + C v + g
    tau = f.inverse_dynamics(q, v, a)
    h = 1e-5

    def energy(s):
        return f.kinetic_energy(q + s * v, v + s * a) + f.potential_energy(q + s * v)

    np.testing.assert_allclose((energy(h) - energy(-h)) / (2 * h), np.einsum("ki,ki->k", v, tau),
                               rtol=1e-6, atol=1e-7)
    # forward dynamics (Cholesky of the CRBA M) undoes inverse dynamics (Newton-Euler)
    np.testing.assert_allclose(f.forward_dynamics(q, v, tau), a, rtol=1e-9, atol=1e-10)
    # tau = M a + b: Newton-Euler with a against CRBA's M and Newton-Euler without
    np.testing.assert_allclose(tau, np.einsum("kij,kj->ki", mass, a) + f.bias_forces(q, v),
                               rtol=1e-12, atol=1e-12 * np.abs(tau).max())
    # one state, a batch, (n,) broadcast against a batch, leading axes kept
    one = [f.inverse_dynamics(q[k], v[k], a[k]) for k in range(len(q))]
    np.testing.assert_allclose(tau, one, rtol=1e-14, atol=0)
    np.testing.assert_allclose(f.bias_forces(q[0], v),
                               f.bias_forces(np.broadcast_to(q[0], v.shape), v), rtol=1e-15)
    assert f.mass_matrix(q.reshape(2, 2, n)).shape == (2, 2, n, n)
    assert f.kinetic_energy(q[0], v[0]).shape == ()
    with pytest.raises(ModelError, match=f"expected {n} values"):
        f.mass_matrix([0.1, 0.2])
    with pytest.raises(ModelError, match=f"expected {n} values") as info:
        f.inverse_dynamics(q, v, [1.0])
    assert info.value.field == "a"


@needs_c
@pytest.mark.parametrize("lock", [{"grip": 0.01}, {"grip": 0.01, "wrist": -0.3}])
def test_numpy_recursions_equal_the_generated_c(tmp_path, lock):
    system = arm(tmp_path, RECURSIVE.TREE, lock)
    fast = system.dynamics()
    assert fast.backend == "recursive"
    assert_same(system.dynamics(backend="numpy"), fast, fast.n, seed=8)


def chain(links: int) -> str:
    """A spatial chain: joint axes alternating z, y, x, link offsets and tilted origins."""
    parts = [RECURSIVE.link("l0")]
    axes = ["0 0 1", "0 1 0", "1 0 0"]
    for i in range(1, links + 1):
        parts.append(RECURSIVE.link(f"l{i}", 1.0 + 0.01 * i, "0.1 0.01 0.02", "0.1 0 0"))
        parts.append(RECURSIVE.joint(f"j{i}", f"l{i - 1}", f"l{i}", xyz="0.2 0 0.01",
                                     rpy="0 0.1 0", axis=axes[i % 3]))
    return '<?xml version="1.0"?><robot name="chain">' + "".join(parts) + "</robot>"


@pytest.fixture(scope="module")
def deep(tmp_path_factory):
    path = tmp_path_factory.mktemp("chain") / "chain30.urdf"
    path.write_text(chain(30))
    return lagrangian.load(path)


def test_deep_chain_without_recursion_error(deep):
    f = deep.dynamics(backend="numpy")
    assert f.kernel == "numpy" and f.n == 30
    x = states(30, count=3, seed=2)
    mass = f.mass_matrix(x["q"])
    np.testing.assert_allclose(mass, np.swapaxes(mass, -1, -2), rtol=0,
                               atol=1e-14 * np.abs(mass).max())
    assert np.all(np.linalg.eigvalsh(mass) > 0)
    np.testing.assert_allclose(f.kinetic_energy(x["q"], x["v"]),
                               0.5 * np.einsum("ki,kij,kj->k", x["v"], mass, x["v"]), rtol=1e-12)
    tau = f.inverse_dynamics(x["q"], x["v"], x["a"])
    np.testing.assert_allclose(f.forward_dynamics(x["q"], x["v"], tau), x["a"], rtol=1e-8,
                               atol=1e-9)


@needs_c
@pytest.mark.slow
def test_chain_equals_the_generated_c(tmp_path):
    # 10 links: the C build of the 30-link chain alone takes ~30 s on a loaded 2-core machine
    # (it agrees to 1e-11 too: checked when this test was written)
    system = arm(tmp_path, chain(10))
    fast = system.dynamics()
    assert fast.backend == "recursive"
    assert_same(system.dynamics(backend="numpy"), fast, 10, rtol=1e-11, seed=9)


def test_without_a_compiler_the_urdf_tree_runs_in_numpy(tmp_path, no_compiler):
    assert not compiled.available()
    system = arm(tmp_path, URDF.TWO_LINK)
    f = system.dynamics()
    assert f.kernel == "numpy"
    numeric_system = system.numeric()
    assert numeric_system.backend == "numpy"
    q, v = np.array([0.3, -0.5]), np.array([0.2, 1.0])
    accelerations, multipliers = numeric_system.accelerations_and_multipliers(q, v)
    assert multipliers.shape == (0,)
    np.testing.assert_allclose(accelerations, f.forward_dynamics(q, v, np.zeros(2)), rtol=1e-14)
    np.testing.assert_allclose(numeric_system.forcing(q, v), -f.bias_forces(q, v), rtol=1e-14)
    np.testing.assert_allclose(numeric_system.energy(q, v),
                               f.kinetic_energy(q, v) + f.potential_energy(q), rtol=1e-14)
    with pytest.raises(BackendUnavailable):
        system.dynamics(backend="c")
    # zero torque: T + V is kept along a simulated motion on the numpy recursions
    run = system.simulate(1.0, initial={"shoulder": 0.3, "elbow": -0.5, "elbow_dot": 1.0})
    frame = run.to_pandas()
    qs = frame[["shoulder", "elbow"]].to_numpy()
    vs = frame[["shoulder_dot", "elbow_dot"]].to_numpy()
    energy = f.kinetic_energy(qs, vs) + f.potential_energy(qs)
    assert np.ptp(energy) < 1e-7 * np.abs(energy).max()
    assert np.ptp(f.kinetic_energy(qs, vs)) > 0.1  # it did move


def test_massless_branch_is_refused_naming_the_lock(tmp_path, no_compiler):
    """A joint that carries no mass makes M singular at every state: refused at once by the
    recursions (no derivation to wait for), naming the joint and the fix, lock (issue 23)."""
    text = URDF.robot(URDF.link("base"), URDF.link("a", 1.0, (0.3, 0, 0)), URDF.link("b"),
                      URDF.joint("j1", "base", "a", axis="0 -1 0"),
                      URDF.joint("j2", "a", "b", xyz="0.6 0 0", axis="0 -1 0"))
    from lagrangian.dynamics.selection import recursive_dynamics

    system = arm(tmp_path, text)
    with pytest.raises(DerivationError, match="URDF joint 'j2' moves no mass.*--lock j2=0"):
        recursive_dynamics(system.model, backend="numpy")
    with pytest.raises(DerivationError, match="singular mass matrix.*'j2'"):
        system.dynamics()
