"""Frames, Jacobians and the centre of mass of a URDF robot against Pinocchio (skipped where it
is not installed): every link and joint frame's placement, its Jacobian in the three reference
frames, the centre of mass and its Jacobian, at random states; and the laws they obey."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import lagrangian

pin = pytest.importorskip("pinocchio")
pytest.importorskip("yourdfpy")

from tests.dynamics.test_dynamics_pinocchio import ARM  # noqa: E402  (revolute, prismatic, fixed)

REFERENCES = {"world": pin.ReferenceFrame.WORLD, "local": pin.ReferenceFrame.LOCAL,
              "local_world_aligned": pin.ReferenceFrame.LOCAL_WORLD_ALIGNED}


@pytest.fixture(scope="module")
def arm(tmp_path_factory):
    path = tmp_path_factory.mktemp("frames") / "spatial.urdf"
    path.write_text(ARM)
    return lagrangian.load(path).dynamics(backend="numpy")


def _pinocchio_frame(model, name):
    """Pinocchio's frame of a link (BODY) or a joint (JOINT or FIXED_JOINT) named so."""
    for kind in (pin.FrameType.BODY, pin.FrameType.JOINT, pin.FrameType.FIXED_JOINT):
        if model.existFrame(name, kind):
            return model.getFrameId(name, kind)
    raise AssertionError(f"Pinocchio has no frame {name}")


def test_every_frame_and_jacobian_agrees_with_pinocchio(arm):
    model = pin.buildModelFromXML(ARM)
    data = model.createData()
    rng = np.random.default_rng(11)
    q = rng.uniform(-1, 1, (6, 3))
    assert set(arm.frames) == {"base", "a", "b", "c", "tool", "j1", "j2", "j3", "flange"}
    for name in arm.frames:
        placement = arm.placement(q, name)
        jacobians = {ref: arm.jacobian(q, name, ref) for ref in REFERENCES}
        frame_id = _pinocchio_frame(model, name)
        for k in range(len(q)):
            pin.forwardKinematics(model, data, q[k])
            pin.updateFramePlacements(model, data)
            pin.computeJointJacobians(model, data, q[k])
            np.testing.assert_allclose(placement[k], data.oMf[frame_id].homogeneous, atol=1e-12)
            for ref, pin_ref in REFERENCES.items():
                expected = pin.getFrameJacobian(model, data, frame_id, pin_ref)
                np.testing.assert_allclose(jacobians[ref][k], expected, atol=1e-12,
                                           err_msg=f"{name} {ref}")
    com = arm.center_of_mass(q)
    com_jacobian = arm.center_of_mass_jacobian(q)
    for k in range(len(q)):
        np.testing.assert_allclose(com[k], pin.centerOfMass(model, data, q[k]), atol=1e-12)
        np.testing.assert_allclose(com_jacobian[k], pin.jacobianCenterOfMass(model, data, q[k]),
                                   atol=1e-12)


def test_jacobians_are_the_derivatives_of_the_placements(arm):
    """Central differences of the tool's origin and orientation along a random rate equal J q_dot:
    the law, without Pinocchio."""
    rng = np.random.default_rng(3)
    q, v = rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 3)
    h = 1e-6
    ahead, behind = arm.placement(q + h * v, "tool"), arm.placement(q - h * v, "tool")
    velocity = (ahead[:3, 3] - behind[:3, 3]) / (2 * h)
    R = arm.placement(q, "tool")[:3, :3]
    spin = (ahead[:3, :3] - behind[:3, :3]) / (2 * h) @ R.T  # [w]x in world axes
    omega = np.array([spin[2, 1], spin[0, 2], spin[1, 0]])
    J = arm.jacobian(q, "tool")
    np.testing.assert_allclose(J[:3] @ v, velocity, atol=1e-8)
    np.testing.assert_allclose(J[3:] @ v, omega, atol=1e-8)


def test_bad_frames_and_models_are_refused_in_one_line(arm):
    with pytest.raises(lagrangian.InputError, match="no frame named 'tol'; did you mean 'tool'"):
        arm.placement(np.zeros(3), "tol")
    with pytest.raises(lagrangian.InputError, match="unknown reference"):
        arm.jacobian(np.zeros(3), "tool", "global")
    with pytest.raises(lagrangian.InputError, match="expected 3 values"):
        arm.placement(np.zeros(4), "tool")
    with pytest.raises(lagrangian.InputError, match="kinematic tree"):
        lagrangian.load("pendulum").dynamics().placement(np.zeros(1), "bob")


def _robot_files():
    for parent in Path(pin.__file__).resolve().parents:
        candidate = parent / "share/example-robot-data/robots"
        if candidate.is_dir():
            return sorted(candidate.glob("*/urdf/*.urdf")) + sorted(candidate.glob("*/robots/*.urdf"))
    return []


@pytest.mark.slow
def test_frames_of_every_example_robot_agree_with_pinocchio():
    """Every robot of example-robot-data that both load with the same coordinates (fixed base,
    no continuous joint: Pinocchio writes those as cos/sin pairs): every frame's placement and
    world-aligned Jacobian, and the centre of mass, at random states, to 1e-10 of the robot's
    size. Skipped where the package is not installed."""
    files = _robot_files()
    if not files:
        pytest.skip("example-robot-data is not installed (pip install example-robot-data)")
    compared = 0
    for path in files:
        try:
            model = pin.buildModelFromUrdf(str(path))
            ours = lagrangian.load(path).dynamics(backend="numpy")
        except Exception:  # noqa: BLE001 - refused by either: the dynamics tests judge that
            continue
        if model.nq != model.nv or model.nq != ours.n or \
                [model.names[i] for i in range(1, model.njoints)] != \
                [ours.tree.joints[i].name for i in range(len(ours.tree.joints))]:
            continue
        data = model.createData()
        rng = np.random.default_rng(5)
        q = rng.uniform(-1, 1, (3, model.nq))
        names = [n for n in ours.frames if any(model.existFrame(n, kind) for kind in (
            pin.FrameType.BODY, pin.FrameType.JOINT, pin.FrameType.FIXED_JOINT))]
        for name in names:
            frame_id = _pinocchio_frame(model, name)
            placement, jacobian = ours.placement(q, name), ours.jacobian(q, name)
            for k in range(len(q)):
                pin.forwardKinematics(model, data, q[k])
                pin.updateFramePlacements(model, data)
                pin.computeJointJacobians(model, data, q[k])
                np.testing.assert_allclose(placement[k], data.oMf[frame_id].homogeneous,
                                           atol=1e-10, err_msg=f"{path.name} {name}")
                np.testing.assert_allclose(
                    jacobian[k], pin.getFrameJacobian(model, data, frame_id,
                                                      pin.ReferenceFrame.LOCAL_WORLD_ALIGNED),
                    atol=1e-10, err_msg=f"{path.name} {name}")
        if ours.kinematics.mass() > 0:
            centre = ours.center_of_mass(q)
            for k in range(len(q)):
                np.testing.assert_allclose(centre[k], pin.centerOfMass(model, data, q[k]),
                                           atol=1e-10, err_msg=path.name)
        compared += 1
    print(f"{compared} robots compared")
    assert compared >= 5, f"only {compared} robots compared"
