"""The joint kinds in the per-tree generated code (dynamics/emit/: the standalone C export and
kernel="unrolled"), compiled with -std=c99 -pedantic -Werror:

- a helical joint and a universal one (two revolute joints): M, ID, FD, T, V, a frame's
  placement and its Jacobians against Pinocchio's JointModelHelicalUnaligned and
  JointModelUniversal to 1e-10;
- ball joints (MuJoCo's: q w x y z, v the child's angular velocity in its axes; a chain of nine,
  its forward dynamics the articulated-body algorithm), MJCF free joints
  in MuJoCo's layout (three world slides and a ball) and URDF floating joints between links
  (q x y z qx qy qz qw, v the child's twist in its axes), also on a floating base: the unrolled
  kernel's seven functions and every function of the export (frames, J_dot v, the centre of
  mass, A_g) against the numpy reference (algorithms/recursions.py) at random unit quaternions
  to 1e-10 (kernel="unrolled" on the ball-hinge-ball chain: test_joint_kinds.py, against
  Pinocchio). One unrolled module per tree shape, one export per robot."""

from __future__ import annotations

import ctypes
import shutil
import subprocess

import numpy as np
import pytest
from tests.dynamics.test_joint_kinds import _agree, _builder, _pinocchio
from tests.mjcf_models import BALL_HINGE_BALL
from tests.model.test_mjcf_free import ROBOT as MJCF_FREE
from tests.model.test_urdf_floating_mid_tree import ARM, POD

import lagrangian
from lagrangian.dynamics.tree.spherical import quaternion_slices
from lagrangian.output.files import write_c

pin = pytest.importorskip("pinocchio")
COMPILER = shutil.which("cc") or shutil.which("gcc")
pytestmark = pytest.mark.skipif(COMPILER is None, reason="no C compiler")
KINDS = ("universal", "helical", "helical")  # screws below a universal joint and a screw
REFERENCES = (pin.WORLD, pin.LOCAL, pin.LOCAL_WORLD_ALIGNED)  # the export's 0, 1, 2


def _export(system, folder, optimize="-O1"):
    """The system's standalone C compiled as a shared library: (library, prefix, code)."""
    code = system.to_c()
    write_c(code, folder / "gen")
    library = folder / "robot.so"
    subprocess.run([COMPILER, "-std=c99", optimize, "-Wall", "-Werror", "-pedantic", "-shared",
                    "-fPIC", str(folder / "gen" / f"{code.prefix}.c"), "-o", str(library),
                    "-lm"], check=True)
    return ctypes.CDLL(str(library)), code.prefix, code


def test_the_standalone_c_moves_helical_and_universal_joints(tmp_path):
    system = _builder(KINDS).build()
    c, P, code = _export(system, tmp_path)
    model, body = _pinocchio(KINDS, False)
    data = model.createData()
    n = model.nv
    import re

    count = int(re.search(rf"#define {P.upper()}_NP (\d+)", code.header).group(1))
    parameters = np.ctypeslib.as_array((ctypes.c_double * count).in_dll(c, f"{P}_parameters"))
    names = [x.decode() for x in (ctypes.c_char_p * len(system.dynamics().frames)).in_dll(
        c, f"{P}_frame_names")]
    kinetic, potential = getattr(c, f"{P}_kinetic_energy"), getattr(c, f"{P}_potential_energy")
    kinetic.restype = potential.restype = ctypes.c_double

    def at(x):
        return np.ascontiguousarray(x, dtype=float).ctypes.data_as(ctypes.c_void_p)

    rng = np.random.default_rng(5)
    for _ in range(3):
        q, v, a = rng.uniform(-1.0, 1.0, (3, n))
        tau = pin.rnea(model, data, q, v, a)
        M, out, acc = np.zeros((n, n)), np.zeros(n), np.zeros(n)
        c[f"{P}_mass_matrix"](at(q), at(parameters), at(M))
        full = pin.crba(model, data, q)
        _agree(M, np.triu(full) + np.triu(full, 1).T, "export: M")
        c[f"{P}_inverse_dynamics"](at(q), at(v), at(a), at(parameters), at(out))
        _agree(out, tau, "export: ID")
        assert c[f"{P}_forward_dynamics"](at(q), at(v), at(tau), at(parameters), at(acc)) == 0
        _agree(acc, a, "export: FD")
        _agree(kinetic(at(q), at(v), at(parameters)),
               pin.computeKineticEnergy(model, data, q, v), "export: T")
        _agree(potential(at(q), at(parameters)),
               pin.computePotentialEnergy(model, data, q), "export: V")
        pin.computeJointJacobians(model, data, q)
        T = np.zeros((4, 4))
        c[f"{P}_frame_placement"](at(q), names.index("c"), at(T))
        _agree(T, data.oMi[body].homogeneous, "export: placement")
        for r, reference in enumerate(REFERENCES):
            J = np.zeros((6, n))
            c[f"{P}_frame_jacobian"](at(q), names.index("c"), r, at(J))
            _agree(J, pin.getJointJacobian(model, data, body, reference), f"export: J {r}")


# (file name, text, floating_base): ball joints; free joints in MuJoCo's layout with a ball wrist
# and hinges; a floating joint between links with a moving parent and child; one below a
# floating base
def _ball_chain(count: int) -> str:
    """``count`` bodies on ball joints, each 0.3 m below the last, turned and off-centre: nv =
    3 count past 24, so the export's forward dynamics is the articulated-body algorithm."""
    body = ""
    for k in reversed(range(count)):
        body = (f'<body name="b{k}" pos="0.02 0.01 -0.3" euler="0.{k} 0.2 -0.1">'
                f'<joint name="s{k}" type="ball"/><inertial pos="0.01 -0.02 -0.15" '
                f'mass="{1 + 0.1 * k:.1f}" diaginertia="0.02 0.03 0.01"/>{body}</body>')
    return (f'<mujoco model="ball_chain"><compiler angle="radian"/><worldbody>{body}'
            "</worldbody></mujoco>")


QUATERNION_ROBOTS = {"ball_chain": ("balls.xml", _ball_chain(9), False),
                     "ball_hinge_ball": ("chain.xml", BALL_HINGE_BALL, False),
                     "mjcf_free": ("two_free.xml", MJCF_FREE, False),
                     "urdf_floating": ("arm.urdf", ARM, False),
                     "urdf_floating_on_a_base": ("pod.urdf", POD, True)}


def _states(tree, count, seed):
    """Random q (unit quaternions: the base's and every joint's), v and a."""
    rng = np.random.default_rng(seed)
    Q = rng.uniform(-1.0, 1.0, (count, tree.nq))
    starts = [3] * tree.floating_base + [iq for *_, iq, _ in quaternion_slices(tree)]
    for start in starts:
        Q[:, start:start + 4] /= np.linalg.norm(Q[:, start:start + 4], axis=-1, keepdims=True)
    V, A = rng.uniform(-1.0, 1.0, (2, count, tree.nv))
    return Q, V, A


@pytest.fixture(scope="module", params=sorted(QUATERNION_ROBOTS))
def quaternion_robot(request, tmp_path_factory):
    name, text, floating = QUATERNION_ROBOTS[request.param]
    folder = tmp_path_factory.mktemp(request.param)
    (folder / name).write_text(text)
    system = lagrangian.load(folder / name, floating_base=floating)
    assert system.model.kinematic_tree.quaternion_joints, request.param
    return request.param, system, system.dynamics(backend="numpy"), folder


def _seven(d, Q, V, A):
    return {"M": d.mass_matrix(Q), "b": d.bias_forces(Q, V), "g": d.gravity(Q),
            "ID": d.inverse_dynamics(Q, V, A), "FD": d.forward_dynamics(Q, V, A),
            "T": d.kinetic_energy(Q, V), "V": d.potential_energy(Q)}


# the unrolled module compiles per tree (3-5 s each): one per shape (a ball-hinge-ball chain:
# test_joint_kinds.py's against Pinocchio), not the floating base's variant
@pytest.mark.parametrize("quaternion_robot", ["mjcf_free", "urdf_floating"], indirect=True)
def test_the_unrolled_kernel_takes_ball_and_free_joints(quaternion_robot):
    """kernel="unrolled" on nq-wide q and nv-wide v: its batches (vector lanes) and single
    calls equal the numpy reference to 1e-10, and each other bit for bit; a quaternion off unit
    norm is refused in one line naming its joint."""
    key, system, reference, _ = quaternion_robot
    d = system.dynamics(kernel="unrolled")
    assert d.kernel == "unrolled" and d.module is not None, key
    tree = system.model.kinematic_tree
    Q, V, A = _states(tree, 9, seed=3)
    expected = _seven(reference, Q, V, A)
    batch = _seven(d, Q, V, A)
    for what, rows in batch.items():
        _agree(rows, expected[what], f"{key}: unrolled {what} (batch)")
    for i in (0, 8):
        for what, single in _seven(d, Q[i], V[i], A[i]).items():
            _agree(single, expected[what][i], f"{key}: unrolled {what} (state {i})")
            # the vector lanes' row is the scalar call's, bit for bit (no fused operations)
            assert np.array_equal(single, batch[what][i]), (key, what, i)
    name, what, iq, _ = quaternion_slices(tree)[-1]
    bad = Q[0].copy()
    bad[iq:iq + 4] *= 0.5
    with pytest.raises(lagrangian.InputError, match=f"{what} '{name}' quaternion") as error:
        d.mass_matrix(bad)
    assert "\n" not in str(error.value)


def test_the_c_export_takes_ball_and_free_joints(quaternion_robot):
    """Every function of the standalone C (M, bias, g, ID, FD, T, V, each frame's placement,
    Jacobians and J_dot v in the three references, the centre of mass and its Jacobian, A_g)
    against the numpy reference to 1e-10 at random unit quaternions; the header names q's
    and v's numbers apart (<P>_NQ, <P>_N)."""
    key, system, d, folder = quaternion_robot
    c, P, code = _export(system, folder, "-O0")
    tree = system.model.kinematic_tree
    nq, nv = tree.nq, tree.nv
    assert f"#define {P.upper()}_N {nv}\n#define {P.upper()}_NQ {nq}\n" in code.header, key
    if key == "ball_chain":  # O(n): the balls' 3 x 3 D = S^T IA S (emit/tree_floating.py)
        assert "forward dynamics: the articulated-body algorithm" in code.source
    import re

    count = int(re.search(rf"#define {P.upper()}_NP (\d+)", code.header).group(1))
    parameters = np.ctypeslib.as_array((ctypes.c_double * count).in_dll(c, f"{P}_parameters"))
    names = [x.decode() for x in (ctypes.c_char_p * len(d.frames)).in_dll(c, f"{P}_frame_names")]
    assert names == list(d.frames), key
    f = {name: getattr(c, f"{P}_{name}") for name in (
        "mass_matrix", "bias_forces", "gravity", "inverse_dynamics", "forward_dynamics",
        "kinetic_energy", "potential_energy", "frame_placement", "frame_jacobian",
        "frame_jacobian_dot_times_v", "center_of_mass", "center_of_mass_jacobian",
        "centroidal_momentum_matrix")}
    f["kinetic_energy"].restype = f["potential_energy"].restype = ctypes.c_double

    def at(x):
        return x.ctypes.data_as(ctypes.c_void_p)

    p = at(parameters)
    Q, V, A = _states(tree, 3, seed=5)
    for q, v, a in zip(Q, V, A, strict=True):
        where = f"{key} export"
        M, out = np.zeros((nv, nv)), np.zeros(nv)
        f["mass_matrix"](at(q), p, at(M))
        _agree(M, d.mass_matrix(q), f"{where}: M")
        f["bias_forces"](at(q), at(v), p, at(out))
        _agree(out, d.bias_forces(q, v), f"{where}: bias")
        f["gravity"](at(q), p, at(out))
        _agree(out, d.gravity(q), f"{where}: g")
        tau = d.inverse_dynamics(q, v, a)
        f["inverse_dynamics"](at(q), at(v), at(a), p, at(out))
        _agree(out, tau, f"{where}: ID")
        assert f["forward_dynamics"](at(q), at(v), at(tau), p, at(out)) == 0, where
        _agree(out, d.forward_dynamics(q, v, tau), f"{where}: FD")
        _agree(f["kinetic_energy"](at(q), at(v), p), d.kinetic_energy(q, v), f"{where}: T")
        _agree(f["potential_energy"](at(q), p), d.potential_energy(q), f"{where}: V")
        for k, frame in enumerate(names):
            T = np.zeros((4, 4))
            f["frame_placement"](at(q), k, at(T))
            _agree(T, d.placement(q, frame), f"{where}: {frame} placement")
            for r, reference in enumerate(("world", "local", "local_world_aligned")):
                J, Jv = np.zeros((6, nv)), np.zeros(6)
                f["frame_jacobian"](at(q), k, r, at(J))
                _agree(J, d.jacobian(q, frame, reference), f"{where}: {frame} J {reference}")
                f["frame_jacobian_dot_times_v"](at(q), at(v), k, r, at(Jv))
                _agree(Jv, d.jacobian_dot_times_v(q, v, frame, reference),
                       f"{where}: {frame} J_dot v {reference}")
        com, Jc, Ag = np.zeros(3), np.zeros((3, nv)), np.zeros((6, nv))
        f["center_of_mass"](at(q), at(com))
        _agree(com, d.center_of_mass(q), f"{where}: com")
        f["center_of_mass_jacobian"](at(q), at(Jc))
        _agree(Jc, d.center_of_mass_jacobian(q), f"{where}: com Jacobian")
        f["centroidal_momentum_matrix"](at(q), at(Ag))
        _agree(Ag, d.centroidal_momentum_matrix(q), f"{where}: A_g")
