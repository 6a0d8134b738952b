"""The section on fast numeric functions (docs/getting-started/robotics.md): its Python runs, the
mass matrix it prints is the double pendulum's closed form and the compiled integration keeps the
energy, as a conservative system must."""

import re

import numpy as np

import docs_blocks


def test_python_example_runs_and_its_numbers_are_the_double_pendulums(capsys):
    code = re.findall(r"```python\n(.*?)```", docs_blocks.block("numeric"), re.S)[0]
    scope: dict = {}
    exec(compile(code, "numeric", "exec"), scope)
    f, run = scope["f"], scope["run"]
    # M = [[(m1 + m2) l1^2, m2 l1 l2 cos(theta1 - theta2)], [., m2 l2^2]], all parameters 1.
    c = np.cos(1.0 - 0.5)
    np.testing.assert_allclose(f.mass_matrix([1.0, 0.5], [0.0, 0.0]), [[2.0, c], [c, 1.0]],
                               rtol=1e-12)
    assert scope["q_ddot"].shape == (10_000, 2) and scope["y_dot"].shape == (4,)
    assert run.success
    start, end = np.array([1.0, 0.5, 0.0, 0.0]), run.y[-1]
    assert abs(f.energy(end[:2], end[2:]) - f.energy(start[:2], start[2:])) < 1e-7
    printed = capsys.readouterr().out.splitlines()
    assert printed[0] in ("c", "numpy") and printed[1].startswith("True ")
