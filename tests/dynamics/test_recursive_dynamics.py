"""Recursive dynamics of URDF trees in generated C (dynamics/recursive.py): the same numbers as
the derived equations (an independent path: Lagrange's equations, lambdified), and the laws
they obey on their own: T = 1/2 v.M v, g = dV/dq, d(T + V)/dt = v.tau, T + V kept in a free
motion; where the tree does not describe the model, the symbolic path."""

from __future__ import annotations

import shutil
import subprocess
from dataclasses import replace

import numpy as np
import pytest

import lagrangian
from lagrangian.compile import compiled
from lagrangian.compile.functions import numeric
from lagrangian.dynamics.joint_space import Dynamics
from lagrangian.dynamics.recursive import TreeDynamics, applicable_tree
from lagrangian.dynamics.selection import recursive_dynamics
from lagrangian.errors import ModelError

pytest.importorskip("yourdfpy")
needs_c = pytest.mark.skipif(not compiled.available(), reason="no C compiler / Python headers")

INERTIA = '<inertia ixx="{0}" ixy="{1}" ixz="{2}" iyy="{3}" iyz="{4}" izz="{5}"/>'


def link(name, m=None, xyz="0 0 0", rpy="0 0 0", inertia=(0.01, 0, 0, 0.02, 0, 0.015)):
    if m is None:
        return f'<link name="{name}"/>'
    return (f'<link name="{name}"><inertial><origin xyz="{xyz}" rpy="{rpy}"/>'
            f'<mass value="{m}"/>{INERTIA.format(*inertia)}</inertial></link>')


def joint(name, parent, child, kind="revolute", xyz="0 0 0", rpy="0 0 0", axis="0 0 1",
          extra=""):
    return (f'<joint name="{name}" type="{kind}"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{axis}"/>'
            f'<limit lower="-3" upper="3" effort="10" velocity="5"/>{extra}</joint>')


# A branched tree: a turret carrying two arms; rpy origins, a tilted revolute axis, a tilted
# prismatic axis, a continuous joint, a mimic joint, a locked joint, a fixed tool with its own
# mass and inertial rpy, a massless link in the middle of the tree, full inertia tensors.
TREE = ('<?xml version="1.0"?><robot name="turret">' + "".join([
    link("base", 5.0, "0 0 0.05"),
    link("turret", 2.0, "0.01 0.02 0.1", "0.1 0.2 0.3", (0.03, 0.001, -0.002, 0.04, 0.003, 0.02)),
    link("left", 1.0, "0.2 0 0.01", "0 0.4 0", (0.004, 0.0005, 0, 0.02, -0.0007, 0.021)),
    link("left_fore", 0.7, "0.15 0.01 0", inertia=(0.002, 0, 0.0003, 0.01, 0, 0.011)),
    link("right"),  # massless, between two joints
    link("right_slide", 0.6, "0 0.05 0.02", "0.3 0 0"),
    link("tool", 0.3, "0 0 0.04", "0 0.5 0.2", (0.0004, 0.0001, 0, 0.0005, 0, 0.0003)),
    link("finger", 0.1, "0.02 0 0"),
    joint("yaw", "base", "turret", xyz="0 0 0.3", rpy="0 0 0.4", axis="0 0 1"),
    joint("shoulder", "turret", "left", xyz="0.1 0.05 0.2", rpy="1.5707963267948966 0 0",
          axis="0.6 0 0.8"),
    joint("elbow", "left", "left_fore", kind="continuous", xyz="0.4 0 0", rpy="0.2 -0.1 0.3",
          axis="0 1 0"),
    joint("wrist", "left_fore", "tool", xyz="0.3 0 0",
          extra='<mimic joint="elbow" multiplier="-0.5" offset="0.2"/>'),
    joint("mount", "turret", "right", kind="fixed", xyz="-0.1 0 0.2", rpy="0 0.3 0"),
    joint("slide", "right", "right_slide", kind="prismatic", xyz="0 0.1 0", rpy="0.1 0 0",
          axis="0.48 0.6 0.64"),
    joint("grip", "tool", "finger", kind="prismatic", axis="1 0 0"),
]) + "</robot>")


@pytest.fixture(scope="module", params=["unrolled", "compact"])
def tree(tmp_path_factory, request):
    """The turret, and the kernel its dynamics run on: the engine's one module for every tree
    (the default) or the tree's own unrolled module (kernel="unrolled")."""
    path = tmp_path_factory.mktemp("tree") / "turret.urdf"
    path.write_text(TREE)
    system = lagrangian.load(path, lock={"grip": 0.01})
    assert system.dynamics().kernel == "compact" or not compiled.available()
    return OnKernel(system, request.param)


class OnKernel:
    """A System whose dynamics and numeric functions run on one kernel (the rest its own)."""

    def __init__(self, system, kernel):
        self.system, self.kernel = system, kernel

    def __getattr__(self, name):
        return getattr(self.system, name)

    def dynamics(self, **options):
        return self.system.dynamics(**{"kernel": self.kernel, **options})

    def numeric(self):
        return self.dynamics().numeric_system()

    def with_parameters(self, **values):
        return OnKernel(self.system.with_parameters(**values), self.kernel)


def states(n, count=6, seed=3):
    rng = np.random.default_rng(seed)
    return (rng.uniform(-1.5, 1.5, (count, n)) for _ in range(4))


@needs_c
@pytest.mark.slow
def test_recursive_equals_the_derived_equations_on_a_branched_tree(tree):
    fast = tree.dynamics()
    assert fast.backend == "recursive"
    assert fast.coordinates == ("yaw", "shoulder", "elbow", "slide")
    # the derived equations, lambdified: Lagrange's method, no shared code with the recursion
    slow = Dynamics(numeric(tree.equations_of_motion(), backend="numpy"))
    q, v, a, tau = states(4)
    for name, args in [("mass_matrix", (q,)), ("bias_forces", (q, v)), ("gravity", (q,)),
                       ("inverse_dynamics", (q, v, a)), ("forward_dynamics", (q, v, tau)),
                       ("kinetic_energy", (q, v)), ("potential_energy", (q,))]:
        ours, theirs = getattr(fast, name)(*args), getattr(slow, name)(*args)
        np.testing.assert_allclose(ours, theirs, rtol=1e-10, atol=1e-12 * np.abs(theirs).max(),
                                   err_msg=name)


@pytest.fixture(scope="module")
def no_mimic(tmp_path_factory):
    """The tree with its mimic joint locked: forward dynamics by the articulated-body
    algorithm (with the mimic, by Cholesky of M)."""
    path = tmp_path_factory.mktemp("tree") / "turret.urdf"
    path.write_text(TREE)
    return lagrangian.load(path, lock={"grip": 0.01, "wrist": -0.3})


@needs_c
@pytest.mark.parametrize("which", ["tree", "no_mimic"])
def test_laws_of_the_recursive_functions(which, tree, no_mimic):
    kernel = tree.dynamics().kernel  # each kernel, by the tree fixture's parameter
    f = {"tree": tree, "no_mimic": no_mimic}[which].dynamics(kernel=kernel)
    assert f.kernel == kernel
    assert f.backend == "recursive"
    n = f.n
    q, v, a, _ = states(n, count=4, seed=11)
    mass = f.mass_matrix(q)
    np.testing.assert_allclose(mass, np.swapaxes(mass, -1, -2), rtol=0, atol=1e-15)
    assert np.all(np.linalg.eigvalsh(mass) > 0)
    # T = 1/2 v.M v: the velocity recursion against the composite-rigid-body M
    np.testing.assert_allclose(f.kinetic_energy(q, v), 0.5 * np.einsum("ki,kij,kj->k", v, mass, v),
                               rtol=1e-12)
    # g(q) = dV/dq (central differences, error ~ h^2)
    h = 1e-6
    for i in range(n):
        step = np.zeros(n)
        step[i] = h
        slope = (f.potential_energy(q + step) - f.potential_energy(q - step)) / (2 * h)
        np.testing.assert_allclose(f.gravity(q)[:, i], slope, rtol=1e-6, atol=1e-7)
    # the work-energy theorem: d(T + V)/dt = v.tau along q' = v, v' = a, tau = M a + C v + g
    tau = f.inverse_dynamics(q, v, a)
    h = 1e-5

    def energy(s):
        return f.kinetic_energy(q + s * v, v + s * a) + f.potential_energy(q + s * v)

    np.testing.assert_allclose((energy(h) - energy(-h)) / (2 * h), np.einsum("ki,ki->k", v, tau),
                               rtol=1e-6, atol=1e-7)
    # forward dynamics (articulated-body algorithm or Cholesky) undoes inverse dynamics
    # (Newton-Euler), and equals M^-1 (tau - b) solved here
    np.testing.assert_allclose(f.forward_dynamics(q, v, tau), a, rtol=1e-9, atol=1e-10)
    solved = np.linalg.solve(mass, (tau - f.bias_forces(q, v))[..., None])[..., 0]
    np.testing.assert_allclose(solved, a, rtol=1e-9, atol=1e-10)
    # a batch (two states per vector operation, an odd one alone) equals one call per state
    for name, args in [("mass_matrix", (q[:3],)), ("inverse_dynamics", (q[:3], v[:3], a[:3])),
                       ("forward_dynamics", (q[:3], v[:3], tau[:3])),
                       ("kinetic_energy", (q[:3], v[:3]))]:
        one_by_one = [getattr(f, name)(*(x[k] for x in args)) for k in range(3)]
        np.testing.assert_allclose(getattr(f, name)(*args), one_by_one, rtol=1e-14, atol=0)
    # q of shape (n,) broadcast against a batch
    one = f.bias_forces(q[0], v)
    np.testing.assert_allclose(one, f.bias_forces(np.broadcast_to(q[0], v.shape), v), rtol=1e-15)
    assert f.mass_matrix(q.reshape(2, 2, n)).shape == (2, 2, n, n)
    assert f.kinetic_energy(q[0], v[0]).shape == ()


@needs_c
def test_a_large_batch_split_over_threads_equals_one_call_per_state(tree):
    """Past 1024 states per processor a batch runs on threads, each taking a range: every
    state's result is its own single call's (an odd count, so a part ends mid-vector)."""
    f = tree.dynamics()
    q, v, a, _ = states(f.n, count=4097, seed=5)
    tau = f.inverse_dynamics(q, v, a)
    picks = [0, 1, 2047, 2048, 2049, 4095, 4096]
    for name, args in [("mass_matrix", (q,)), ("inverse_dynamics", (q, v, a)),
                       ("forward_dynamics", (q, v, tau)), ("potential_energy", (q,))]:
        batch = getattr(f, name)(*args)
        one_by_one = [getattr(f, name)(*(x[k] for x in args)) for k in picks]
        np.testing.assert_allclose(batch[picks], one_by_one, rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(f.forward_dynamics(q, v, tau), a, rtol=1e-8, atol=1e-9)


@needs_c
def test_a_compiler_that_refuses_the_native_flags_still_builds(tree, monkeypatch, tmp_path):
    """The batches are built for this processor (its own vector width); a compiler that
    refuses those flags gets the portable ones, with the same numbers."""
    native = tree.dynamics()
    monkeypatch.setenv("LAGRANGIAN_CACHE", str(tmp_path))
    monkeypatch.setattr(compiled, "NATIVE_CFLAGS", ("-mno-such-instruction-set",))
    portable = TreeDynamics(tree.model, applicable_tree(tree.model), kernel="unrolled")
    assert portable.module.__name__ != native.module.__name__
    q, v, a, _ = states(native.n, count=9, seed=8)
    np.testing.assert_allclose(portable.mass_matrix(q), native.mass_matrix(q),
                               rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(portable.inverse_dynamics(q, v, a),
                               native.inverse_dynamics(q, v, a), rtol=1e-12, atol=1e-12)


@needs_c
def test_a_compiler_that_refuses_an_exactness_flag_still_builds(tree, monkeypatch, tmp_path):
    """The robot's module asks for no fused multiply-adds and no packing of scalar code
    (compiled.EXACT_CFLAGS); a compiler that knows only the first still builds it, with the
    same numbers."""
    native = tree.dynamics()
    monkeypatch.setenv("LAGRANGIAN_CACHE", str(tmp_path))
    monkeypatch.setattr(compiled, "EXACT_CFLAGS", ("-ffp-contract=off", "-fno-such-flag"))
    fallback = TreeDynamics(tree.model, applicable_tree(tree.model), kernel="unrolled")
    q, v, a, _ = states(fallback.n, count=9, seed=8)
    np.testing.assert_allclose(fallback.inverse_dynamics(q, v, a),
                               native.inverse_dynamics(q, v, a), rtol=1e-12, atol=1e-12)


@needs_c
def test_free_motion_keeps_energy(tree):
    """Zero torque: T + V is constant along the motion q'' = M^-1 (-C q' - g)."""
    from scipy.integrate import solve_ivp

    f = tree.dynamics()
    n = f.n

    def rhs(_, y):
        return np.concatenate([y[n:], f.forward_dynamics(y[:n], y[n:], np.zeros(n))])

    y0 = np.array([0.2, -0.4, 0.7, 0.05, 1.0, -0.5, 0.8, 0.3])
    run = solve_ivp(rhs, (0.0, 1.0), y0, method="DOP853", rtol=1e-11, atol=1e-12)
    q, v = run.y[:n].T, run.y[n:].T
    energy = f.kinetic_energy(q, v) + f.potential_energy(q)
    assert np.ptp(energy) < 1e-8 * np.abs(energy).max()
    assert np.ptp(f.kinetic_energy(q, v)) > 0.1  # it did move


@needs_c
def test_two_link_mass_matrix_closed_form(tmp_path):
    """Planar two-link arm (Spong): M11 = I1 + I2 + m1 c1^2 + m2 (l1^2 + c2^2 + 2 l1 c2 cos q2),
    M12 = I2 + m2 (c2^2 + l1 c2 cos q2), M22 = I2 + m2 c2^2."""
    m1, m2, l1, c1, c2, i1, i2 = 2.0, 1.5, 1.0, 0.5, 0.4, 0.2, 0.1
    text = ('<?xml version="1.0"?><robot name="two">' + link("base")
            + link("upper", m1, f"{c1} 0 0", inertia=(0.01, 0, 0, i1, 0, 0.2))
            + link("fore", m2, f"{c2} 0 0", inertia=(0.01, 0, 0, i2, 0, 0.1))
            + joint("shoulder", "base", "upper", axis="0 -1 0")
            + joint("elbow", "upper", "fore", xyz=f"{l1} 0 0", axis="0 -1 0") + "</robot>")
    path = tmp_path / "two.urdf"
    path.write_text(text)
    f = lagrangian.load(path).dynamics()
    assert f.backend == "recursive"
    q2 = np.linspace(-3, 3, 7)
    q = np.column_stack([np.full_like(q2, 0.3), q2])
    mass = f.mass_matrix(q)
    np.testing.assert_allclose(mass[:, 0, 0], i1 + i2 + m1 * c1**2
                               + m2 * (l1**2 + c2**2 + 2 * l1 * c2 * np.cos(q2)), rtol=1e-13)
    np.testing.assert_allclose(mass[:, 0, 1], i2 + m2 * (c2**2 + l1 * c2 * np.cos(q2)),
                               rtol=1e-13)
    np.testing.assert_allclose(mass[:, 1, 1], i2 + m2 * c2**2, rtol=1e-13)
    # Over many turns (the batch's vector sine and cosine in every quadrant): heights
    # c1 sin q1 and l1 sin q1 + c2 sin(q1 + q2), so V = g (...) and g(q) = dV/dq.
    q1, q2 = np.linspace(-40, 40, 4001), np.linspace(35, -45, 4001)
    q = np.column_stack([q1, q2])
    g = f.parameters["g"]
    potential = g * (m1 * c1 * np.sin(q1) + m2 * (l1 * np.sin(q1) + c2 * np.sin(q1 + q2)))
    gravity = g * np.column_stack([m1 * c1 * np.cos(q1) + m2 * (l1 * np.cos(q1)
                                                                 + c2 * np.cos(q1 + q2)),
                                   m2 * c2 * np.cos(q1 + q2)])
    np.testing.assert_allclose(f.potential_energy(q), potential, rtol=0, atol=1e-12)
    np.testing.assert_allclose(f.gravity(q), gravity, rtol=0, atol=1e-12)
    np.testing.assert_allclose(f.mass_matrix(q)[:, 0, 1], i2 + m2 * (c2**2 + l1 * c2 * np.cos(q2)),
                               rtol=1e-13, atol=1e-15)


@needs_c
def test_parameters_and_what_the_tree_does_not_describe(tree):
    # g and the actuator parameters are runtime values
    moon = tree.with_parameters(g=1.62, tau_slide=0.5).dynamics()
    assert moon.backend == "recursive"
    q = np.array([0.1, 0.2, 0.3, 0.04])
    earth = tree.dynamics().gravity(q)
    expected = earth * 1.62 / 9.81
    expected[3] -= 0.5  # tau_slide is a load: b = C q_dot + g - tau_p
    np.testing.assert_allclose(moon.gravity(q), expected, rtol=1e-12, atol=1e-15)
    # a model edited after reading (a load added) is not the tree's: the symbolic path
    edited = replace(tree.model, loads=tree.model.loads + (object(),))
    assert applicable_tree(edited) is None
    assert applicable_tree(replace(tree.model, generalized_forces=())) is None
    # backend "numpy": the same recursions in numpy (recursive_numpy.py), not the C module
    assert recursive_dynamics(tree.model, backend="numpy").kernel == "numpy"
    with pytest.raises(ModelError, match="expected 4 values"):
        tree.dynamics().mass_matrix([0.1, 0.2])
    with pytest.raises(ModelError, match="expected 4 values"):
        tree.dynamics().inverse_dynamics(q, q, [1.0])


@needs_c
def test_simulation_runs_on_the_recursive_module(tree):
    system = tree.numeric()
    # the compact module has no DOP853 loop of its own: scipy steps it
    assert system.backend == {"unrolled": "c", "compact": "compact"}[tree.dynamics().kernel]
    q, v = np.array([0.1, 0.2, 0.3, 0.04]), np.array([0.5, -0.2, 0.1, 0.0])
    accelerations, _ = system.accelerations_and_multipliers(q, v)
    np.testing.assert_allclose(accelerations, tree.dynamics().forward_dynamics(q, v, np.zeros(4)),
                               rtol=1e-12)
    run = tree.simulate(t_end=0.2)
    assert run.completed


@needs_c
def test_standalone_recursive_c_gives_the_python_numbers(tree, tmp_path):
    # (the Python numbers are the derived equations' in the first test)
    import ctypes

    from lagrangian.dynamics.standalone.standalone import standalone_tree_c

    compiler = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    code = standalone_tree_c(tree.model, applicable_tree(tree.model), tree.parameters, "tur")
    (tmp_path / "tur.h").write_text(code.header)
    (tmp_path / "tur.c").write_text(code.source)
    assert "Python.h" not in code.source and "malloc" not in code.source
    library = tmp_path / "tur.so"
    subprocess.run([compiler, "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-pedantic",
                    "-shared", "-fPIC", str(tmp_path / "tur.c"), "-o", str(library), "-lm"],
                   check=True)
    c = ctypes.CDLL(str(library))
    n, vec = 4, ctypes.c_double * 4
    params = (ctypes.c_double * len(tree.parameters)).in_dll(c, "tur_parameters")
    slow = tree.dynamics()
    q, v, a, _ = states(n, count=3, seed=5)
    for k in range(3):
        M = (ctypes.c_double * (n * n))()
        c.tur_mass_matrix(vec(*q[k]), params, M)
        np.testing.assert_allclose(np.array(M).reshape(n, n), slow.mass_matrix(q[k]), rtol=1e-10)
        out = vec()
        c.tur_inverse_dynamics(vec(*q[k]), vec(*v[k]), vec(*a[k]), params, out)
        np.testing.assert_allclose(np.array(out), slow.inverse_dynamics(q[k], v[k], a[k]),
                                   rtol=1e-10)
        assert c.tur_forward_dynamics(vec(*q[k]), vec(*v[k]), out, params, out) == 0
        np.testing.assert_allclose(np.array(out), a[k], rtol=1e-9)
