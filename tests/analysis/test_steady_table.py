"""The [steady] table: the steady motion a model is studied about by default (`speeds MODEL`,
System.speed_form()). A coin rolling upright at speed V: its lean-yaw equations about that
motion are stable exactly above V = sqrt(g r / 3) (thin uniform disc)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import lagrangian
from lagrangian.errors import ModelError
from lagrangian.model import examples

STEADY = '\n[steady]\nspeed = "V"\nrates = { spin_dot = "V/r", x_dot = "V" }\nkeep = ["lean", "yaw"]\n'


def coin_text(steady: str = STEADY) -> str:
    text = (Path(examples.__file__).parent / "rolling_coin.toml").read_text()
    gravity = 'g = { value = 9.81, unit = "m/s^2" }'
    assert gravity in text
    return text.replace(gravity, gravity + '\nV = { value = 1.2, unit = "m/s" }') + steady


@pytest.fixture(scope="module")
def coin_path(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("steady") / "coin.toml"
    path.write_text(coin_text())
    return path


def test_the_coin_is_stable_above_sqrt_g_r_over_3(coin_path):
    coin = lagrangian.load(coin_path)
    sweep = coin.speed_sweep(speeds=np.linspace(0.2, 2.0, 10))
    critical = math.sqrt(9.81 * 0.3 / 3)
    assert [c.speed for c in sweep.crossings] == pytest.approx([critical], rel=1e-9)
    assert sweep.stable[0][0] == pytest.approx(critical, rel=1e-9)
    # the table's motion is the one given explicitly
    explicit = coin.speed_form({"spin_dot": "V/r", "x_dot": "V"}, "V", ["lean", "yaw"])
    default = coin.speed_form()
    for name in ("M", "C1", "K0", "K2"):
        np.testing.assert_array_equal(getattr(default, name), getattr(explicit, name))


def test_speeds_takes_the_table_from_the_model_file(cli, coin_path):
    code, out, err = cli("speeds", str(coin_path), "--from", "0.5", "--to", "1.5", "--points",
                         "5", "--json")
    assert code == 0, err
    document = json.loads(out)
    speeds = [c["speed"] for c in document["crossings"]]
    assert speeds == pytest.approx([math.sqrt(9.81 * 0.3 / 3)], rel=1e-9)


def test_without_a_table_the_motion_must_be_given(cli):
    with pytest.raises(ModelError) as error:
        lagrangian.load("rolling_coin").speed_form()
    assert "[steady]" in str(error.value)
    code, out, err = cli("speeds", "rolling_coin")
    assert code == 2 and out == "" and err.startswith("error:") and "--steady" in err


@pytest.mark.parametrize(
    ("steady", "field", "words"),
    [
        (STEADY.replace('speed = "V"', 'speed = "U"'), "steady.speed", "not a parameter"),
        (STEADY.replace("spin_dot", "spun_dot"), "steady.rates.spun_dot", "spin_dot"),
        (STEADY.replace('"V/r"', '"V/r + lean_dot"'), "steady.rates.spin_dot", "velocities"),
        (STEADY.replace('"V/r"', '"V/r + lean"'), "steady.rates.spin_dot", "parameters only"),
        (STEADY.replace('["lean", "yaw"]', '["lean", "jaw"]'), "steady.keep", "yaw"),
        (STEADY.replace('keep = ["lean", "yaw"]', ""), "steady", "missing key 'keep'"),
        (STEADY.replace("speed =", "sped ="), "steady.sped", "speed"),
        (STEADY.replace('keep = ["lean", "yaw"]', 'keep = "lean"'), "steady.keep", "list"),
    ],
)
def test_a_bad_table_is_named(cli, tmp_path, steady, field, words):
    path = tmp_path / "coin.toml"
    path.write_text(coin_text(steady))
    with pytest.raises(ModelError) as error:
        lagrangian.load(path)
    assert error.value.field == field and words in str(error.value)
    code, out, err = cli("derive", str(path))
    assert code == 2 and out == "" and field in err and len(err.strip().splitlines()) == 1
