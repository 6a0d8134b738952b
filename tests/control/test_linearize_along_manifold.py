"""linearize_along on a tree whose q holds quaternions (a ball joint, a free flyer below the
root, a floating base, MuJoCo's free joint): x = [dq; v] with dq in the tangent, q = q_run (+)
dq (a ball's and a flyer's turn R_run exp([dq]x), a flyer's position moved by R_run dq_lin).
The physics: a run started at q0 (+) d and v0 + dv ends, to first order in d, at the transition
matrix of A(t) times (d, dv) from the run itself, measured by the same (-) at its end; without
A's tangent drift (d(dq)/dt = dv - ad(v) dq) it misses by a fifth."""

from __future__ import annotations

import json

import numpy as np
import pytest
import scipy.linalg
from scipy.spatial.transform import Rotation
from tests.model.test_urdf_floating_mid_tree import ARM

import lagrangian
from lagrangian.dynamics.tree.spherical import ball_slices
from mjcf_models import BALL_HINGE_BALL, FREE_HINGE_BALL

pytest.importorskip("yourdfpy")

CASES = {  # file text, suffix, floating_base
    "ball, hinge, ball": (BALL_HINGE_BALL, "xml", False),
    "MuJoCo's free joint": (FREE_HINGE_BALL, "xml", False),
    "free flyer base": (FREE_HINGE_BALL, "xml", True),
    "floating joint between links": (ARM, "urdf", False),
}


def _pieces(tree):
    """(kind, q index, v index) of each number or manifold piece of q, in order."""
    turned = {iq: ("ball", iq, iv) for _, iq, iv in ball_slices(tree)}
    turned |= {tree.base_nq + j.coordinate: ("flyer", tree.base_nq + j.coordinate,
                                             tree.base_nv + tree.velocity_index(j.coordinate))
               for j in tree.free_joints}
    if tree.floating_base:
        turned[0] = ("flyer", 0, 0)
    pieces, iq, iv = [], 0, 0
    while iq < tree.nq:
        kind, _, jv = turned.get(iq, ("plain", iq, iv))
        pieces.append((kind, iq, jv))
        iq, iv = iq + {"ball": 4, "flyer": 7, "plain": 1}[kind], jv + {"ball": 3, "flyer": 6,
                                                                         "plain": 1}[kind]
    return pieces


def _rotation(q, kind, iq):
    """A ball's quaternion is w x y z (MuJoCo's), a flyer's x y z w after its x, y, z."""
    if kind == "ball":
        return Rotation.from_quat(np.r_[q[iq + 1:iq + 4], q[iq]])
    return Rotation.from_quat(q[iq + 3:iq + 7])


def _plus(tree, q, d):
    q = q.copy()
    for kind, iq, iv in _pieces(tree):
        if kind == "plain":
            q[iq] += d[iv]
            continue
        turn = 0 if kind == "ball" else 3
        R = _rotation(q, kind, iq)
        if kind == "flyer":
            q[iq:iq + 3] += R.apply(d[iv:iv + 3])
        x = (R * Rotation.from_rotvec(d[iv + turn:iv + turn + 3])).as_quat()
        if kind == "ball":
            q[iq:iq + 4] = np.r_[x[3], x[:3]]
        else:
            q[iq + 3:iq + 7] = x
    return q


def _minus(tree, q, q_run):
    out = []
    for kind, iq, _ in _pieces(tree):
        if kind == "plain":
            out.append(q[iq] - q_run[iq])
            continue
        R = _rotation(q_run, kind, iq)
        if kind == "flyer":
            out.extend(R.inv().apply(q[iq:iq + 3] - q_run[iq:iq + 3]))
        out.extend((R.inv() * _rotation(q, kind, iq)).as_rotvec())
    return np.array(out)


def _start(system, seed):
    """A state away from rest: every number and quaternion turned at random, every rate random."""
    dynamics, tree = system.dynamics(), system.model.kinematic_tree
    rng = np.random.default_rng(seed)
    q = np.zeros(dynamics.nq)
    for kind, iq, _ in _pieces(tree):  # the identity turn: w = 1
        if kind != "plain":
            q[iq if kind == "ball" else iq + 6] = 1.0
    return _plus(tree, q, rng.uniform(-0.5, 0.5, dynamics.nv)), rng.uniform(-0.6, 0.6,
                                                                           dynamics.nv)


def _initial(dynamics, q, v):
    names, rates = dynamics.coordinates, dynamics.velocity_names
    return {**{n: float(x) for n, x in zip(names, q, strict=True)},
            **{f"{n}_dot" if n in names else n: float(x) for n, x in zip(rates, v, strict=True)}}


def _transition(along, t, without_drift=False):
    n = along.A.shape[1] // 2
    A = along.A.copy()
    if without_drift:
        A[:, :n, :n] = 0.0
    transition = np.eye(2 * n)
    for k in range(len(t) - 1):  # midpoint exponentials: second order in the spacing
        transition = scipy.linalg.expm((A[k] + A[k + 1]) / 2 * (t[k + 1] - t[k])) @ transition
    return transition


@pytest.mark.parametrize("case", CASES, ids=str)
def test_a_perturbed_run_follows_the_transition_matrix_on_the_manifold(case, tmp_path):
    text, suffix, floating = CASES[case]
    path = tmp_path / f"robot.{suffix}"
    path.write_text(text)
    system = lagrangian.load(path, floating_base=floating)
    dynamics, tree = system.dynamics(), system.model.kinematic_tree
    q0, v0 = _start(system, 3)
    options = {"samples": 401, "rtol": 1e-12, "atol": 1e-12}
    run = system.simulate(0.4, initial=_initial(dynamics, q0, v0), **options)
    along = system.linearize_along(run)
    n = dynamics.nv
    assert along.A.shape == (401, 2 * n, 2 * n) and along.B.shape == (401, 2 * n, n)
    assert along.inputs == tuple(dynamics.velocity_names)
    assert along.state_names[n:] == run.rate_names
    delta = 1e-6 * np.random.default_rng(5).uniform(-1.0, 1.0, 2 * n)
    moved = system.simulate(0.4, initial=_initial(dynamics, _plus(tree, q0, delta[:n]),
                                                  v0 + delta[n:]), **options)
    difference = np.r_[_minus(tree, moved.q[-1], run.q[-1]), moved.q_dot[-1] - run.q_dot[-1]]
    error = np.linalg.norm(difference - _transition(along, run.t) @ delta)
    assert error < 1e-4 * np.linalg.norm(difference), case  # the midpoint rule: 1/samples^2
    drifting = np.linalg.norm(difference - _transition(along, run.t, True) @ delta)
    assert drifting > 1e-2 * np.linalg.norm(difference), case


def test_the_command_line_linearizes_a_ball_run_and_refuses_independent(cli, tmp_path):
    path = tmp_path / "chain.xml"
    path.write_text(BALL_HINGE_BALL)
    result = cli("simulate", str(path), "--t-end", "0.2", "--samples", "5",
                 "--linearize-along", "--json")
    assert result.code == 0, result.err
    along = json.loads(result.out)["linearize_along"]
    assert along["states"][:4] == ["delta_shoulder_wx", "delta_shoulder_wy",
                                   "delta_shoulder_wz", "elbow"]
    A = np.array(along["A"])
    assert A.shape == (5, 14, 14)
    np.testing.assert_allclose(A[:, :7, 7:], np.broadcast_to(np.eye(7), (5, 7, 7)))
    system = lagrangian.load(path)
    with pytest.raises(lagrangian.InputError, match="no constraints") as caught:
        system.linearize_along(system.simulate(0.1, samples=3), independent="auto")
    assert caught.value.field == "independent"
    with pytest.raises(lagrangian.InputError, match="'shoulder_qw' is not a coordinate"):
        system.linearize_along(system.simulate(0.1, samples=3), inputs=["shoulder_qw"])
