"""Rigid-body dynamics in a controller's words: M(q), C(q, q_dot) q_dot + g(q), inverse and
forward dynamics, energies, batched over leading axes.

With the equations M q_ddot = f(q, q_dot) (f holds every force of the model: gravity, springs,
dampers, its loads), a generalized force tau applied on top gives M q_ddot = f + tau, so

    bias b(q, q_dot) = C q_dot + g = -f,   g(q) = -f(q, 0),   tau = M q_ddot + b,
    q_ddot = M^-1 (tau - b).

For a URDF arm the actuator parameters tau_<joint> are 0, so f holds gravity and the velocity
terms only. Units SI (rad or m per coordinate; N m or N for tau; J for energies).

A robot read from URDF (a tree of rigid bodies on revolute, prismatic and fixed joints, nothing
added) is evaluated by recursive algorithms in generated C instead (recursive.py; in numpy,
recursive_numpy.py, without a compiler), without deriving its equations: selection.py's
``model_dynamics`` picks that path wherever it applies.

Batches report, not fail: a state whose inputs are not all finite, or (forward dynamics) whose
M is not positive definite, gives NaN in its own output row; every other row equals the call
for that state alone, and one DynamicsWarning per call counts the states (errors.py).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping
from functools import partial
from typing import TYPE_CHECKING

import numpy as np

from ..compile.functions import NumericSystem
from ..derivation.equations import EquationsOfMotion
from ..errors import DerivationError, DynamicsWarning, InputError, ModelError
from .control_terms import ControlTerms
from .tree.numbers import (
    batch_shape,
    float_array,
    over_finite_rows,
    solve_positive,
    warn_undefined,
)

if TYPE_CHECKING:
    from .model_frames import ModelKinematics


def reported_rows(out, tail: int, stacklevel: int = 4):
    """A compiled function's output, or its (output, count of NaN rows) where there are any
    (the tree and reach modules), ``tail`` the axes of one state's output: then one
    DynamicsWarning; the output."""
    if out.__class__ is not tuple:
        return out
    out, bad = out
    warn_undefined(bad, int(np.prod(out.shape[:out.ndim - tail], dtype=np.int64)),
                   stacklevel=stacklevel)
    return out


def undefined_rows(compute, args, inputs, tail: int, stacklevel: int = 4) -> np.ndarray:
    """compute(*args) over a batch, then NaN in the whole row of each state whose inputs are
    not all finite (inputs: arrays (..., k) of the batch, or one state's (k,) shared by it),
    with one DynamicsWarning counting them: Dynamics._guarded's rule for a function that checks
    its own arguments (a frame's name, a wrench table, named even where no state is finite),
    so it runs on every state and a NaN in one leg, which would leave the other legs' numbers
    finite, is blanked after; the numpy paths' own warnings are folded into that one. A
    function and its arguments, not a closure: a method that makes a closure pays for its
    cells on every call, its compiled path's too (a fifth of a single A_g)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynamicsWarning)
        with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
            out = np.asarray(compute(*args), dtype=float)
    batch = out.shape[:out.ndim - tail]
    good = np.ones(batch, dtype=bool)
    for x in inputs:
        x = np.asarray(x, dtype=float)
        if x.ndim:
            good &= np.broadcast_to(np.isfinite(x).all(axis=-1), batch)
    if not good.all():
        out = np.array(out)
        out[~good] = np.nan
        warn_undefined(int((~good).sum()), good.size, stacklevel=stacklevel)
    return out


def _without_warnings(compute, *arrays):
    """compute(*arrays) with its DynamicsWarnings held back (the caller counts the rows)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynamicsWarning)
        return compute(*arrays)


class Dynamics(ControlTerms):
    """Joint-space dynamics, batched over leading axes (SI units): M(q), the bias
    C(q, q_dot) q_dot + g(q), g(q), inverse and forward dynamics and the energies. The one type
    every path returns: this class evaluates the derived equations (a NumericSystem), and the
    recursive algorithms of a URDF tree (recursive.TreeDynamics, over a backend) are its
    subclass."""

    coordinates: tuple[str, ...]  # the configuration's names (nq of them)
    n: int  # the velocity's numbers: M is n x n (nv; nq = n but for a floating base)
    velocity_names: tuple[str, ...] | None = None  # where they differ from the coordinates

    # whether f's velocity terms are -C(q, q_dot) q_dot of M's Christoffel symbols (a tree's
    # recursions: always; the derived equations: checked once, on first use)
    _christoffel: bool | None = None

    def __init__(self, functions: NumericSystem,
                 equations: Callable[[], EquationsOfMotion] | None = None):
        if functions.m:
            raise ModelError("dynamics in joint space needs a model without constraints "
                             f"(this one has {functions.m}: {', '.join(functions.constraint_names)})")
        self.functions = functions
        self.coordinates = functions.coordinates
        self.n = functions.n
        self._equations = equations

    @property
    def nq(self) -> int:
        """The configuration's numbers (n + 7 for a floating base: its position and quaternion)."""
        return len(self.coordinates)

    @property
    def nv(self) -> int:
        """The velocity's numbers (n + 6 for a floating base: its twist)."""
        return self.n

    def _width(self, field: str) -> tuple[int, tuple[str, ...]]:
        if field == "q" or self.velocity_names is None:
            return len(self.coordinates), self.coordinates
        return self.n, self.velocity_names

    def _vector(self, value, field: str) -> np.ndarray:
        array = float_array(value, field)
        width, names = self._width(field)
        if array.ndim == 0 or array.shape[-1] != width:
            shape = "()" if array.ndim == 0 else str(array.shape)
            raise InputError(f"expected {width} values ({', '.join(names)}) along "
                             f"the last axis, got shape {shape}", field=field)
        return array

    def _guarded(self, compute, arrays, fields, tail: tuple[int, ...], forward: bool = False,
                 quiet: bool = False):
        """compute(*flat inputs (N, n)) -> (N, *tail) over the states whose inputs are finite,
        NaN rows for the others (and for forward dynamics, for rows without a finite result),
        reshaped to the batch; one DynamicsWarning when any row is NaN. ``quiet``: compute is
        made of this object's own functions, whose warnings that one counts."""
        if quiet:
            compute = partial(_without_warnings, compute)
        arrays = [self._vector(x, f) for x, f in zip(arrays, fields, strict=True)]
        batch = batch_shape(arrays, fields)
        total = int(np.prod(batch, dtype=np.int64))
        flat = [np.broadcast_to(x, batch + x.shape[-1:]).reshape(total, x.shape[-1])
                for x in arrays]
        if self.velocity_names is not None and fields[0] == "q":  # a floating base's quaternion
            self._check_quaternions(flat[0])
        out, good = over_finite_rows(compute, flat, tail, forward)
        bad = total - int(good.sum())
        if bad:
            warn_undefined(bad, total)
        return out.reshape(batch + tail)

    def _check_quaternions(self, flat) -> None:
        """Refuse q's quaternions of the wrong norm in one line (flat (N, nq)): a model file
        has none (a floating base's are checked by its own class: tree_frames.py)."""

    # -- frames, Jacobians and the centre of mass (a URDF robot's tree: frames.py) --------------

    @property
    def kinematics(self) -> ModelKinematics:
        """Placements, frame Jacobians and the centre of mass of the robot's kinematic tree
        (refused in one line for a model without one)."""
        found = self.__dict__.get("_kinematics")
        if found is None:
            found = self.__dict__["_kinematics"] = self._frames_source()
        return found

    def _frames_source(self):
        """A model file's points and bodies from its own expressions (model_frames.py), at this
        object's parameter values; refused in one line for a model without them."""
        model = getattr(self, "model", None)
        from .model_frames import ModelKinematics, model_frames_apply

        if model is not None and model_frames_apply(model):

            values = getattr(self, "parameters", None) or self.functions.parameters
            return ModelKinematics(model, values)
        raise InputError("frames, Jacobians and the centre of mass are those of a URDF "
                         "robot's kinematic tree or a model file's particles and bodies; this "
                         "model has neither (energies alone name no point)", field="frame")

    @property
    def frames(self) -> tuple[str, ...]:
        """The names of the robot's link and joint frames."""
        return self.kinematics.frames

    # The functions of a state below give, as the dynamics functions do, NaN in the whole row
    # of a state whose inputs are not all finite and one DynamicsWarning counting them.

    def placement(self, q, frame: str) -> np.ndarray:
        """The frame's 4 x 4 placement in the world (rotation and origin in m), (..., 4, 4)."""
        return undefined_rows(self.kinematics.placement, (q, frame), (q,), 2)

    def jacobian(self, q, frame: str, reference: str = "local_world_aligned") -> np.ndarray:
        """The frame's 6 x n Jacobian, linear rows first, (..., 6, n); ``reference`` "world",
        "local" or "local_world_aligned" as Pinocchio's ReferenceFrame."""
        return undefined_rows(self.kinematics.jacobian, (q, frame, reference), (q,), 2)

    def center_of_mass(self, q) -> np.ndarray:
        """The moving bodies' centre of mass in the world (m), (..., 3)."""
        return undefined_rows(self.kinematics.center_of_mass, (q,), (q,), 1)

    def center_of_mass_jacobian(self, q) -> np.ndarray:
        """J_c with c_dot = J_c q_dot, (..., 3, n)."""
        return undefined_rows(self.kinematics.center_of_mass_jacobian, (q,), (q,), 2)

    def jacobian_dot_times_v(self, q, v, frame: str,
                             reference: str = "local_world_aligned") -> np.ndarray:
        """J_dot q_dot: the frame's classical acceleration at q_ddot = 0 (m/s^2, rad/s^2),
        (..., 6), as Pinocchio's getFrameClassicalAcceleration with a = 0."""
        return undefined_rows(self.kinematics.jacobian_dot_times_v, (q, v, frame, reference),
                              (q, v), 1)

    def centroidal_momentum_matrix(self, q) -> np.ndarray:
        """A_g with h_g = A_g q_dot (linear, then angular momentum about the centre of mass,
        world axes), (..., 6, n), as Pinocchio's ccrba."""
        return undefined_rows(self.kinematics.centroidal_momentum_matrix, (q,), (q,), 2)

    def _with_wrenches(self, q, v, x, f_ext, forward: bool) -> np.ndarray:
        """Inverse or forward dynamics with wrenches at frames: tau_ext = sum J^T w
        (wrenches.py) taken from tau, or added to it (in compiled C where it can be:
        tree_frames.py)."""
        inputs = (q, v, x, *f_ext.values()) if isinstance(f_ext, Mapping) else (q, v, x)
        return undefined_rows(self._wrenches_numpy, (q, v, x, f_ext, forward), inputs, 1, 5)

    def _wrenches_numpy(self, q, v, x, f_ext, forward: bool) -> np.ndarray:
        from .algorithms.wrenches import wrench_forces

        tau_ext = wrench_forces(self.kinematics, self._vector(q, "q"), f_ext)
        if forward:
            return self.forward_dynamics(q, v, self._vector(x, "tau") + tau_ext)
        return self.inverse_dynamics(q, v, x) - tau_ext
    # -- the configuration space: a floating base's is a manifold (free_flyer.py) ---------------

    def integrate(self, q, v, dt: float = 1.0) -> np.ndarray:
        """q (+) v dt: the configuration reached moving at velocity v for dt s, (..., nq); a
        floating base moves along its twist (SE(3)'s exponential) and its quaternion comes
        back normalized, a ball joint's quaternion by q exp(w dt), the joints by q + v dt."""
        step = float_array(dt, "dt")
        if step.ndim:
            raise InputError(f"expected one number of seconds, got shape {step.shape}", field="dt")
        q, v = self._vector(q, "q"), self._vector(v, "v") * float(step)
        batch = batch_shape((q, v), ("q", "v"))
        Q = np.broadcast_to(q, batch + q.shape[-1:]).reshape(-1, q.shape[-1])
        V = np.broadcast_to(v, batch + v.shape[-1:]).reshape(-1, v.shape[-1])
        return self._integrate_rows(Q, V).reshape(batch + q.shape[-1:])

    def _integrate_rows(self, Q, V) -> np.ndarray:
        """Q + V over rows (N, n): a model file's coordinates are flat (quaternions:
        tree_frames.py)."""
        return Q + V

    def difference(self, q0, q1) -> np.ndarray:
        """v with q0 (+) v = q1 (integrate's inverse for dt = 1), (..., nv)."""
        q0, q1 = self._vector(q0, "q"), self._vector(q1, "q")
        batch = batch_shape((q0, q1), ("q0", "q1"))
        Q0, Q1 = (np.broadcast_to(x, batch + x.shape[-1:]).reshape(-1, x.shape[-1])
                  for x in (q0, q1))
        return self._difference_rows(Q0, Q1).reshape(batch + (self.n,))

    def _difference_rows(self, Q0, Q1) -> np.ndarray:
        """Q1 - Q0 over rows (N, n) (quaternions: tree_frames.py)."""
        return Q1 - Q0

    def coriolis_matrix(self, q, v) -> np.ndarray:
        """C(q, q_dot) of the Coriolis and centrifugal terms, C q_dot = bias - g, with
        C_ij = sum_k Gamma_ijk q_dot_k (M's Christoffel symbols), so that M_dot - 2 C is
        skew-symmetric; as Pinocchio's computeCoriolisMatrix. Shape (..., n, n).

        Exact: the velocity terms are quadratic in q_dot, so column j is
        (bias(q, q_dot + e_j) - bias(q, q_dot - e_j)) / 4. Refused where the model's velocity
        terms are not M's (a damper, a gyroscopic load, a moving support, M changing with t).

        A floating base's twist is not the rate of its coordinates: there C is the tree's
        spatial factorization (coriolis_tree.py), M_dot - 2C skew along q (+) v dt, (..., nv, nv)."""
        self._require_christoffel()
        return self._guarded(self._christoffel_coriolis, (q, v), ("q", "v"), (self.n, self.n))

    def _christoffel_coriolis(self, q, v) -> np.ndarray:
        eye = np.eye(self.n)
        ahead = self.bias_forces(q[..., None, :], v[..., None, :] + eye)
        behind = self.bias_forces(q[..., None, :], v[..., None, :] - eye)
        return np.swapaxes((ahead - behind) / 4.0, -1, -2)

    def _velocity_terms_are_christoffel(self) -> bool:
        if self._christoffel is None:
            from ..derivation.coriolis import velocity_terms_are_christoffel

            self._christoffel = (self._equations is not None
                                 and velocity_terms_are_christoffel(self._equations()))
        return self._christoffel

    def _require_christoffel(self) -> None:
        """Refuse C in one line where the velocity terms are not only M's."""
        if not self._velocity_terms_are_christoffel():
            raise DerivationError(
                "C(q, q_dot) is the matrix of the Coriolis and centrifugal terms of M; this "
                "model's velocity terms are not only those (a damper, a velocity-dependent load, "
                "a moving support, or M changing with t): use bias_forces(q, q_dot)")

    def mass_matrix(self, q) -> np.ndarray:
        """M(q), shape (..., n, n) (kg, kg m or kg m^2 per entry)."""
        return self._guarded(lambda Q: self.functions.mass_matrix(Q, np.zeros_like(Q)), (q,),
                             ("q",), (self.n, self.n))

    def bias_forces(self, q, v) -> np.ndarray:
        """C(q, q_dot) q_dot + g(q) = -f(q, q_dot), shape (..., n)."""
        return self._guarded(lambda Q, V: -self.functions.forcing(Q, V), (q, v), ("q", "v"),
                             (self.n,))

    def gravity(self, q) -> np.ndarray:
        """g(q) = -f(q, 0): the generalized forces that hold the arm at rest, shape (..., n)."""
        return self._guarded(lambda Q: -self.functions.forcing(Q, np.zeros_like(Q)), (q,),
                             ("q",), (self.n,))

    def inverse_dynamics(self, q, v, a, f_ext=None) -> np.ndarray:
        """tau = M(q) a + C(q, q_dot) q_dot + g(q) - sum J^T w, shape (..., n); ``f_ext``
        {frame: [fx, fy, fz, mx, my, mz]} wrenches at frames (world axes, at the frame's origin;
        N, N m), a URDF robot's only."""
        if f_ext is not None:  # wrenches at frames (wrenches.py)
            return self._with_wrenches(q, v, a, f_ext, forward=False)
        def compute(Q, V, A):
            mass, forcing = self.functions._parts(Q, V, 0.0)[:2]
            return np.einsum("...ij,...j->...i", mass, A) - forcing

        return self._guarded(compute, (q, v, a), ("q", "v", "a"), (self.n,))

    def forward_dynamics(self, q, v, tau, f_ext=None) -> np.ndarray:
        """q_ddot = M(q)^-1 (tau + sum J^T w - C(q, q_dot) q_dot - g(q)), shape (..., n); NaN
        where M is not positive definite; ``f_ext`` as for inverse_dynamics."""
        if f_ext is not None:  # wrenches at frames (wrenches.py)
            return self._with_wrenches(q, v, tau, f_ext, forward=True)
        def compute(Q, V, TAU):
            mass, forcing = self.functions._parts(Q, V, 0.0)[:2]
            return solve_positive(mass, forcing + TAU)

        return self._guarded(compute, (q, v, tau), ("q", "v", "tau"), (self.n,), forward=True)

    def potential_energy(self, q) -> np.ndarray:
        """V(q) in J, shape (...)."""
        return self._guarded(lambda Q: self.functions.energy(Q, np.zeros_like(Q)), (q,), ("q",),
                             ())

    def kinetic_energy(self, q, v) -> np.ndarray:
        """T(q, q_dot) = (T + V)(q, q_dot) - V(q) in J, shape (...)."""
        return self._guarded(lambda Q, V: self.functions.energy(Q, V)
                             - self.functions.energy(Q, np.zeros_like(V)), (q, v), ("q", "v"), ())


__all__ = ["Dynamics", "solve_positive", "warn_undefined"]
