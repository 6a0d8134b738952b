"""One compiled derivatives engine for every robot (dynamics/engine/derivatives_c.py): a 200-joint chain
and a 102-coordinate floating tree get the compiled derivatives, which are forward dynamics'
own (M^-1, central differences of FD on the manifold, Pinocchio's computeABADerivatives); two
robots share the one module and the second compiles nothing; the Panda on a free flyer with
its mimic fingers (a coordinate driving two bodies)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from test_dynamics_pinocchio import ARM
from test_recursive_dynamics import TREE
from test_tree_kernel_scale import snake_urdf

import lagrangian
from lagrangian.compile import compiled
from robot_data import robots as _robots

pytest.importorskip("yourdfpy")
needs_c = pytest.mark.skipif(not compiled.available(), reason="no C compiler")

_INERTIA = ('<inertia ixx="0.002" ixy="0.0001" ixz="0" iyy="0.0021" iyz="0.00005" '
            'izz="0.0005"/>')


def _link(name: str, mass: float = 0.3) -> str:
    return (f'<link name="{name}"><inertial><origin xyz="0.01 -0.005 0.03"/>'
            f'<mass value="{mass}"/>{_INERTIA}</inertial></link>')


def _joint(name: str, parent: str, child: str, index: int) -> str:
    """A revolute joint about x, y or z in turn, every fifth a slide along a tilted axis."""
    slides = index % 5 == 2
    axis = "0.6 0 0.8" if slides else ("1 0 0", "0 1 0", "0 0 1")[index % 3]
    return (f'<joint name="{name}" type="{"prismatic" if slides else "revolute"}">'
            f'<parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="0.02 0.01 0.06" rpy="0.1 0 -0.2"/><axis xyz="{axis}"/>'
            '<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>')


def branching_urdf(limbs: int = 4, arm: int = 12, finger: int = 6) -> str:
    """A trunk with ``limbs`` limbs, each a chain of ``arm`` joints then two fingers of
    ``finger``: limbs (arm + 2 finger) joints, written depth first (Pinocchio's order)."""
    parts = ['<?xml version="1.0"?><robot name="hydra">', _link("trunk", 5.0)]
    count = 0
    for limb in range(limbs):
        parent = "trunk"
        for k in range(arm):
            child = f"l{limb}_{k}"
            parts += [_link(child), _joint(f"j{limb}_{k}", parent, child, count)]
            parent, count = child, count + 1
        for side in range(2):
            tip = parent
            for k in range(finger):
                child = f"l{limb}_{side}_{k}"
                parts += [_link(child, 0.1), _joint(f"j{limb}_{side}_{k}", tip, child, count)]
                tip, count = child, count + 1
    return "".join(parts) + "</robot>"


@pytest.fixture(scope="module")
def chain(tmp_path_factory):
    path = tmp_path_factory.mktemp("chain") / "snake.urdf"
    path.write_text(snake_urdf(200))
    return lagrangian.load(path).dynamics()


@pytest.fixture(scope="module")
def hydra(tmp_path_factory):
    path = tmp_path_factory.mktemp("hydra") / "hydra.urdf"
    path.write_text(branching_urdf())
    return lagrangian.load(path, floating_base=True).dynamics()


def _floating_states(robot, count: int, seed: int):
    rng = np.random.default_rng(seed)
    q = rng.uniform(-0.5, 0.5, (count, robot.nq))
    q[:, 3:7] = rng.normal(size=(count, 4))
    q[:, 3:7] /= np.linalg.norm(q[:, 3:7], axis=-1, keepdims=True)
    v, tau = rng.uniform(-0.5, 0.5, (2, count, robot.nv))
    return q, v, tau


def _identity(robot, q, ftau):
    """M ftau is 1 where ftau is M^-1 (M from the robot's own mass-matrix path), to rounding:
    1e-13 of |M| |ftau| (a long chain's M is ill-conditioned, 1e8 on the 200 joints)."""
    M = robot.mass_matrix(q)
    product = np.einsum("kij,kjl->kil", M, ftau)
    np.testing.assert_allclose(product, np.broadcast_to(np.eye(robot.nv), product.shape),
                               rtol=0, atol=1e-13 * np.abs(M).max() * np.abs(ftau).max())


def _central(robot, q, v, tau, columns, floating: bool, h: float = 1e-6):
    """d q_ddot/dq and d q_ddot/dq_dot at one state, the given columns, by central differences
    of forward dynamics (along q (+) h e_k on a floating base), in one batch."""
    from lagrangian.dynamics.tree.free_flyer import integrate

    E = h * np.eye(robot.nv)[columns]
    if floating:
        plus, minus = (integrate(np.repeat(q[None], len(columns), 0), s * E) for s in (1, -1))
    else:
        plus, minus = q + E, q - E
    shifted = np.concatenate([plus, minus, np.repeat(q[None], 2 * len(columns), 0)])
    rates = np.concatenate([np.repeat(v[None], 2 * len(columns), 0), v + E, v - E])
    qdd = robot.forward_dynamics(shifted, rates, np.broadcast_to(tau, rates.shape))
    k = len(columns)
    return ((qdd[:k] - qdd[k:2 * k]) / (2 * h)).T, ((qdd[2 * k:3 * k] - qdd[3 * k:]) / (2 * h)).T


@needs_c
def test_a_200_joint_chain_gets_the_compiled_forward_derivatives(chain):
    """d q_ddot/d tau is M^-1; d q_ddot/dq and d q_ddot/dq_dot are the central differences of
    forward dynamics (every tenth column)."""
    assert chain._derivatives_kernel() is not None  # the compiled path, not the complex step
    rng = np.random.default_rng(3)
    q, v, tau = rng.uniform(-0.5, 0.5, (3, 2, 200))
    fq, fv, ftau = chain.forward_dynamics_derivatives(q, v, tau)
    _identity(chain, q, ftau)
    columns = list(range(0, 200, 10)) + [199]
    for k in range(2):
        by_q, by_v = _central(chain, q[k], v[k], tau[k], columns, floating=False)
        for ours, central in ((fq[k][:, columns], by_q), (fv[k][:, columns], by_v)):
            np.testing.assert_allclose(ours, central, rtol=0,
                                       atol=1e-6 * max(1.0, np.abs(central).max()))


@needs_c
def test_a_floating_tree_of_102_coordinates_gets_the_compiled_forward_derivatives(hydra):
    """Four limbs of two fingers each on a free flyer (factored along the tree): M^-1, and every
    column of d q_ddot/dq (on the manifold) and d q_ddot/dq_dot by central differences."""
    from lagrangian.dynamics.engine.derivatives_c import factored_along_the_tree

    assert hydra.nv == 102 and hydra._derivatives_kernel() is not None
    assert factored_along_the_tree(hydra.tree) is not None
    q, v, tau = _floating_states(hydra, 9, 4)  # a group of eight lanes and one state alone
    fq, fv, ftau = hydra.forward_dynamics_derivatives(q, v, tau)
    _identity(hydra, q, ftau)
    for k in (0, 8):
        by_q, by_v = _central(hydra, q[k], v[k], tau[k], list(range(hydra.nv)), floating=True)
        for ours, central in ((fq[k], by_q), (fv[k], by_v)):
            np.testing.assert_allclose(ours, central, rtol=0,
                                       atol=1e-6 * max(1.0, np.abs(central).max()))


@needs_c
@pytest.mark.parametrize("floating", [False, True], ids=["chain", "floating tree"])
def test_large_trees_derivatives_are_pinocchios(chain, hydra, floating):
    """computeRNEADerivatives to 1e-12 of each matrix's largest entry and
    computeABADerivatives to 1e-9 (on the chain 1e-7: its M's condition number is 1e8, and
    M^-1's products are good to about that times the rounding), on the 200-joint chain and
    the 102-coordinate floating tree."""
    pin = pytest.importorskip("pinocchio")
    ours = hydra if floating else chain
    if floating:
        model = pin.buildModelFromXML(branching_urdf(), pin.JointModelFreeFlyer())
        assert ours.coordinates[7:] == tuple(model.names[i] for i in range(2, model.njoints))
        q, v, a = _floating_states(ours, 2, 5)
    else:
        model = pin.buildModelFromXML(snake_urdf(200))
        q, v, a = np.random.default_rng(5).uniform(-0.5, 0.5, (3, 2, 200))
    data = model.createData()
    dq, dv = ours.inverse_dynamics_derivatives(q, v, a)
    fq, fv, ftau = ours.forward_dynamics_derivatives(q, v, a)

    def close(mine, theirs, scale):
        np.testing.assert_allclose(mine, theirs, rtol=0,
                                   atol=scale * max(1.0, np.abs(theirs).max()))

    forward = 1e-9 if floating else 1e-7
    for k in range(2):
        pq, pv, _ = pin.computeRNEADerivatives(model, data, q[k], v[k], a[k])
        close(dq[k], pq, 1e-12)
        close(dv[k], pv, 1e-12)
        pin.computeABADerivatives(model, data, q[k], v[k], a[k])
        close(fq[k], data.ddq_dq, forward)
        close(fv[k], data.ddq_dv, forward)
        close(ftau[k], np.triu(data.Minv) + np.triu(data.Minv, 1).T, forward)


@needs_c
def test_two_robots_share_one_module_and_the_second_compiles_nothing(tmp_path, monkeypatch,
                                                                     chain):
    """The turret (a branch, a mimic joint) and a spatial arm: their derivatives come from the
    200-joint chain's module object, and the arm's first derivatives compile nothing into the
    cache (compiled._compile, the only writer of its modules, refused once the arm's dynamics
    have their own module; a count of the cache's files would see a parallel worker's)."""
    turret_path, arm_path = tmp_path / "turret.urdf", tmp_path / "arm.urdf"
    turret_path.write_text(TREE)
    arm_path.write_text(ARM)
    turret = lagrangian.load(turret_path, lock={"grip": 0.01}).dynamics()
    arm = lagrangian.load(arm_path).dynamics()
    arm.mass_matrix(np.zeros(arm.nq))
    engine = chain._derivatives_kernel().forward.func.__self__

    def refuse(*args, **kwargs):
        raise AssertionError("a derivatives module compiled for a second robot")

    monkeypatch.setattr(compiled, "_compile", refuse)
    for robot in (turret, arm):
        assert robot._derivatives_kernel().forward.func.__self__ is engine
    q, v, a = np.random.default_rng(6).uniform(-1, 1, (3, arm.n))
    _, _, ftau = arm.forward_dynamics_derivatives(q, v, a)
    np.testing.assert_allclose(ftau, np.linalg.inv(arm.mass_matrix(q)), rtol=1e-10, atol=1e-12)
    assert Path(engine.__file__).parent == compiled.trusted_cache_dir()


@needs_c
def test_panda_on_a_free_flyer_with_mimic_fingers_has_its_forward_derivatives():
    """The fingers' one coordinate drives two bodies: d q_ddot/d tau = M^-1 and d q_ddot/d(q,
    q_dot) = -M^-1 d ID/d(q, q_dot) at q_ddot = FD, to 1e-8 of each matrix's largest entry;
    d q_ddot/dq by central differences on the manifold."""
    pin = pytest.importorskip("pinocchio")
    path = _robots(pin) / "panda_description/urdf/panda.urdf"
    robot = lagrangian.load(path, floating_base=True).dynamics()
    assert robot._derivatives_kernel() is not None
    assert robot.nv == 14 and len(robot.tree.joints) == robot.nv - 6 + 2  # a mimic finger
    q, v, tau = _floating_states(robot, 3, 7)
    fq, fv, ftau = robot.forward_dynamics_derivatives(q, v, tau)
    Minv = np.linalg.inv(robot.mass_matrix(q))
    dq, dv = robot.inverse_dynamics_derivatives(q, v, robot.forward_dynamics(q, v, tau))

    def close(mine, theirs, scale=1e-8):
        np.testing.assert_allclose(mine, theirs, rtol=0, atol=scale * np.abs(theirs).max())

    close(ftau, Minv)
    close(fq, -Minv @ dq)
    close(fv, -Minv @ dv)
    by_q, by_v = _central(robot, q[0], v[0], tau[0], list(range(robot.nv)), floating=True)
    close(fq[0], by_q, 1e-6)
    close(fv[0], by_v, 1e-6)


def test_a_floating_base_without_compiled_c_takes_the_complex_step(tmp_path):
    """The numpy backend's complex step on a free flyer (d/dq along the base's own tangent,
    q (x) exp(dq)) equals the compiled analytic derivatives (two derivations), for inverse and
    forward dynamics alike, to 1e-9; a state off the unit quaternion is refused by name."""
    from test_floating_base import FLOATING_URDF

    path = tmp_path / "hopper.urdf"
    path.write_text(FLOATING_URDF)
    system = lagrangian.load(path)
    robot, compiled = system.dynamics(backend="numpy"), system.dynamics()
    rng = np.random.default_rng(9)
    q = rng.uniform(-1.0, 1.0, (3, robot.nq))
    q[:, 3:7] /= np.linalg.norm(q[:, 3:7], axis=-1, keepdims=True)
    v, a = rng.uniform(-1.0, 1.0, (2, 3, robot.nv))
    for name in ("inverse_dynamics_derivatives", "forward_dynamics_derivatives"):
        ours, theirs = getattr(robot, name)(q, v, a), getattr(compiled, name)(q, v, a)
        for x, y in zip(ours, theirs, strict=True):
            np.testing.assert_allclose(x, y, rtol=0, atol=1e-9 * max(1.0, np.abs(y).max()))
    q[1, 3] += 0.1
    with pytest.raises(lagrangian.InputError, match="quaternion") as caught:
        robot.forward_dynamics_derivatives(q, v, a)
    assert "\n" not in str(caught.value)
