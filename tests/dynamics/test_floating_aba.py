"""Forward dynamics of a floating base in generated C is the articulated-body algorithm with a
free-flyer root (its 6 x 6 articulated inertia solved, as Pinocchio's aba does), straight-line and
on vector lanes for batches: the module says so, and q_ddot agrees with Pinocchio's
aba(buildModelFromUrdf(path, JointModelFreeFlyer())) to 1e-12, one state and a batch alike. The
base quaternion's norm is checked in the module; a wrong one is still one line naming the state."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

import lagrangian

pytest.importorskip("yourdfpy")
pytestmark = pytest.mark.skipif(not (shutil.which("cc") or shutil.which("gcc")),
                                reason="no C compiler")

from tests.dynamics.test_floating_base import (  # noqa: E402
    FLOATING_URDF,
    _close_forward,
    _layout,
    _robots,
)


def _module_text(ours) -> str:
    from lagrangian.dynamics.engine.tree_module import module_source

    return module_source(ours.tree, tuple(ours.parameters)).source


def _compare_forward(model, ours, states: int = 7, seed: int = 3):
    """q_ddot of a batch (vector lanes and the scalar rest) and of single calls against aba;
    M q_ddot + b = tau for Pinocchio's own M and b."""
    import pinocchio as pin

    data = model.createData()
    iq, iv = _layout(model, ours)
    rng = np.random.default_rng(seed)
    q = np.array([pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
                  for _ in range(states)])
    v, tau = rng.uniform(-1, 1, (states, model.nv)), rng.uniform(-5, 5, (states, model.nv))
    batch = ours.forward_dynamics(q[:, iq], v[:, iv], tau[:, iv])
    for k in range(states):
        expected = pin.aba(model, data, q[k], v[k], tau[k])[iv]
        mass = pin.crba(model, data, q[k]).copy()
        mass = (np.triu(mass) + np.triu(mass, 1).T)[np.ix_(iv, iv)]
        bias = pin.rnea(model, data, q[k], v[k], np.zeros(model.nv))[iv]
        for ours_k in (batch[k], ours.forward_dynamics(q[k, iq], v[k, iv], tau[k, iv])):
            _close_forward(ours_k, expected, mass, bias, tau[k, iv])


UNROLLED_NUMBERS = {"solo_description/robots/solo12.urdf",
                    "borinot_description/urdf/borinot_flying_arm_2.urdf"}


def _check_robot(robot: str, algorithm: str = "the articulated-body algorithm"):
    import pinocchio as pin

    path = _robots() / robot
    if not path.is_file():
        pytest.skip(f"{robot} is not in this example-robot-data")
    # the opt-in unrolled module's numbers once per tree shape (Solo12 for the three 12-joint
    # quadrupeds, whose modules the generator writes alike, 5-7 s of gcc each); the others on
    # the engine, each one's unrolled module's text still asked what it does
    system = lagrangian.load(path, floating_base=True)
    kernel = "unrolled" if robot in UNROLLED_NUMBERS else "compact"
    ours = system.dynamics(backend="c", kernel=kernel)
    assert ours.kernel == kernel
    text = _module_text(ours)
    assert f"/* forward dynamics: {algorithm}, straight-line */" in text
    assert "rt4_forward_dynamics" in text  # batches on vector lanes
    _compare_forward(pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer()), ours)


def test_the_hopper_agrees_with_aba(tmp_path):
    """A floating base under a prismatic and two revolute joints (one on a skew axis) and a
    welded foot: three joints, where M = L L^T takes fewer operations than the articulated-body
    algorithm and is chosen; either agrees with Pinocchio's aba, batch and single call."""
    pin = pytest.importorskip("pinocchio")
    path = tmp_path / "hopper.urdf"
    path.write_text(FLOATING_URDF)
    ours = lagrangian.load(path).dynamics(backend="c")
    assert "/* forward dynamics: M = L L^T, straight-line */" in _module_text(ours)
    _compare_forward(pin.buildModelFromXML(FLOATING_URDF), ours, states=9)


@pytest.mark.slow
@pytest.mark.parametrize("robot, algorithm", [
    ("solo_description/robots/solo12.urdf", "the articulated-body algorithm"),
    ("anymal_b_simple_description/robots/anymal.urdf", "the articulated-body algorithm"),
    ("go1_description/urdf/go1.urdf", "the articulated-body algorithm"),
    ("talos_data/robots/talos_reduced.urdf", "the articulated-body algorithm"),
    # two joints: M = L L^T takes fewer operations
    ("borinot_description/urdf/borinot_flying_arm_2.urdf", "M = L L^T"),
])
def test_floating_robots_run_the_articulated_body_algorithm(robot, algorithm):
    """The floating robots of test_floating_base.py, in generated C (20 s to compile and print
    Solo12's module, a minute or two the humanoid's)."""
    _check_robot(robot, algorithm)


def test_the_module_checks_the_quaternion(tmp_path):
    """A wrong norm in any finite state of a batch, or in a q broadcast against a batch of v:
    one line naming the state and the norm; a norm within the tolerance is used (made unit);
    a state that is not finite is a NaN row, its quaternion not judged."""
    path = tmp_path / "hopper.urdf"
    path.write_text(FLOATING_URDF)
    ours = lagrangian.load(path).dynamics(backend="c")
    q = np.r_[0.1, 0.2, 0.3, 0, 0, 0, 1.0, 0.2, -0.4, 0.05]
    v = np.zeros(9)
    batch = np.stack([q, q, np.r_[q[:6], 0.5, q[7:]]])
    with pytest.raises(lagrangian.InputError, match="norm 0.5 in state 2") as info:
        ours.forward_dynamics(batch, v, v)
    assert info.value.field == "q"
    with pytest.raises(lagrangian.InputError, match="norm 2"):
        ours.gravity(np.r_[q[:6], 2.0, q[7:]])
    with pytest.raises(lagrangian.InputError, match="norm 2"):  # one q against five v
        ours.bias_forces(np.r_[q[:6], 2.0, q[7:]], np.zeros((5, 9)))
    near = np.r_[q[:6], 1 + 5e-7, q[7:]]
    np.testing.assert_allclose(ours.forward_dynamics(near, v, v), ours.forward_dynamics(q, v, v),
                               rtol=0, atol=1e-12)
    with pytest.warns(lagrangian.DynamicsWarning):
        out = ours.forward_dynamics(np.stack([q, np.r_[q[:6], np.nan, q[7:]]]), v, v)
    assert np.isfinite(out[0]).all() and np.isnan(out[1]).all()


def test_the_articulated_body_algorithm_of_the_hopper(tmp_path):
    """The algorithm itself on the hopper (where the module prefers M = L L^T): a floating joint
    with an origin of its own, a skew revolute axis, a prismatic joint, a welded foot; compiled
    alone, its q_ddot against aba to 1e-12."""
    import ctypes
    import subprocess

    pin = pytest.importorskip("pinocchio")
    from lagrangian.dynamics.emit.tree_algorithms import _forward_dynamics
    from lagrangian.dynamics.emit.tree_c import _SINCOS, _inputs
    from lagrangian.dynamics.emit.tree_emitter import _Emitter, _Layout

    path = tmp_path / "hopper.urdf"
    path.write_text(FLOATING_URDF)
    ours = lagrangian.load(path).dynamics(backend="numpy")
    layout = _Layout(ours.tree, tuple(ours.parameters))
    E = _Emitter()
    qdd = _forward_dynamics(E, ours.tree, layout, _inputs("q", 10), _inputs("v", 9),
                            _inputs("tau", 9))
    source = ("#include <math.h>\n" + _SINCOS
              + "void fd(const double *q, const double *v, const double *tau, const double *p, "
              "double *qdd)\n{\n    (void)p;\n"
              + E.body([(f"qdd[{i}]", x) for i, x in enumerate(qdd)]) + "\n}\n")
    (tmp_path / "fd.c").write_text(source)
    library = tmp_path / "fd.so"
    subprocess.run([shutil.which("cc") or shutil.which("gcc"), "-O1", "-shared", "-fPIC",
                    str(tmp_path / "fd.c"), "-o", str(library), "-lm"], check=True)
    function = ctypes.CDLL(str(library)).fd
    doubles = ctypes.POINTER(ctypes.c_double)
    model = pin.buildModelFromXML(FLOATING_URDF)
    data = model.createData()
    iq, iv = _layout(model, ours)
    rng = np.random.default_rng(5)
    P = np.array(list(ours.parameters.values()), dtype=float)
    for _ in range(5):
        q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
        v, tau = rng.uniform(-1, 1, model.nv), rng.uniform(-5, 5, model.nv)
        Q, V, T = (np.ascontiguousarray(x, dtype=float) for x in (q[iq], v[iv], tau[iv]))
        out = np.zeros(9)
        function(*(x.ctypes.data_as(doubles) for x in (Q, V, T, P, out)))
        mass = pin.crba(model, data, q).copy()
        mass = (np.triu(mass) + np.triu(mass, 1).T)[np.ix_(iv, iv)]
        _close_forward(out, pin.aba(model, data, q, v, tau)[iv], mass,
                       pin.rnea(model, data, q, v, np.zeros(model.nv))[iv], tau[iv])
