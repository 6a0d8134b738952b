"""An MJCF quadruped in MuJoCo's own layout against the same robot on the free flyer, and the
compiled engine against the numpy reference, per call (issue "One engine for every robot").

    python benchmarks/bench_mjcf_layout.py

Solo12 as MuJoCo writes it from its URDF (mj_saveLastXML, meshes left out), its trunk on a
<freejoint>: loaded as it is (q = qpos, v = qvel: three world slides and a ball joint), and
with floating_base=True (the free flyer, Pinocchio's layout). Per function, one state, the best
of 7 runs of 200 calls, warm (the modules built or loaded from the cache first); the three
columns alternate in this process. MuJoCo's mj_forward on the same state is printed beside
(its whole step: positions, M, its factor and the accelerations). Needs the bench extra
(pin, example-robot-data) and mujoco.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
from bench_engine import best
from bench_variants import robots

import lagrangian


def solo_on_a_free_joint(folder: Path) -> Path:
    """MuJoCo's MJCF of Solo12 with its trunk on a free joint."""
    import mujoco
    from lxml import etree

    root = etree.parse(str(robots() / "solo_description/robots/solo12.urdf")).getroot()
    for tag in ("visual", "collision"):
        for element in list(root.iter(tag)):
            element.getparent().remove(element)
    written = folder / "solo12.xml"
    mujoco.mj_saveLastXML(str(written), mujoco.MjModel.from_xml_string(
        etree.tostring(root).decode()))
    xml = written.read_text()
    begin = xml.index("<worldbody>") + len("<worldbody>")
    end = xml.index("</worldbody>")
    trunk = ('<body name="trunk"><freejoint name="root"/>'
             '<inertial pos="0 0 0" mass="1.5" diaginertia="0.01 0.02 0.03"/>')
    written.write_text(xml[:begin] + trunk + xml[begin:end] + "</body>" + xml[end:])
    return written


def main() -> None:
    import mujoco

    with tempfile.TemporaryDirectory() as folder:
        path = solo_on_a_free_joint(Path(folder))
        layouts = {"MuJoCo's": lagrangian.load(path).dynamics(),
                   "free flyer": lagrangian.load(path, floating_base=True).dynamics(),
                   "numpy, MuJoCo's": lagrangian.load(path).dynamics(backend="numpy")}
        model = mujoco.MjModel.from_xml_path(str(path))
    data = mujoco.MjData(model)
    rng = np.random.default_rng(0)
    q = rng.uniform(-1, 1, model.nq)
    q[3:7] /= np.linalg.norm(q[3:7])
    v, tau = rng.uniform(-1, 1, (2, model.nv))
    # the free flyer's q: x y z, the quaternion x y z w, the joints; its v in the base's axes
    states = {"MuJoCo's": (q, v), "numpy, MuJoCo's": (q, v),
              "free flyer": (np.r_[q[:3], q[4:7], q[3], q[7:]], v)}
    frame = "FL_FOOT" if "FL_FOOT" in layouts["MuJoCo's"].frames else layouts["MuJoCo's"].frames[-1]
    calls = {
        "M": lambda d, q, v: d.mass_matrix(q),
        "ID": lambda d, q, v: d.inverse_dynamics(q, v, tau),
        "FD": lambda d, q, v: d.forward_dynamics(q, v, tau),
        "FD derivatives": lambda d, q, v: d.forward_dynamics_derivatives(q, v, tau),
        "ID derivatives": lambda d, q, v: d.inverse_dynamics_derivatives(q, v, tau),
        "frame Jacobian": lambda d, q, v: d.jacobian(q, frame),
        "J_dot v": lambda d, q, v: d.jacobian_dot_times_v(q, v, frame),
        "A_g": lambda d, q, v: d.centroidal_momentum_matrix(q),
        "C(q, v)": lambda d, q, v: d.coriolis_matrix(q, v),
        "regressor": lambda d, q, v: d.regressor(q, v, tau),
        "ID with a wrench": lambda d, q, v: d.inverse_dynamics(q, v, tau,
                                                               f_ext={frame: np.ones(6)}),
    }
    names = list(layouts)
    print(f"Solo12 on an MJCF free joint, nv {model.nv} (us per call; mj_forward "
          f"{1e6 * best(lambda: mujoco.mj_forward(model, data), 200, 7):.2f} us)")
    print(f"{'':18s}" + "".join(f"{name:>18s}" for name in names) + "   MuJoCo's / flyer")
    data.qpos[:], data.qvel[:] = q, v
    for label, call in calls.items():
        times = {}
        for name in names:
            d, (x, y) = layouts[name], states[name]
            call(d, x, y)  # warm: built, cached, checked
            times[name] = 1e6 * best(lambda d=d, x=x, y=y, call=call: call(d, x, y), 200, 7)
        print(f"{label:18s}" + "".join(f"{times[name]:18.2f}" for name in names)
              + f"{times[names[0]] / times[names[1]]:14.2f}")


if __name__ == "__main__":
    main()
