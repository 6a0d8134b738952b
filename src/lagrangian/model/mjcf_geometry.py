"""MJCF's numbers: orientations (quat, euler, axisangle, xyaxes, zaxis) as rotation matrices,
and a body's mass and inertia inferred from its geoms by MuJoCo's rules (uniform density,
default 1000 kg/m^3, or a geom's mass). Units SI: m, kg, kg m^2; angles as the compiler says."""

from __future__ import annotations

import math

import numpy as np

from ..errors import ModelError

DENSITY = 1000.0  # kg/m^3, MuJoCo's default geom density


def quaternion_matrix(w: float, x: float, y: float, z: float) -> np.ndarray:
    """R of the unit quaternion (w, x, y, z) (normalised first, as MuJoCo does)."""
    norm = math.sqrt(w * w + x * x + y * y + z * z)
    if norm < 1e-15:
        raise ValueError("a quaternion of zero length")
    w, x, y, z = w / norm, x / norm, y / norm, z / norm
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def axis_angle_matrix(axis, angle: float) -> np.ndarray:
    """Rot(axis, angle) (axis normalised) by Rodrigues' formula."""
    a = np.asarray(axis, float)
    norm = float(np.linalg.norm(a))
    if norm < 1e-15:
        raise ValueError("an axis of zero length")
    a = a / norm
    cross = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return math.cos(angle) * np.eye(3) + math.sin(angle) * cross + \
        (1 - math.cos(angle)) * np.outer(a, a)


def euler_matrix(angles, sequence: str) -> np.ndarray:
    """MuJoCo's euler: three turns about the axes of ``sequence`` (eulerseq), each lower-case
    letter about the turned (intrinsic) axis, each upper-case one about the fixed axis."""
    R = np.eye(3)
    for angle, letter in zip(angles, sequence, strict=True):
        turn = axis_angle_matrix(np.eye(3)["xyz".index(letter.lower())], angle)
        R = R @ turn if letter.islower() else turn @ R
    return R


def xy_axes_matrix(values) -> np.ndarray:
    """xyaxes: the frame's x axis and a y axis made normal to it; z = x cross y."""
    x, y = np.asarray(values[:3], float), np.asarray(values[3:], float)
    x = x / _length(x)
    y = y - x * float(x @ y)
    y = y / _length(y)
    return np.column_stack([x, y, np.cross(x, y)])


def z_axis_matrix(values) -> np.ndarray:
    """zaxis: the least rotation taking (0, 0, 1) to the given direction (mju_quatZ2Vec)."""
    z = np.asarray(values, float)
    z = z / _length(z)
    axis = np.cross([0.0, 0.0, 1.0], z)
    sine, cosine = float(np.linalg.norm(axis)), float(z[2])
    if sine < 1e-10:
        return np.eye(3) if cosine > 0 else axis_angle_matrix((1, 0, 0), math.pi)
    return axis_angle_matrix(axis / sine, math.atan2(sine, cosine))


def _length(v) -> float:
    norm = float(np.linalg.norm(v))
    if norm < 1e-15:
        raise ValueError("a direction of zero length")
    return norm


def rpy(R: np.ndarray) -> tuple[float, float, float]:
    """URDF's roll, pitch, yaw of R = Rz(yaw) Ry(pitch) Rx(roll), checked by rebuilding R."""
    c = math.hypot(R[0, 0], R[1, 0])
    if c > 1e-9:
        angles = (math.atan2(R[2, 1], R[2, 2]), math.atan2(-R[2, 0], c),
                  math.atan2(R[1, 0], R[0, 0]))
    elif R[2, 0] < 0:  # pitch +pi/2: only roll - yaw is fixed; yaw 0
        angles = (math.atan2(R[0, 1], R[1, 1]), math.pi / 2, 0.0)
    else:
        angles = (math.atan2(-R[0, 1], R[1, 1]), -math.pi / 2, 0.0)
    roll, pitch, yaw = angles
    rebuilt = axis_angle_matrix((0, 0, 1), yaw) @ axis_angle_matrix((0, 1, 0), pitch) @ \
        axis_angle_matrix((1, 0, 0), roll)
    assert np.abs(rebuilt - R).max() < 1e-9, "rpy of a rotation"
    return angles


# -- inertia from geoms -----------------------------------------------------------------------

def geom_volume_and_inertia(kind: str, size) -> tuple[float, np.ndarray]:
    """Volume (m^3) and principal inertia per unit density (m^5) of a MuJoCo geom about its
    centre, in its own axes (z the axis of a capsule or cylinder)."""
    s = [float(v) for v in size]
    if kind == "sphere":
        r = s[0]
        volume = 4 / 3 * math.pi * r**3
        return volume, volume * 2 / 5 * r * r * np.ones(3)
    if kind == "ellipsoid":
        a, b, c = s[:3]
        volume = 4 / 3 * math.pi * a * b * c
        return volume, volume / 5 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])
    if kind == "box":
        a, b, c = s[:3]
        volume = 8 * a * b * c
        return volume, volume / 3 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])
    if kind == "cylinder":
        r, half = s[:2]
        volume = math.pi * r * r * 2 * half
        axial = volume * r * r / 2
        side = volume * (3 * r * r + 4 * half * half) / 12
        return volume, np.array([side, side, axial])
    if kind == "capsule":
        r, half = s[:2]
        height = 2 * half
        sphere, cylinder = 4 / 3 * math.pi * r**3, math.pi * r * r * height
        side = cylinder * (3 * r * r + height * height) / 12 + \
            sphere * (2 * r * r / 5 + height * height / 4 + 3 * height * r / 8)
        axial = cylinder * r * r / 2 + sphere * 2 * r * r / 5
        return sphere + cylinder, np.array([side, side, axial])
    raise KeyError(kind)


GEOM_SIZES = {"sphere": 1, "ellipsoid": 3, "box": 3, "cylinder": 2, "capsule": 2}


def combined_inertia(parts) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass (kg), centre of mass (m) and inertia about it (kg m^2) of rigidly joined parts,
    each (mass, centre, rotation to the body's axes, principal inertia), by the parallel-axis
    theorem: I = sum R_i I_i R_i^T + m_i (|d_i|^2 E - d_i d_i^T), d_i = c_i - c."""
    mass = sum(m for m, *_ in parts)
    if mass <= 0:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    center = sum(m * np.asarray(c) for m, c, *_ in parts) / mass
    tensor = np.zeros((3, 3))
    for m, c, R, principal in parts:
        d = np.asarray(c) - center
        tensor += R @ np.diag(principal) @ R.T + m * (float(d @ d) * np.eye(3) - np.outer(d, d))
    return mass, center, 0.5 * (tensor + tensor.T)


def check_geom(kind: str, size, where: str, source: str) -> None:
    """A geom whose inertia can be inferred: a primitive with enough positive sizes."""
    if kind not in GEOM_SIZES:
        raise ModelError(f"the inertia of a {kind} geom is not inferred here (only sphere, "
                         "ellipsoid, box, cylinder and capsule): give the body an <inertial>",
                         field=where, source=source)
    if len(size) < GEOM_SIZES[kind] or any(v <= 0 for v in size[:GEOM_SIZES[kind]]):
        raise ModelError(f"a {kind} needs {GEOM_SIZES[kind]} positive size numbers, has "
                         f"{' '.join(f'{v:g}' for v in size) or 'none'}", field=where,
                         source=source)


__all__ = ["DENSITY", "GEOM_SIZES", "axis_angle_matrix", "check_geom", "combined_inertia",
           "euler_matrix", "geom_volume_and_inertia", "quaternion_matrix", "rpy",
           "xy_axes_matrix", "z_axis_matrix"]
