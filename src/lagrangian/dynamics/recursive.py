"""Recursive rigid-body dynamics of a robot's kinematic tree (model/tree.py) as generated C.

Instead of expanding the equations of motion (whose size grows much faster than the number of
bodies), the generated code keeps the recursions over the tree, unrolled body by body with the
joint axes, placements and inertias as numbers (zeros and ones folded away, common terms
shared):

- inverse dynamics by recursive Newton-Euler: tau = M(q) a + C(q, q_dot) q_dot + g(q);
- the mass matrix by the composite-rigid-body algorithm;
- forward dynamics by the articulated-body algorithm, O(n), or M = L L^T, whichever takes
  fewer operations (Cholesky only with mimic joints);
- sin and cos of each joint angle once, by inline kernels (fdlibm's polynomials after a
  three-part reduction by pi/2, libm beyond |x| = 1e5): a libm call costs as much as the rest
  of the mass matrix of a 7-joint arm;
- kinetic energy 1/2 sum (m v.v + 2 v.(w x h) + w.J_O w), potential energy m g height.

A floating base (free_flyer.py) takes q of nq = n + 7 numbers and v, a, tau of nv = n + 6 (the
module's RT_NQ and LG_N); its quaternion's norm is checked before the C call, the C uses its
unit rotation.

Units SI. Gravity g (a runtime parameter) along the tree's direction; each coordinate's actuator
parameter tau_<joint> acts as a load, as in the symbolic equations (b = C q_dot + g - tau_p).
The same functions are written as standalone C99 (standalone.py) and, with the Python bindings
below and template.c, as a compiled module cached by compiled.py (a key of the tree's numbers,
taken before any code is generated).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..errors import InputError
from ..model.model import Model
from ..model.tree import KinematicTree, body_tree
from .joint_space import TreeDynamics, reported_rows
from .numbers import batch_shape, float_array
from .tree_module import module_source, tree_key

# A model file's tree of at least this many bodies runs the recursions (numbers, simulation,
# modes): below it the derived equations compile quickly and print as the user wrote them.
TREE_PATH_BODIES = 6


def applicable_tree(model: Model, parameters: Mapping[str, float] | None = None
                    ) -> KinematicTree | None:
    """The model's kinematic tree when it describes the model's whole dynamics (a robot read
    from URDF and not edited since: only its rigid bodies, gravity and the actuator forces; or
    a model file's rigid bodies on revolute and prismatic joints, in numbers at ``parameters``
    over the model's values), else None, so that nothing else a model holds is ever left out."""
    tree = model.kinematic_tree
    if tree is None:
        if not model.rigid_bodies or any(b.joint is None for b in model.rigid_bodies):
            return None
        from ..model.values import resolve_parameters

        values = resolve_parameters(model, parameters, require=False)
        if any(v is None for v in values.values):
            return None
        # built from the model itself: its bodies, gravity and forces are checked there
        return body_tree(model, dict(zip((p.symbol for p in model.parameters), values.values,
                                         strict=True)))
    if (model.particles or model.bodies or model.springs or model.dampers or model.loads
            or model.constraints or model.definitions
            or model.kinetic_energy != 0 or model.potential_energy != 0
            or model.dissipation != 0):
        return None
    if model.rigid_bodies != tree.rigid_bodies:
        return None
    if tuple(c.name for c in model.coordinates) != tree.coordinates:
        return None
    names = {p.name: p.symbol for p in model.parameters}
    if any(a is not None and a not in names
           for a in (tree.gravity_parameter, *tree.actuators)):
        return None
    gravity = model.gravity
    if (gravity is None) != (tree.gravity_parameter is None):
        return None
    if gravity is not None and (gravity.magnitude != names[tree.gravity_parameter] or
                                tuple(float(d) for d in gravity.direction)
                                != tree.gravity_direction):
        return None
    expected = {c: ((names[a]),) for c, a in zip(tree.coordinates, tree.actuators, strict=True)
                if a is not None}
    given: dict[str, tuple] = {}
    for coordinate, force in model.generalized_forces:
        given[coordinate] = given.get(coordinate, ()) + (force,)
    if given != expected:
        return None
    return tree


class RecursiveDynamics(TreeDynamics):
    """Compiled recursive dynamics of a tree, batched over leading axes (SI units).

    Every input is (..., n) (or (n,), broadcast against the others); outputs keep the batch
    shape. ``functions`` (lazy) is the NumericSystem over the same module (simulation).
    """

    backend = "recursive"
    kernel = "unrolled"  # the straight-line module of this tree (compact_kernel.py: "compact")

    def __init__(self, model: Model, tree: KinematicTree,
                 parameters: Mapping[str, float] | None = None):
        from ..compile import compiled

        names = tuple(p.name for p in model.parameters)
        self._take_tree(model, tree, parameters)
        self.parameter_values = np.array(list(self.parameters.values()), dtype=float)
        self.parameter_values.flags.writeable = False
        # exact: no fused multiply-adds, which the compiler places differently in the scalar
        # and the vector functions, so that a batch's row equals its state's single call bit
        # for bit (docs/robotics.md; with them Solo12's g differed in the last bit in 162 of
        # 400 states); 10-20% of an arm's ID and FD on one thread
        self.module = compiled.load_keyed(tree_key(tree, names),
                                          lambda: module_source(tree, names), native=True,
                                          exact=True)
        P = self.parameter_values
        m = self.module
        # The fast path: one C call each, the parameters bound here.
        self._mass, self._bias, self._gravity = m.mass_matrix, m.bias_forces, m.gravity
        self._inverse, self._forward = m.inverse_dynamics, m.forward_dynamics
        self._kinetic, self._potential = m.kinetic_energy, m.potential_energy
        self._P = P  # a floating base's quaternion: the module checks its norm (ValueError)

    def regular(self) -> bool:
        """Whether M is positive definite at a few random states (a massless branch is not)."""
        rng = np.random.default_rng(0)
        q = rng.uniform(-np.pi, np.pi, (3, self.nq))
        if self.tree.floating_base:
            q[:, 3:7] /= np.linalg.norm(q[:, 3:7], axis=-1, keepdims=True)
        try:
            np.linalg.cholesky(self.mass_matrix(q))
        except np.linalg.LinAlgError:
            return False
        return True

    def numeric_system(self):
        """The NumericSystem over this module (M, f = -b, energy, accelerations, rhs), as the
        symbolic path gives it; simulation uses it."""
        from ..compile.functions import CKernel, NumericSystem

        if self.tree.floating_base:
            from .recursive_numpy import floating_refusal

            raise floating_refusal()
        return NumericSystem(coordinates=self.coordinates, constraint_names=(),
                             constraint_kinds=(), parameters=dict(self.parameters),
                             _kernel=CKernel(self.module, self.parameter_values))

    def __repr__(self) -> str:
        return f"RecursiveDynamics(coordinates={list(self.coordinates)})"

    def _call(self, function, *arrays):
        # numbers first: text or a mapping named here, not by a field read off numpy's text
        third = "tau" if function is self._forward else "a"
        arrays = [float_array(x, field) for x, field in zip(arrays, ("q", "v", third), strict=False)]
        try:
            return function(*arrays, self._P)
        except ValueError as exc:
            if str(exc).startswith("q: the base quaternion"):  # the module's check: say more
                return function(_unit_quaternions(arrays[0]), *arrays[1:], self._P)
            if "batch shapes" in str(exc):  # broadcast in numpy, then one C call
                batch = batch_shape(arrays, ("q", "v", third)[:len(arrays)])
                return self._call(function, *(
                    np.ascontiguousarray(np.broadcast_to(x, batch + x.shape[-1:]))
                    for x in arrays))
            field = str(exc).split(":")[0]
            width, names = self._width(field)
            raise InputError(f"expected {width} values ({', '.join(names)}) "
                             "along the last axis", field=field) from None

    def mass_matrix(self, q):
        """M(q), shape (..., n, n)."""
        try:
            out = self._mass(q, self._P)
        except (ValueError, TypeError):
            out = self._call(self._mass, q)
        return out if out.__class__ is not tuple else reported_rows(out, 2)

    def bias_forces(self, q, v):
        """C(q, q_dot) q_dot + g(q), shape (..., n)."""
        try:
            out = self._bias(q, v, self._P)
        except (ValueError, TypeError):
            out = self._call(self._bias, q, v)
        return out if out.__class__ is not tuple else reported_rows(out, 1)

    def gravity(self, q):
        """g(q), shape (..., n)."""
        try:
            out = self._gravity(q, self._P)
        except (ValueError, TypeError):
            out = self._call(self._gravity, q)
        return out if out.__class__ is not tuple else reported_rows(out, 1)

    def inverse_dynamics(self, q, v, a, f_ext=None):
        """tau = M a + C q_dot + g - sum J^T w, shape (..., n) (f_ext: wrenches.py)."""
        if f_ext is not None:  # wrenches at frames (wrenches.py)
            return self._with_wrenches(q, v, a, f_ext, forward=False)
        try:
            out = self._inverse(q, v, a, self._P)
        except (ValueError, TypeError):
            out = self._call(self._inverse, q, v, a)
        return out if out.__class__ is not tuple else reported_rows(out, 1)

    def forward_dynamics(self, q, v, tau, f_ext=None):
        """q_ddot = M^-1 (tau + sum J^T w - C q_dot - g), shape (..., n) (f_ext: wrenches.py)."""
        if f_ext is not None:  # wrenches at frames (wrenches.py)
            return self._with_wrenches(q, v, tau, f_ext, forward=True)
        try:
            out = self._forward(q, v, tau, self._P)
        except (ValueError, TypeError):
            out = self._call(self._forward, q, v, tau)
        return out if out.__class__ is not tuple else reported_rows(out, 1)

    def kinetic_energy(self, q, v):
        """T in J, shape (...)."""
        try:
            out = self._kinetic(q, v, self._P)
        except (ValueError, TypeError):
            out = self._call(self._kinetic, q, v)
        return out if out.__class__ is not tuple else reported_rows(out, 0)

    def potential_energy(self, q):
        """V in J, shape (...)."""
        try:
            out = self._potential(q, self._P)
        except (ValueError, TypeError):
            out = self._call(self._potential, q)
        return out if out.__class__ is not tuple else reported_rows(out, 0)


def _unit_quaternions(q) -> np.ndarray:
    """q with its base quaternions refused in one line (free_flyer.check_quaternions: which
    state, what norm) where the module refused them, else (a norm within rounding of the
    tolerance) made unit."""
    from .free_flyer import check_quaternions

    Q = np.array(q, dtype=float)
    flat = Q.reshape(-1, Q.shape[-1])
    check_quaternions(flat)
    flat[:, 3:7] /= np.linalg.norm(flat[:, 3:7], axis=-1, keepdims=True)
    return flat.reshape(Q.shape)


__all__ = ["RecursiveDynamics", "applicable_tree"]
