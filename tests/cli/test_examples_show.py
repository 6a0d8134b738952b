"""`examples --show NAME` prints the model file as a user would write it: no internal "order"
line, and it reads back as the same model."""

from __future__ import annotations

import pytest

import lagrangian


@pytest.mark.parametrize("name", ["pendulum", "double_pendulum", "two_link_arm"])
def test_show_prints_the_file_without_its_list_position(cli, name, tmp_path):
    result = cli("examples", "--show", name)
    assert result.code == 0
    assert "order:" not in result.out
    suffix = lagrangian.example_path(name).suffix
    copy = tmp_path / f"{name}{suffix}"
    copy.write_text(result.out, encoding="utf-8")
    if suffix == ".toml":
        assert lagrangian.load(copy).equations_of_motion().equations == \
            lagrangian.load(name).equations_of_motion().equations
    else:
        pytest.importorskip("yourdfpy")
        import numpy as np

        assert np.allclose(lagrangian.load(copy).dynamics().mass_matrix([0.3, 0.2]),
                           lagrangian.load(name).dynamics().mass_matrix([0.3, 0.2]))
