"""Frames, Jacobians and the centre of mass of a model file's points and bodies (not a URDF tree),
from the model's own expressions, batched over states, in the conventions of frames.py
(4 x 4 placements, 6 x n Jacobians with the linear rows first, references WORLD, LOCAL and
LOCAL_WORLD_ALIGNED).

A frame is a named particle (its position, axes the world's), a planar body (its centre of mass,
turned by its angle about z) or a rigid body in space (its body frame: origin and rotation R).
Each frame's expressions are made once, on first use, with the parameters put in: the linear
rows J_v = dp/dq, the angular rows J_w = d(omega)/d(q_dot) (omega = R omega_body, linear in
q_dot), and J_dot q_dot = (d(J q_dot)/dq) q_dot; then compiled by the package's one lambdify.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import sympy as sp

from ..compile.lambdified import StateFunction
from ..derivation.kinematics import Differentiator
from ..errors import InputError, did_you_mean_or_list
from ..model.model import Body, Model, Particle
from ..model.rotations import apply
from .algorithms.frames import check_reference, expressed
from .tree.numbers import batch_shape, float_array

_ZERO = sp.S.Zero


def _three(vector) -> list[sp.Expr]:
    """A position of 2 or 3 components as 3 (a planar model's z = 0)."""
    items = [sp.sympify(x) for x in vector]  # safe: the model's own sympy objects and numbers
    return items + [_ZERO] * (3 - len(items))


class _Frame:
    """One frame's symbolic pose (R, p) and angular velocity (world axes), parameters put in."""

    def __init__(self, rotation, origin, omega):
        self.rotation, self.origin, self.omega = rotation, origin, omega
        self.pose: StateFunction | None = None  # R (9), p (3), J (6 n), compiled on first use
        self.drift: StateFunction | None = None  # J_dot q_dot (6)


class ModelKinematics:
    """Placements, frame Jacobians and the centre of mass of a model file's particles, planar
    bodies and rigid bodies (SI units). Every function takes q of shape (n,) or (..., n) and
    keeps the batch shape in front."""

    def __init__(self, model: Model, parameters: Mapping[str, float]):
        self.model = model
        self.coordinates = tuple(c.name for c in model.coordinates)
        self.n = len(self.coordinates)
        self._values = {p.symbol: sp.Float(parameters[p.name]) for p in model.parameters
                        if parameters.get(p.name) is not None}
        self._d = Differentiator()
        self._frames: dict[str, _Frame | None] = {}
        self._sources: dict[str, object] = {}
        for component in (*model.particles, *model.bodies, *model.rigid_bodies):
            self._sources.setdefault(component.name, component)
        self._centre: StateFunction | None = None
        self._momentum = None  # (StateFunction, parts) of centroidal_momentum_matrix

    @property
    def frames(self) -> tuple[str, ...]:
        """The names of every particle, planar body and rigid body, in the model's order."""
        return tuple(self._sources)

    def _put(self, expr) -> sp.Expr:
        return sp.sympify(expr).xreplace(self._values)  # safe: a model expression, not text

    def _q(self, q, field: str = "q") -> tuple[np.ndarray, tuple[int, ...]]:
        q = float_array(q, field)
        if q.ndim == 0 or q.shape[-1] != self.n:
            shape = "()" if q.ndim == 0 else str(q.shape)
            raise InputError(f"expected {self.n} values ({', '.join(self.coordinates)}) along the "
                             f"last axis, got shape {shape}", field=field)
        return q.reshape(-1, self.n), q.shape[:-1]

    def _no_time(self, exprs, what: str, field: str = "frame") -> None:
        if any(self.model.time in sp.sympify(e).free_symbols  # safe: model expressions
               for e in exprs):
            raise InputError(f"{what} moves with t (a prescribed motion): frames and Jacobians "
                             "of a model file are for q alone; not yet", field=field)

    def _frame(self, name: str) -> _Frame:
        if not isinstance(name, str):  # (a list would not even hash)
            raise InputError(f"a frame is named by a string, not a {type(name).__name__}",
                             field="frame")
        if name not in self._sources:
            raise InputError(f"no frame named '{name}'{did_you_mean_or_list(name, self._sources)}",
                             field="frame")
        found = self._frames.get(name)
        if found is None:
            found = self._frames[name] = self._symbolic(self._sources[name])
        return found

    def _symbolic(self, component) -> _Frame:
        if isinstance(component, Particle):
            rotation = sp.eye(3)
            origin = _three(component.position)
            omega = [_ZERO] * 3
        elif isinstance(component, Body):  # turned by its angle about z
            c, s = sp.cos(component.angle), sp.sin(component.angle)
            rotation = sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])
            origin = _three(component.position)
            omega = [_ZERO, _ZERO, self._d.rate(component.angle, self.model.q,
                                                self.model.q_dot, self.model.time)]
        else:  # a rigid body in space: its body frame
            rotation = sp.Matrix(component.rotation)
            origin = list(component.origin)
            omega = list(apply(component.rotation, component.angular_velocity))
        rotation = rotation.applyfunc(self._put)
        origin, omega = [self._put(x) for x in origin], [self._put(x) for x in omega]
        self._no_time([*rotation, *origin, *omega], f"frame '{component.name}'")
        return _Frame(rotation, origin, omega)

    def _jacobian_exprs(self, frame: _Frame) -> list[sp.Expr]:
        """J (6 x n, row-major) at the frame's origin, world axes."""
        d, q, q_dot = self._d, self.model.q, self.model.q_dot
        linear = [d.row(x, q) for x in frame.origin]
        angular = [d.row(w, q_dot) for w in frame.omega]
        return [x for row in (*linear, *angular) for x in row]

    def _pose(self, Q: np.ndarray, name: str):
        """R (N, 3, 3), p (N, 3) and J (N, 6, n: local_world_aligned) of a frame."""
        frame = self._frame(name)
        if frame.pose is None:
            frame.pose = StateFunction(self.model, [*frame.rotation, *frame.origin,
                                                    *self._jacobian_exprs(frame)])
        values = frame.pose(Q, np.zeros_like(Q), 0.0)
        count = len(Q)
        return (values[:, :9].reshape(count, 3, 3), values[:, 9:12],
                values[:, 12:].reshape(count, 6, self.n))

    def placement(self, q, frame: str) -> np.ndarray:
        """The frame's placement in the world: [[R, p], [0, 1]] (R frame -> world axes, p its
        origin in m), shape (..., 4, 4)."""
        Q, batch = self._q(q)
        R, p, _ = self._pose(Q, frame)
        out = np.zeros((len(Q), 4, 4))
        out[:, :3, :3], out[:, :3, 3], out[:, 3, 3] = R, p, 1.0
        return out.reshape(batch + (4, 4))

    def jacobian(self, q, frame: str, reference: str = "local_world_aligned") -> np.ndarray:
        """J with [v; w] = J q_dot for the frame, shape (..., 6, n), references as frames.py's
        TreeKinematics.jacobian (m/s and rad/s per unit rate)."""
        check_reference(reference)
        Q, batch = self._q(q)
        R, p, J = self._pose(Q, frame)
        return expressed(J, R, p, reference).reshape(batch + (6, self.n))

    def jacobian_dot_times_v(self, q, v, frame: str,
                             reference: str = "local_world_aligned") -> np.ndarray:
        """J_dot q_dot: the frame's classical acceleration at q_ddot = 0, [a; w_dot] (m/s^2,
        rad/s^2), shape (..., 6), ``reference`` as for jacobian."""
        check_reference(reference)
        q, v = float_array(q, "q"), float_array(v, "v")
        self._q(q), self._q(v, "v")
        batch = batch_shape((q, v), ("q", "v"))
        Q = np.broadcast_to(q, batch + (self.n,)).reshape(-1, self.n)
        V = np.broadcast_to(v, batch + (self.n,)).reshape(-1, self.n)
        found = self._frame(frame)
        if found.drift is None:
            d, m = self._d, self.model
            rates = [sum((a * b for a, b in zip(d.row(x, m.q), m.q_dot, strict=True)), _ZERO)
                     for x in found.origin]
            exprs = [d.rate(x, m.q, m.q_dot, m.time) for x in (*rates, *found.omega)]
            found.drift = StateFunction(m, exprs)
        R, p, J = self._pose(Q, frame)
        drift = found.drift(Q, V, 0.0)
        a, w_dot = drift[:, :3], drift[:, 3:]
        if reference == "local":
            Rt = np.swapaxes(R, -1, -2)
            a, w_dot = (Rt @ a[..., None])[..., 0], (Rt @ w_dot[..., None])[..., 0]
        elif reference == "world":  # the point at the world's origin: a - w_dot x p - w x (w x p)
            w = (J[:, 3:] @ V[..., None])[..., 0]
            a = a - np.cross(w_dot, p) - np.cross(w, np.cross(w, p))
        return np.concatenate([a, w_dot], axis=1).reshape(batch + (6,))

    # -- centre of mass -------------------------------------------------------------------------

    def _masses(self) -> list[tuple[sp.Expr, list[sp.Expr]]]:
        return [(self._put(c.mass), [self._put(x) for x in _three(c.position)])
                for c in (*self.model.particles, *self.model.bodies, *self.model.rigid_bodies)]

    def mass(self) -> float:
        """The total mass of the particles and bodies (kg)."""
        return float(sum((m for m, _ in self._masses()), _ZERO))

    def _centre_values(self, Q: np.ndarray) -> np.ndarray:
        """(N, 3 + 3 n): the centre of mass and its Jacobian (row-major)."""
        if self._centre is None:
            masses = self._masses()
            total = sum((m for m, _ in masses), _ZERO)
            if not (total.is_number and float(total) > 0):
                raise InputError("the model's particles and bodies have no mass: no centre "
                                 "of mass", field="q")
            centre = [sum((m * r[i] for m, r in masses), _ZERO) / total for i in range(3)]
            self._no_time(centre, "the centre of mass", "q")
            rows = [x for c in centre for x in self._d.row(c, self.model.q)]
            self._centre = StateFunction(self.model, [*centre, *rows])
        return self._centre(Q, np.zeros_like(Q), 0.0)

    def center_of_mass(self, q) -> np.ndarray:
        """The centre of mass of the particles and bodies in the world (m), shape (..., 3)."""
        Q, batch = self._q(q)
        return self._centre_values(Q)[:, :3].reshape(batch + (3,))

    def center_of_mass_jacobian(self, q) -> np.ndarray:
        """J_c with c_dot = J_c q_dot (m per unit rate), shape (..., 3, n)."""
        Q, batch = self._q(q)
        return self._centre_values(Q)[:, 3:].reshape(batch + (3, self.n))

    def centroidal_momentum_matrix(self, q) -> np.ndarray:
        """A_g with h_g = A_g q_dot, shape (..., 6, n): linear momentum sum m J_r (kg m/s per
        unit rate), then angular momentum about the centre of mass c, world axes:
        sum m (r - c) x J_r, plus I J_w of each body (I about its centre: a planar body's
        about z, a rigid body's R I_body R^T)."""
        Q, batch = self._q(q)
        count, n = len(Q), self.n
        if self._momentum is None:
            self._momentum = self._momentum_parts()
        function, parts = self._momentum
        values = function(Q, np.zeros_like(Q), 0.0)
        total = sum(m for m, *_ in parts)
        if not total > 0:
            raise InputError("the model's particles and bodies have no mass: no centroidal "
                             "momentum", field="q")
        centre = np.zeros((count, 3))
        rows = []
        at = 0
        for m, kind, inertia in parts:
            r, J = values[:, at:at + 3], values[:, at + 3:at + 3 + 3 * n].reshape(count, 3, n)
            at += 3 + 3 * n
            centre += m * r
            turn = None
            if kind == "planar":  # I about z times d(angle)/dq
                turn = np.zeros((count, 3, n))
                turn[:, 2] = inertia * values[:, at:at + n]
                at += n
            elif kind == "rigid":  # R I R^T J_w (world axes)
                R = values[:, at:at + 9].reshape(count, 3, 3)
                Jw = values[:, at + 9:at + 9 + 3 * n].reshape(count, 3, n)
                at += 9 + 3 * n
                turn = R @ inertia @ np.swapaxes(R, -1, -2) @ Jw
            rows.append((m, r, J, turn))
        centre /= total
        A = np.zeros((count, 6, n))
        for m, r, J, turn in rows:
            A[:, :3] += m * J
            A[:, 3:] += m * np.cross((r - centre)[:, :, None], J, axisa=1, axisb=1, axisc=1)
            if turn is not None:
                A[:, 3:] += turn
        return A.reshape(batch + (6, n))

    def _momentum_parts(self):
        """One function of q giving, per massive component, r (3) and J_r (3 n); a planar
        body's d(angle)/dq (n), a rigid body's R (9) and J_w (3 n, world); and per component
        (mass, kind, inertia) in numbers (kg, kg m^2)."""
        d, q, q_dot = self._d, self.model.q, self.model.q_dot
        exprs, parts = [], []
        for c in (*self.model.particles, *self.model.bodies, *self.model.rigid_bodies):
            r = [self._put(x) for x in _three(c.position)]
            exprs += [*r, *(x for row in (d.row(x, q) for x in r) for x in row)]
            if isinstance(c, Particle):
                parts.append((float(self._put(c.mass)), "point", None))
            elif isinstance(c, Body):
                exprs += d.row(self._put(c.angle), q)
                parts.append((float(self._put(c.mass)), "planar", float(self._put(c.inertia))))
            else:
                frame = self._frame(c.name)
                exprs += [*frame.rotation,
                          *(x for row in (d.row(w, q_dot) for w in frame.omega) for x in row)]
                inertia = np.array([[float(self._put(x)) for x in row] for row in c.inertia])
                parts.append((float(self._put(c.mass)), "rigid", inertia))
        self._no_time(exprs, "the centroidal momentum", "q")
        return StateFunction(self.model, exprs), parts


def model_frames_apply(model: Model) -> bool:
    """Whether the model's frames are its own points and bodies: a model file's, not a URDF
    robot's (whose frames are its tree's, frames.py)."""
    return model.kinematic_tree is None and bool(model.particles or model.bodies
                                                 or model.rigid_bodies)


__all__ = ["ModelKinematics", "model_frames_apply"]
