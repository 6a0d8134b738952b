"""One compiled reach module for every tree (reach_c.py): the Panda, the UR5 and the Panda on
a floating base run on the same module object, the second and third writing nothing into the
compiled cache, their frame Jacobians against Pinocchio's computeFrameJacobian; a tree of 120
joints (branches, tilted axes, sliders) on one state and on threads' batches against the numpy
twins (frames.py, centroidal.py); a description or tables that describe no tree refused in one
line."""

from __future__ import annotations

import numpy as np
import pytest

import lagrangian
from lagrangian.compile import compiled
from lagrangian.dynamics.engine.reach_c import ReachKernel, engine, reach_module, tables
from lagrangian.dynamics.tree.description import HEADER, STRIDE, describe
from robot_data import robots

pytest.importorskip("yourdfpy")
REFERENCES = ("world", "local", "local_world_aligned")
ROBOTS = {"panda": ("panda_description/urdf/panda.urdf",
                    {"panda_finger_joint1": 0.0, "panda_finger_joint2": 0.0}, "panda_hand"),
          "ur5": ("ur_description/urdf/ur5_robot.urdf", {}, "tool0")}


def _kernel(dynamics) -> ReachKernel:
    """The compiled kernel of a numpy dynamics' tree (as joint_space.py builds it for the C
    backends), without the tree module's own build."""
    module = reach_module(dynamics.tree)
    if module is None:
        pytest.skip("no C compiler")
    return ReachKernel(module, dynamics.tree, dynamics.kinematics.mass() > 0)


def _refuse_compiling(*args, **kwargs):
    raise AssertionError("a reach module compiled for a second tree")


@pytest.fixture(scope="module")
def arms():
    """(name, Pinocchio's model, our numpy dynamics, its kernel) for the Panda, then the UR5,
    then the Panda on a floating base; once the first has its kernel, compiled._compile (the
    only writer of the cache's modules) is refused: a count of the cache's files would see a
    parallel worker's."""
    pin = pytest.importorskip("pinocchio")
    out = []
    refusing = pytest.MonkeyPatch()
    for name, floating in (("panda", False), ("ur5", False), ("panda", True)):
        relpath, lock, _ = ROBOTS[name]
        path = robots(pin) / relpath
        if not path.is_file():
            pytest.skip(f"{relpath} is not in this example-robot-data")
        ours = lagrangian.load(path, lock=lock, floating_base=floating).dynamics(backend="numpy")
        model = (pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer()) if floating
                 else pin.buildModelFromUrdf(str(path)))
        if lock:
            model = pin.buildReducedModel(model, [model.getJointId(j) for j in lock],
                                          pin.neutral(model))
        try:
            out.append((name, model, ours, _kernel(ours)))
        finally:
            refusing.setattr(compiled, "_compile", _refuse_compiling)
    refusing.undo()
    return out


def test_every_tree_runs_on_the_one_module_and_builds_nothing(arms):
    (_, _, _, first), *others = arms  # built with compiling refused after the first
    assert first.module is engine()
    for _, _, _, kernel in others:
        assert kernel.module is first.module


def test_each_trees_frame_jacobian_agrees_with_pinocchio(arms):
    import pinocchio as pin

    for name, model, ours, kernel in arms:
        frame = ROBOTS[name][2]
        fid = model.getFrameId(frame)
        data = model.createData()
        q = np.array([pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
                      for _ in range(9)])  # a batch on lanes, its last state alone
        for ref, pin_ref in zip(REFERENCES, (pin.ReferenceFrame.WORLD, pin.ReferenceFrame.LOCAL,
                                             pin.ReferenceFrame.LOCAL_WORLD_ALIGNED),
                                strict=True):
            batch = kernel.jacobian(q, frame, ref)
            for k in range(len(q)):
                expected = pin.computeFrameJacobian(model, data, q[k], fid, pin_ref)
                np.testing.assert_allclose(batch[k], expected, atol=1e-12, err_msg=f"{name} {ref}")
            np.testing.assert_allclose(kernel.jacobian(q[-1], frame, ref), batch[-1], atol=1e-15)
        np.testing.assert_allclose(kernel.placement(q, frame), ours.placement(q, frame),
                                   atol=1e-12)


def _big_urdf(joints: int) -> str:
    """A tree of ``joints`` moving joints: a trunk with a side chain every fifth link, axes
    along e_k, tilted, some of them sliders, origins turned, inertias full."""
    rng = np.random.default_rng(11)
    links = ['<link name="base"/>']
    parts = []
    for k in range(joints):
        parent = "base" if k == 0 else f"l{k - 1}" if k % 5 else f"l{max(k - 5, 0)}"
        m, (x, y, z) = rng.uniform(0.2, 2.0), rng.uniform(-0.1, 0.1, 3)
        links.append(
            f'<link name="l{k}"><inertial><origin xyz="{x} {y} {z}" rpy="0.1 0.2 0.3"/>'
            f'<mass value="{m}"/><inertia ixx="0.02" ixy="0.001" ixz="-0.002" iyy="0.03" '
            f'iyz="0.0015" izz="0.025"/></inertial></link>')
        axis = ("0 0 1", "1 0 0", "0 -1 0", "0.6 0 0.8", "0 0.8 0.6")[k % 5]
        kind = "prismatic" if k % 7 == 3 else "revolute"
        rpy = "0 0 0" if k % 3 else "0.3 -0.2 0.1"
        parts.append(
            f'<joint name="j{k}" type="{kind}"><parent link="{parent}"/><child link="l{k}"/>'
            f'<origin xyz="0.05 0.01 0.1" rpy="{rpy}"/><axis xyz="{axis}"/>'
            '<limit lower="-3" upper="3" effort="1" velocity="1"/></joint>')
    return f'<?xml version="1.0"?><robot name="big">{"".join(links + parts)}</robot>'


@pytest.fixture(scope="module")
def big(tmp_path_factory):
    path = tmp_path_factory.mktemp("engine") / "big.urdf"
    path.write_text(_big_urdf(120))
    ours = lagrangian.load(path).dynamics(backend="numpy")
    return ours, _kernel(ours)


def test_a_large_trees_jacobian_and_centroidal_matrix_agree_with_numpy(big):
    """120 bodies: one state's work on the heap (past the stack's), a batch of 2100 states on
    threads (RK_THREAD_STATES = 1024), against frames.py's and centroidal.py's numpy."""
    ours, kernel = big
    rng = np.random.default_rng(2)
    q = rng.uniform(-1, 1, (2100, ours.n))
    for frame in ("l119", "l57"):
        for ref in REFERENCES:
            batch = kernel.jacobian(q, frame, ref)
            np.testing.assert_allclose(batch[:40], ours.jacobian(q[:40], frame, ref), atol=1e-11)
            np.testing.assert_allclose(batch[-5:], ours.jacobian(q[-5:], frame, ref), atol=1e-11)
            np.testing.assert_allclose(kernel.jacobian(q[7], frame, ref), batch[7], atol=1e-13)
    A = kernel.centroidal(q)
    np.testing.assert_allclose(A[:40], ours.centroidal_momentum_matrix(q[:40]), atol=1e-10)
    np.testing.assert_allclose(A[-5:], ours.centroidal_momentum_matrix(q[-5:]), atol=1e-10)
    np.testing.assert_allclose(kernel.centroidal(q[3]), A[3], atol=1e-13)


def test_tables_that_describe_no_tree_are_refused(big):
    ours, kernel = big
    D, (ints, floats) = describe(ours.tree, {}), tables(ours.tree)
    module, index = kernel.module, kernel.frame_index
    bad_parent = D.copy()
    bad_parent[HEADER + int(D[1]) + 5 * STRIDE] = 9  # body 5's parent after it
    bad_frame = ints.copy()
    bad_frame[3] = 10 ** 6  # frame 0 on no body
    for args, match in [((D, ints[:-1], floats), "sizes"), ((D, ints, floats[:-1]), "sizes"),
                        ((bad_parent, ints, floats), "description"), ((D[:-1], ints, floats),
                                                                      "description"),
                        ((D, bad_frame, floats), "frame"), ((D, ints[:2], floats), "header")]:
        with pytest.raises(ValueError, match=match):
            module.tree(*args, index)
    spoilt = floats.copy()
    spoilt[10] = np.nan
    with pytest.raises(ValueError, match="finite"):
        module.tree(D, ints, spoilt, index)
    with pytest.raises(TypeError):
        module.tree(D, ints, floats, list(index))
