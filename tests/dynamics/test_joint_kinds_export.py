"""A helical joint and a universal one (two revolute joints) in the standalone C export (the
unrolled emitter's recursions, dynamics/emit/, and the frames of standalone_frames.py),
compiled with -std=c99 -pedantic -Werror: M, ID, FD, T, V, a frame's placement and its
Jacobians against Pinocchio's JointModelHelicalUnaligned and JointModelUniversal to 1e-10."""

from __future__ import annotations

import ctypes
import shutil
import subprocess

import numpy as np
import pytest
from tests.dynamics.test_joint_kinds import _agree, _builder, _pinocchio

from lagrangian.output.files import write_c

pin = pytest.importorskip("pinocchio")
COMPILER = shutil.which("cc") or shutil.which("gcc")
pytestmark = pytest.mark.skipif(COMPILER is None, reason="no C compiler")
KINDS = ("universal", "helical", "helical")  # screws below a universal joint and a screw
REFERENCES = (pin.WORLD, pin.LOCAL, pin.LOCAL_WORLD_ALIGNED)  # the export's 0, 1, 2


def test_the_standalone_c_moves_helical_and_universal_joints(tmp_path):
    system = _builder(KINDS).build()
    code = system.to_c()
    write_c(code, tmp_path / "gen")
    library = tmp_path / "robot.so"
    subprocess.run([COMPILER, "-std=c99", "-O1", "-Wall", "-Werror", "-pedantic", "-shared",
                    "-fPIC", str(tmp_path / "gen" / f"{code.prefix}.c"), "-o", str(library),
                    "-lm"], check=True)
    c, P = ctypes.CDLL(str(library)), code.prefix
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
