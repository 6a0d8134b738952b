"""The state of a robot's tree where q and v differ in length (simulation/floating.py steps it):
a floating base's 7 numbers (x y z, then a unit quaternion x y z w) and twist (6), each ball
joint's unit quaternion (w x y z, MuJoCo's order, 4 numbers) and angular velocity in the body's
own axes (3, rad/s), each free flyer below the root's 7 (<joint>_x, _y, _z in m, then qx qy qz
qw) and 6 (the child's linear then angular velocity relative to its parent, in its own axes);
every other joint one angle (rad) or length (m) and its rate.

q_dot from v: the base's and a free flyer's position by R(quat) v_lin (floating.base_rate), a
joint's its own rate; every joint's quaternion is stepped on the sphere of rotations
(BallCharts: q = c (x) exp(d), the solver's three numbers d a turn from a centre c). The joints'
numbers are also read in the model's coordinates (``joints_q``, ``joints_v``: a ball's three
Euler hinges and a free flyer's six there read 0), where the position limits, the loads and the
stop condition live.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np

from ..errors import InputError, ModelError, did_you_mean
from ..model.values import resolve_state

BASE_START = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)  # at the origin, unturned
BALL_START = (1.0, 0.0, 0.0, 0.0)  # w x y z: the joint's reference orientation
FREE_START = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0)  # at the joint's origin, unturned (x y z w)
FREE_Q = ("x", "y", "z", "qx", "qy", "qz", "qw")
FREE_V = ("vx", "vy", "vz", "wx", "wy", "wz")
FREE_MODEL = ("x", "y", "z", "roll", "pitch", "yaw")  # its six in the model's coordinates
FREE_TURNS = FREE_MODEL[3:]


class TreeState:
    """Where each joint's numbers sit in q (nq) and v (nv), from the dynamics' names."""

    def __init__(self, dynamics, model):
        tree = model.kinematic_tree
        self.q_names, self.v_names = tuple(dynamics.coordinates), tuple(dynamics.velocity_names)
        self.nq, self.nv = len(self.q_names), len(self.v_names)
        self.floating = tree.floating_base
        # each ball: (name, q index of its w, v index of its omega_x)
        self.balls = tuple((j.name, tree.base_nq + j.coordinate,
                            tree.base_nv + tree.velocity_index(j.coordinate))
                           for j in tree.spherical)
        self.mujoco_free = tree.mujoco_free  # MJCF free joints: balls at the end of world slides
        self.base_q = self.q_names[:tree.base_nq]
        self.base_v = self.v_names[:tree.base_nv]
        self.ball_q = {n for name, iq, _ in self.balls for n in self.q_names[iq:iq + 4]}
        self.ball_v = {n for name, _, iv in self.balls for n in self.v_names[iv:iv + 3]}
        # each free flyer below the root: (name, q index of its x, v index of its vx)
        self.free = tuple((j.name, tree.base_nq + j.coordinate,
                           tree.base_nv + tree.velocity_index(j.coordinate))
                          for j in tree.free_joints)
        self.free_q = {n for _, iq, _ in self.free for n in self.q_names[iq:iq + 7]}
        self.free_v = {n for _, _, iv in self.free for n in self.v_names[iv:iv + 6]}
        # its model coordinates (x y z roll pitch yaw): not the state's, read 0 in joints_q
        self.free_model = {f"{name}_{s}": name for name, *_ in self.free for s in FREE_MODEL}
        # the model's coordinates, and where each of the tree's own is in q and in v
        coordinates = [c.name for c in model.coordinates]
        self.n = len(coordinates)
        pairs = [(i, self.q_names.index(name), self.v_names.index(name))
                 for i, name in enumerate(coordinates)
                 if name in self.q_names and name not in self.free_model]
        self.model_index = np.array([p[0] for p in pairs], dtype=int)
        self.q_index = np.array([p[1] for p in pairs], dtype=int)
        self.v_index = np.array([p[2] for p in pairs], dtype=int)
        placed = {*self.base_q, *self.ball_q, *self.free_q,
                  *(self.q_names[i] for i in self.q_index)}
        stray = [name for name in self.q_names if name not in placed]
        if stray:  # every number is stepped by one rule: none may be left out
            raise ModelError(f"simulate cannot place the tree's coordinate '{stray[0]}' among "
                             "the model's coordinates (not yet)", field="joint")
        # a ball's Euler hinges (MJCF: <ball>__x, __y, __z): the model's, not the state's
        self.hinges = {name: ball for ball, *_ in self.balls
                       for name in coordinates if name.startswith(f"{ball}__")}

    def joints_q(self, q: np.ndarray) -> np.ndarray:
        """The model's coordinates (..., n) from q (..., nq): a ball's hinges 0."""
        out = np.zeros(q.shape[:-1] + (self.n,))
        out[..., self.model_index] = q[..., self.q_index]
        return out

    def joints_v(self, v: np.ndarray) -> np.ndarray:
        """The model's coordinate rates (..., n) from v (..., nv): a ball's hinges 0."""
        out = np.zeros(v.shape[:-1] + (self.n,))
        out[..., self.model_index] = v[..., self.v_index]
        return out

    def on_joints(self, forces: np.ndarray) -> np.ndarray:
        """Generalized forces on the model's coordinates (n) as v's entries (nv)."""
        out = np.zeros(self.nv)
        out[self.v_index] = forces[self.model_index]
        return out

    def unit(self, q: np.ndarray) -> np.ndarray:
        """q with the base's, each ball's and each free flyer's quaternion scaled to norm 1,
        in place."""
        if self.floating:
            q[3:7] /= np.linalg.norm(q[3:7])
        for _, iq, _ in self.balls:
            q[iq:iq + 4] /= np.linalg.norm(q[iq:iq + 4])
        for _, iq, _ in self.free:
            q[iq + 3:iq + 7] /= np.linalg.norm(q[iq + 3:iq + 7])
        return q

    def refuse_hinge(self, name: str, field: str) -> None:
        """One line for a ball's Euler hinge, a free flyer's rpy angle or a rate of its x y z
        (or their rates) named where the state's numbers are wanted."""
        stem = name.removesuffix("_dot")
        free = self.free_model.get(stem)
        if free is not None and (stem != name or stem.rsplit("_", 1)[1] in FREE_TURNS):
            q = ", ".join(f"{free}_{s}" for s in FREE_Q)
            v = ", ".join(f"{free}_{s}" for s in FREE_V)
            raise InputError(
                f"'{name}' is not a number of the run's state for the floating joint '{free}': "
                f"give its position and unit quaternion {q} (m; x y z w) and its velocity {v} "
                "(m/s, rad/s; the child's relative to its parent, in its own axes)", field=field)
        ball = self.hinges.get(name, self.hinges.get(stem))
        if ball is not None:
            raise InputError(
                f"'{name}' is an Euler angle of the ball joint '{ball}', which the run does not "
                f"step: give its quaternion {ball}_qw, {ball}_qx, {ball}_qy, {ball}_qz (w x y z, "
                f"unit) and its angular velocity {ball}_wx, {ball}_wy, {ball}_wz (rad/s, body "
                "axes)", field=field)

    def start(self, model, initial: Mapping[str, object] | None
              ) -> tuple[float, np.ndarray, np.ndarray]:
        """(t0, q0, v0) from ``initial``: the base's and the balls' numbers by their names
        (default at the origin, unturned, at rest), a free flyer's likewise (<joint>_x ..
        _qw, <joint>_vx .. _wz; default at its joint's origin, unturned, at rest), the other
        joints' as for a fixed base
        (<joint>, <joint>_dot; default the model's initial values), SI; a quaternion off unit
        norm refused in one line naming it."""
        from ..model.units import parse_quantity
        from ..model.values import State

        if isinstance(initial, State):  # a run's last_state: the tree's own layout, or refused
            if initial.coordinates != self.q_names or len(initial.q_dot) != self.nv:
                raise InputError(f"the state's coordinates {list(initial.coordinates)} are not "
                                 f"this robot's {list(self.q_names)}", field="initial")
            q0 = initial.q_array()
            self.check_unit(q0, "initial")
            return float(initial.t), self.unit(q0), initial.q_dot_array()
        given = dict(initial or {})
        own = dict(zip(self.base_q, BASE_START if self.floating else (), strict=True))
        for _, iq, _ in self.balls:
            own.update(zip(self.q_names[iq:iq + 4], BALL_START, strict=True))
        for _, iq, _ in self.free:
            own.update(zip(self.q_names[iq:iq + 7], FREE_START, strict=True))
        own.update(dict.fromkeys((*self.base_v, *self.ball_v, *self.free_v), 0.0))
        units = self.units()
        joints = {}
        for name, value in given.items():
            if name not in own:
                self.refuse_hinge(name, f"initial.{name}")
                joints[name] = value
                continue
            try:
                own[name] = parse_quantity(value, units[name], f"initial.{name}") \
                    if isinstance(value, str) else float(value)
            except (TypeError, ValueError):
                raise InputError(f"{name}: {value!r} is not a number (SI units)",
                                 field="initial") from None
        try:
            start = resolve_state(model, joints, field="initial",
                                  what="coordinate or velocity (or t)")
        except (InputError, ModelError):
            known = [*self.q_names, *self.v_names, "t"]
            unknown = next((k for k in joints if k != "t" and k not in known
                            and k.removesuffix("_dot") not in known), None)
            if unknown is None:
                raise
            raise InputError(f"'{unknown}' is not a coordinate or velocity of this robot"
                             f"{did_you_mean(unknown, known)}", field="initial") from None
        q_model, v_model = start.q_array(), start.q_dot_array()
        q0 = np.array([own.get(name, 0.0) for name in self.q_names], dtype=float)
        v0 = np.array([own.get(name, 0.0) for name in self.v_names], dtype=float)
        q0[self.q_index] = q_model[self.model_index]
        v0[self.v_index] = v_model[self.model_index]
        self.check_unit(q0, "initial")
        return start.t, self.unit(q0), v0

    def units(self) -> dict[str, str]:
        """The unit of each base, ball and free flyer number (a quaternion's: 1)."""
        out = {}
        if self.floating:
            out.update(zip(self.base_q, ("m",) * 3 + ("1",) * 4, strict=True))
            out.update(zip(self.base_v, ("m/s",) * 3 + ("rad/s",) * 3, strict=True))
        out.update({**dict.fromkeys(self.ball_q, "1"), **dict.fromkeys(self.ball_v, "rad/s")})
        for _, iq, iv in self.free:
            out.update(zip(self.q_names[iq:iq + 7], ("m",) * 3 + ("1",) * 4, strict=True))
            out.update(zip(self.v_names[iv:iv + 6], ("m/s",) * 3 + ("rad/s",) * 3, strict=True))
        return out

    def check_unit(self, q: np.ndarray, field: str) -> None:
        """Refuse a base, ball or free flyer quaternion whose norm is off 1 by more than the
        tolerance."""
        from ..model.quaternions import QUATERNION_TOLERANCE, check_quaternions

        if self.floating:
            check_quaternions(q[None], field=field)
        quaternions = [("free" if name in self.mujoco_free else "ball", name, iq)
                       for name, iq, _ in self.balls] \
            + [("floating", name, iq + 3) for name, iq, _ in self.free]
        for kind, name, iq in quaternions:
            norm = float(np.linalg.norm(q[iq:iq + 4]))
            if not abs(norm - 1.0) <= QUATERNION_TOLERANCE:
                raise InputError(
                    f"the {kind} joint '{name}' quaternion "
                    f"({', '.join(self.q_names[iq:iq + 4])}) has norm {norm:.9g}; a unit "
                    f"quaternion is needed (|q| within {QUATERNION_TOLERANCE:g} of 1)",
                    field=field)


# A ball's chart moves to where the ball is once it has turned this far from the chart's
# centre (rad): J_r^-1 stays near 1 (it is singular at 2 pi), the restart is rare.
RECENTRE = 1.0


class BallCharts:
    """The integrator's configuration z: q with each joint quaternion q_b (a ball's, w x y z; a
    free flyer's below the root, x y z w) replaced by a turn d (3 numbers, rad, in the body's
    axes) from a centre c, q_b = c (x) exp(d) (q (+) d, as MuJoCo's mj_integratePos), so q_b
    stays on the unit sphere; d_dot = J_r(d)^-1 omega. The other numbers (the base's seven, a
    free flyer's x y z, the joints') are z's as they are in q."""

    def __init__(self, state: TreeState, q0: np.ndarray):
        self.state = state
        # each joint quaternion: q index of its first number -> (v index of omega_x, w last)
        starts = {iq: (iv, False) for _, iq, iv in state.balls}
        starts.update({iq + 3: (iv + 3, True) for _, iq, iv in state.free})
        kept_q, kept_z, self.balls = [], [], []  # balls: (q index, z index, v index)
        i = z = 0
        while i < state.nq:
            if i in starts:
                self.balls.append((i, z, starts[i][0]))
                i, z = i + 4, z + 3
            else:
                kept_q.append(i)
                kept_z.append(z)
                i, z = i + 1, z + 1
        self.nz = z
        self.kept_q, self.kept_z = np.array(kept_q, dtype=int), np.array(kept_z, dtype=int)
        # the charts hold w first; a free flyer's quaternion is read and written x y z w
        self.w_last = {iq for iq, (_, last) in starts.items() if last}
        self.centres = {iq: self._read(q0, iq) for iq, _, _ in self.balls}

    def _read(self, q: np.ndarray, iq: int) -> np.ndarray:
        """The joint quaternion at q[iq:iq + 4], w first, normalized."""
        c = q[iq:iq + 4]
        c = np.r_[c[3], c[:3]] if iq in self.w_last else np.array(c, dtype=float)
        return c / np.linalg.norm(c)

    def z0(self, q0: np.ndarray) -> np.ndarray:
        """z at the centres (every turn 0)."""
        z = np.zeros(self.nz)
        z[self.kept_z] = q0[self.kept_q]
        return z

    def q(self, z: np.ndarray) -> np.ndarray:
        """q (nq) of z: each joint quaternion c (x) exp(d), the base's normalized."""
        if not self.balls:
            return self.state.unit(np.array(z, dtype=float))
        q = np.empty(self.state.nq)
        q[self.kept_q] = z[self.kept_z]
        for iq, iz, _ in self.balls:
            turned = _turned(self.centres[iq], z[iz:iz + 3])
            q[iq:iq + 4] = np.r_[turned[1:], turned[0]] if iq in self.w_last else turned
        if self.state.floating:
            q[3:7] /= np.linalg.norm(q[3:7])
        return q

    def rate(self, z: np.ndarray, v: np.ndarray, rate: np.ndarray) -> np.ndarray:
        """z_dot from q_dot (``rate``, its joint quaternions' entries unused): each one's turn
        rate J_r(d)^-1 w."""
        if not self.balls:
            return rate
        out = np.empty(self.nz)
        out[self.kept_z] = rate[self.kept_q]
        for _, iz, iv in self.balls:
            out[iz:iz + 3] = _inverse_right_jacobian(z[iz:iz + 3], v[iv:iv + 3])
        return out

    def recentre(self, z: np.ndarray) -> bool:
        """Move every chart to its joint's place (z's turns 0) where one has turned past
        RECENTRE, in place; whether it did (the solver then starts again from z)."""
        if not any(np.linalg.norm(z[iz:iz + 3]) > RECENTRE for _, iz, _ in self.balls):
            return False
        for iq, iz, _ in self.balls:
            self.centres[iq] = _turned(self.centres[iq], z[iz:iz + 3])
            z[iz:iz + 3] = 0.0
        return True


def _turned(c: np.ndarray, d: np.ndarray) -> np.ndarray:
    """c (x) exp(d), w first, normalized (d in rad, about the body's axes)."""
    dx, dy, dz = (float(x) for x in d)
    angle = math.sqrt(dx * dx + dy * dy + dz * dz)
    half = 0.5 * angle
    # sin(angle/2)/angle, its series where the angle is tiny (no 0/0)
    k = 0.5 - angle * angle / 48 if angle < 1e-4 else math.sin(half) / angle
    ew, ex, ey, ez = math.cos(half), k * dx, k * dy, k * dz
    aw, ax, ay, az = (float(x) for x in c)
    out = np.array([aw * ew - ax * ex - ay * ey - az * ez, aw * ex + ax * ew + ay * ez - az * ey,
                    aw * ey - ax * ez + ay * ew + az * ex, aw * ez + ax * ey - ay * ex + az * ew])
    return out / math.sqrt(float(out @ out))


def _inverse_right_jacobian(d: np.ndarray, w: np.ndarray) -> np.ndarray:
    """J_r(d)^-1 w = w + 1/2 d x w + (1/a^2 - (1 + cos a)/(2 a sin a)) d x (d x w), a = |d|:
    the rate of the turn d whose body angular velocity is w (rad/s)."""
    dx, dy, dz = (float(x) for x in d)
    wx, wy, wz = (float(x) for x in w)
    a2 = dx * dx + dy * dy + dz * dz
    if a2 < 1e-8:  # the factor's series: 1/12 + a^2/720
        factor = 1.0 / 12 + a2 / 720
    else:
        a = math.sqrt(a2)
        factor = 1.0 / a2 - (1.0 + math.cos(a)) / (2.0 * a * math.sin(a))
    # written out: numpy's cross costs ten times the rest of a right-hand side here
    cx, cy, cz = dy * wz - dz * wy, dz * wx - dx * wz, dx * wy - dy * wx
    return np.array([wx + 0.5 * cx + factor * (dy * cz - dz * cy),
                     wy + 0.5 * cy + factor * (dz * cx - dx * cz),
                     wz + 0.5 * cz + factor * (dx * cy - dy * cx)])


def drawing_coordinates(model, t: np.ndarray, q: np.ndarray, v: np.ndarray):
    """The model's coordinates and rates (N, n) of a fixed-base run with ball joints or free
    flyers below the root (t, q, v at its samples): each ball's quaternion as its three Euler
    hinges <ball>__x, __y, __z (R(q) = Rx Ry Rz, model/mjcf_ball.py's chain), a free flyer's as
    its x, y, z and <joint>_roll, _pitch, _yaw (R(q) = Rz Ry Rx, the URDF's rpy), unwrapped,
    their rates by differences; the other joints as they are. None for a floating base (the
    model's bodies hold no base)."""
    tree = model.kinematic_tree
    if tree is None or tree.floating_base:
        return None
    names = [c.name for c in model.coordinates]
    velocities = tree.velocity_coordinates
    out_q, out_v = np.zeros((len(q), len(names))), np.zeros((len(q), len(names)))
    free = {f"{j.name}_{s}" for j in tree.free_joints for s in FREE_MODEL}
    for k, name in enumerate(names):
        if name in tree.coordinates and name not in free:
            out_q[:, k] = q[:, tree.coordinates.index(name)]
            out_v[:, k] = v[:, velocities.index(name)]
    for joint in tree.spherical:
        w, x, y, z = (q[:, joint.coordinate + i] for i in range(4))
        angles = np.unwrap(np.stack([  # Rx(a) Ry(b) Rz(c): R02 = sin b, R12, R22, R01, R00
            np.arctan2(-2 * (y * z - x * w), 1 - 2 * (x * x + y * y)),
            np.arcsin(np.clip(2 * (x * z + y * w), -1.0, 1.0)),
            np.arctan2(-2 * (x * y - z * w), 1 - 2 * (y * y + z * z))], -1), axis=0)
        for i, axis in enumerate("xyz"):
            k = names.index(f"{joint.name}__{axis}")
            out_q[:, k] = angles[:, i]
            out_v[:, k] = np.gradient(angles[:, i], t) if len(t) > 1 else 0.0
    for joint in tree.free_joints:
        x, y, z, w = (q[:, joint.coordinate + i] for i in range(3, 7))
        angles = np.unwrap(np.stack([  # Rz(yaw) Ry(pitch) Rx(roll): R21, R22, R20, R10, R00
            np.arctan2(2 * (y * z + x * w), 1 - 2 * (x * x + y * y)),
            np.arcsin(np.clip(-2 * (x * z - y * w), -1.0, 1.0)),
            np.arctan2(2 * (x * y + z * w), 1 - 2 * (y * y + z * z))], -1), axis=0)
        numbers = np.column_stack([q[:, joint.coordinate + i] for i in range(3)] + [angles])
        for i, axis in enumerate(FREE_MODEL):
            k = names.index(f"{joint.name}_{axis}")
            out_q[:, k] = numbers[:, i]
            out_v[:, k] = np.gradient(numbers[:, i], t) if len(t) > 1 else 0.0
    return out_q, out_v


__all__ = ["BALL_START", "BASE_START", "RECENTRE", "BallCharts", "TreeState",
           "drawing_coordinates"]
