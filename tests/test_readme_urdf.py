"""The README's section on URDF arms: its Python runs and its numbers are the library's."""

import re
from pathlib import Path

import numpy as np

README = Path(__file__).resolve().parents[1] / "README.md"


def section() -> str:
    text = README.read_text(encoding="utf-8")
    return text[text.index("<!-- BEGIN urdf -->"):text.index("<!-- END urdf -->")]


def test_python_example_runs_and_its_numbers_are_textbook():
    code = re.findall(r"```python\n(.*?)```", section(), re.S)[0]
    scope: dict = {}
    exec(compile(code, "README.md", "exec"), scope)
    f = scope["f"]
    q2 = 0.5
    # M of the shipped arm in closed form (its file's comment): 2.54 + 1.2 cos, 0.34 + 0.6 cos
    np.testing.assert_allclose(f.mass_matrix([0.3, q2]),
                               [[2.54 + 1.2 * np.cos(q2), 0.34 + 0.6 * np.cos(q2)],
                                [0.34 + 0.6 * np.cos(q2), 0.34]], rtol=1e-12)
    assert "[[3.593, 0.8665], [0.8665, 0.34]]" in code
    assert scope["a"].shape == (10_000, 2)
    g = f.gravity([0.3, q2])
    assert f"[{g[0]:.4g}, {g[1]:.4g}]" in code
    tau = f.inverse_dynamics([0.3, q2], [1.0, 2.0], [0.0, 1.0])
    assert f"[{tau[0]:.4g}, {tau[1]:.4g}]" in code
