"""Frames, Jacobians and the centre of mass of a robot's kinematic tree, batched over states
(Pinocchio's conventions: 4 x 4 placements in the world, 6 x n Jacobians with the linear rows
first, and the three reference frames WORLD, LOCAL and LOCAL_WORLD_ALIGNED).

Built on the joint models (joint_models.py): a joint moves its body by the motion subspace
S = (s_w, s_v) per unit of joint variable, so the Jacobian's column of a coordinate is, summed
over the joints it drives (theta = k q + offset), k times S carried to the frame:
angular s_w and linear s_v + s_w x (p - o), in world axes (p the frame's origin, o the joint's).
A floating base (free_flyer.py) takes q of nq = n + 7 and gives Jacobians of nv = n + 6 columns:
its six first, S = 1 in the base's axes; a free flyer below the root has seven numbers in q
(x y z qx qy qz qw) and six columns of its own. A ball joint (tree/spherical.py) has four numbers in q
(its quaternion w x y z) and three columns: S = 1 on the angular rows, in its body's axes.
"""

from __future__ import annotations

import numpy as np

from ...errors import InputError, did_you_mean_or_list
from ...kinds import JointKind
from ...model.tree import KinematicTree
from ..tree.free_flyer import BASE_CONFIGURATION, check_quaternions
from ..tree.joint_models import joint_model
from ..tree.numbers import float_array
from ..tree.spherical import check_tree_quaternions
from .centroidal import REFERENCES, check_reference


class TreeKinematics:
    """Placements, frame Jacobians and the centre of mass of a kinematic tree (SI units).

    Every function takes q of shape (n,) or (..., n) and keeps the batch shape in front."""

    def __init__(self, tree: KinematicTree):
        self.tree = tree
        self.n = tree.nv  # the velocity's numbers (Jacobian columns)
        self.coordinates = (BASE_CONFIGURATION if tree.floating_base else ()) + tree.coordinates
        self._frames = {f.name: f for f in tree.frames}
        self._models = [joint_model(j.kind) for j in tree.joints]

    @property
    def frames(self) -> tuple[str, ...]:
        """The names of every link and joint frame, in the URDF's order."""
        return tuple(self._frames)

    # -- placements -----------------------------------------------------------------------------

    def _q(self, q, field: str = "q") -> tuple[np.ndarray, tuple[int, ...]]:
        q = float_array(q, field)
        nq = len(self.coordinates)
        if q.ndim == 0 or q.shape[-1] != nq:
            shape = "()" if q.ndim == 0 else str(q.shape)
            raise InputError(f"expected {nq} values ({', '.join(self.coordinates)}) along the "
                             f"last axis, got shape {shape}", field=field)
        batch = q.shape[:-1]
        if self.tree.quaternion_joints:  # the base's and each ball's or free flyer's, in one line
            check_tree_quaternions(self.tree, q.reshape(-1, nq), field)
        elif self.tree.floating_base:
            check_quaternions(q.reshape(-1, nq))
        return q.reshape(-1, nq), batch

    def _bodies(self, Q: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        """Each body's rotation (N, 3, 3: body -> world) and origin (N, 3: m, world)."""
        count = len(Q)
        world = []
        for joint, model in zip(self.tree.joints, self._models, strict=True):
            if joint.kind == JointKind.FREE_FLYER:  # the base's numbers, or its own below the root
                start = 0 if joint.coordinate < 0 else self.tree.base_nq + joint.coordinate
                R, p = model.placement_arrays(np.array(joint.rotation),
                                              np.array(joint.translation),
                                              Q[:, start:start + 7])
            elif joint.kind == JointKind.SPHERICAL:
                start = self.tree.base_nq + joint.coordinate
                R, p = model.placement_arrays(np.array(joint.rotation),
                                              np.array(joint.translation), Q[:, start:start + 4])
            else:
                theta = joint.multiplier * Q[:, self.tree.base_nq + joint.coordinate] + joint.offset
                R, p = model.placement_arrays(np.array(joint.rotation),
                                              np.array(joint.translation), np.array(joint.axis),
                                              theta, joint.pitch)
            R = np.broadcast_to(R, (count, 3, 3))
            p = np.broadcast_to(p, (count, 3))
            if joint.parent < 0:
                world.append((R, p))
            else:
                R_parent, p_parent = world[joint.parent]
                world.append((R_parent @ R, p_parent + np.einsum("nij,nj->ni", R_parent, p)))
        return world

    def _frame(self, name: str):
        if not isinstance(name, str):  # (a list would not even hash)
            raise InputError(f"a frame is named by a string, not a {type(name).__name__}",
                             field="frame")
        if name not in self._frames:
            raise InputError(f"no frame named '{name}'{did_you_mean_or_list(name, self._frames)}",
                             field="frame")
        return self._frames[name]

    def _frame_pose(self, Q, bodies, name: str) -> tuple[np.ndarray, np.ndarray]:
        frame = self._frame(name)
        rotation = np.array(frame.rotation)
        translation = np.array(frame.translation)
        if frame.body < 0:
            count = len(Q)
            return (np.broadcast_to(rotation, (count, 3, 3)),
                    np.broadcast_to(translation, (count, 3)))
        R, p = bodies[frame.body]
        return R @ rotation, p + R @ translation

    def placement(self, q, frame: str) -> np.ndarray:
        """The frame's placement in the world: [[R, p], [0, 1]] (R frame -> world axes, p its
        origin in m), shape (..., 4, 4)."""
        Q, batch = self._q(q)
        R, p = self._frame_pose(Q, self._bodies(Q), frame)
        out = np.zeros((len(Q), 4, 4))
        out[:, :3, :3], out[:, :3, 3], out[:, 3, 3] = R, p, 1.0
        return out.reshape(batch + (4, 4))

    # -- Jacobians ------------------------------------------------------------------------------

    def _ancestors(self, body: int) -> list[int]:
        chain = []
        while body >= 0:
            chain.append(body)
            body = self.tree.joints[body].parent
        return chain

    def _point_jacobian(self, Q, bodies, body: int, point: np.ndarray) -> np.ndarray:
        """(N, 6, n): the linear velocity of the world point ``point`` (N, 3) fixed to ``body``
        and the body's angular velocity, both in world axes, per unit rate of each coordinate."""
        J = np.zeros((len(Q), 6, self.n))
        for k in self._ancestors(body):
            joint = self.tree.joints[k]
            R, o = bodies[k]
            if joint.kind == JointKind.FREE_FLYER:  # six columns, the base's or its own
                columns, first = self._models[k].columns(), 0
                if joint.coordinate >= 0:
                    first = self.tree.base_nv + self.tree.velocity_index(joint.coordinate)
            elif joint.kind == JointKind.SPHERICAL:  # three angular columns, its own axes
                columns = self._models[k].columns()
                first = self.tree.base_nv + self.tree.velocity_index(joint.coordinate)
            else:
                columns = [self._models[k].subspace(joint.axis, joint.pitch)]
                first = self.tree.base_nv + (self.tree.velocity_index(joint.coordinate)
                                             if self.tree.velocities else joint.coordinate)
            for c, (s_w, s_v) in enumerate(columns):
                column = np.zeros((len(Q), 6))
                if s_w is not None:
                    w = R @ np.array(s_w)
                    column[:, 3:] += w
                    column[:, :3] += np.cross(w, point - o)
                if s_v is not None:
                    column[:, :3] += R @ np.array(s_v)
                J[:, :, first + c] += joint.multiplier * column
        return J

    def jacobian(self, q, frame: str, reference: str = "local_world_aligned") -> np.ndarray:
        """J with [v; w] = J q_dot for the frame, shape (..., 6, n): linear rows first (m/s per
        unit rate), then angular (rad/s). ``reference``: "local_world_aligned" (the frame
        origin's velocity and w, in world axes), "local" (the same in the frame's axes) or
        "world" (the velocity of the point at the world's origin moving with the frame)."""
        check_reference(reference)
        Q, batch = self._q(q)
        bodies = self._bodies(Q)
        R, p = self._frame_pose(Q, bodies, frame)
        body = self._frame(frame).body
        if body < 0:
            return np.zeros(batch + (6, self.n))
        J = expressed(self._point_jacobian(Q, bodies, body, p), R, p, reference)
        return J.reshape(batch + (6, self.n))

    # -- centre of mass -------------------------------------------------------------------------

    def mass(self) -> float:
        """The moving bodies' total mass (kg); links welded to the ground are not counted."""
        return float(sum(j.mass for j in self.tree.joints))

    def _moving_mass(self) -> float:
        total = self.mass()
        if total <= 0:
            raise InputError("the robot's moving bodies have no mass: no centre of mass",
                             field="q")
        return total

    def center_of_mass(self, q) -> np.ndarray:
        """The centre of mass of the moving bodies in the world (m), shape (..., 3)."""
        Q, batch = self._q(q)
        bodies, total = self._bodies(Q), self._moving_mass()
        moment = np.zeros((len(Q), 3))
        for joint, (R, p) in zip(self.tree.joints, bodies, strict=True):
            moment += joint.mass * p + R @ np.array(joint.first_moment)
        return (moment / total).reshape(batch + (3,))

    def center_of_mass_jacobian(self, q) -> np.ndarray:
        """J_c with c_dot = J_c q_dot (m per unit rate), shape (..., 3, n)."""
        Q, batch = self._q(q)
        bodies, total = self._bodies(Q), self._moving_mass()
        J = np.zeros((len(Q), 3, self.n))
        for k, (joint, (R, p)) in enumerate(zip(self.tree.joints, bodies, strict=True)):
            if joint.mass <= 0:
                continue
            centre = p + R @ (np.array(joint.first_moment) / joint.mass)
            J += joint.mass * self._point_jacobian(Q, bodies, k, centre)[:, :3]
        return (J / total).reshape(batch + (3, self.n))

    # -- rates: J_dot q_dot and centroidal momentum (centroidal.py) ----------------------------

    def jacobian_dot_times_v(self, q, v, frame: str,
                             reference: str = "local_world_aligned") -> np.ndarray:
        """J_dot q_dot: the frame's classical acceleration at q_ddot = 0, [a; w_dot] (m/s^2,
        rad/s^2), shape (..., 6), ``reference`` as for jacobian (Pinocchio's
        getFrameClassicalAcceleration with a = 0)."""
        from .centroidal import jacobian_dot_times_v

        return jacobian_dot_times_v(self, q, v, frame, reference)

    def centroidal_momentum_matrix(self, q) -> np.ndarray:
        """A_g with h_g = A_g q_dot, shape (..., 6, n): linear momentum, then angular momentum
        about the centre of mass, world axes (Pinocchio's ccrba)."""
        from .centroidal import centroidal_momentum_matrix

        return centroidal_momentum_matrix(self, q)


def expressed(J: np.ndarray, R: np.ndarray, p: np.ndarray, reference: str) -> np.ndarray:
    """A batch of frame Jacobians (N, 6, n) at the origin p in world axes (local_world_aligned)
    expressed in ``reference``: in the frame's axes R (local), or for the point at the world's
    origin moving with the frame (world: v(0) = v(p) + w x (0 - p))."""
    if reference == "local":
        Rt = np.swapaxes(R, -1, -2)
        return np.concatenate([Rt @ J[:, :3], Rt @ J[:, 3:]], axis=1)
    if reference == "world":
        J = J.copy()
        J[:, :3] += np.cross(J[:, 3:], -p[:, :, None], axisa=1, axisb=1, axisc=1)
    return J


def tree_kinematics(tree: KinematicTree | None) -> TreeKinematics:
    """The kinematics of a URDF robot's tree; refused in one line for a model without one (a
    model file's particles and bodies: model_frames.py)."""
    if tree is None or not tree.frames:
        raise InputError("frames, Jacobians and the centre of mass are those of a URDF "
                         "robot's kinematic tree or a model file's particles and bodies; this "
                         "model has neither (energies alone name no point)", field="frame")
    return TreeKinematics(tree)


__all__ = ["REFERENCES", "TreeKinematics", "check_reference", "expressed", "tree_kinematics"]
