"""Weave and capsize speeds are the exact sign changes of a real part (issue 21), and `speeds
--at` evaluates chosen speeds: the benchmark bicycle's Table 2 eigenvalues at 5 m/s."""

from __future__ import annotations

import json

import numpy as np
import pytest

import lagrangian

# Basu-Mandal, Chatterjee and Papadopoulos (2007), the benchmark's speeds to 14 digits
WEAVE, CAPSIZE = 4.29238253634111, 6.02426201538837
# Meijaard et al. (2007) Table 2 at v = 5 m/s
AT_5 = [-0.32286642900409, -0.77534188219585 - 4.46486771378823j,
        -0.77534188219585 + 4.46486771378823j, -14.07838969279822]


@pytest.fixture(scope="module")
def bicycle():
    return lagrangian.load("whipple_bicycle")


def test_the_crossings_are_the_sign_changes_to_1e12(bicycle):
    sweep = bicycle.speed_sweep()
    weave = sweep.speed_of("oscillatory", stabilizing=True)
    capsize = sweep.speed_of("real", stabilizing=False)
    assert weave == pytest.approx(WEAVE, rel=1e-12)
    assert capsize == pytest.approx(CAPSIZE, rel=1e-12)
    form = bicycle.speed_form()
    for speed in (weave, capsize):  # the largest real part changes sign right there
        below, above = form.eigenvalues(speed * (1 - 1e-10)), form.eigenvalues(speed * (1 + 1e-10))
        assert below.real.max() * above.real.max() < 0
    assert sweep.stable == ((weave, capsize),)


def test_speeds_at_chosen_speeds(cli):
    result = cli("speeds", "whipple_bicycle", "--at", "v=0.7,2.9", "--at", "v=18km/h", "--json")
    assert result.code == 0, result.err
    at = json.loads(result.out)["at"]
    assert [entry["speed"] for entry in at] == pytest.approx([0.7, 2.9, 5.0])
    values = np.array([complex(re, im) for re, im in at[2]["eigenvalues"]])
    np.testing.assert_allclose(sorted(values, key=lambda z: (z.real, z.imag)),
                               sorted(AT_5, key=lambda z: (z.real, z.imag)), rtol=1e-9)
    assert [entry["stable"] for entry in at] == [False, False, True]
    text = cli("speeds", "whipple_bicycle", "--at", "v=5.3")
    assert "Eigenvalues (1/s) at the chosen speeds v:" in text.out and "(stable)" in text.out


@pytest.mark.parametrize("setting", ["w=1", "v=", "v=1,,2", "v=fast"])
def test_a_bad_chosen_speed_is_one_line(cli, setting):
    result = cli("speeds", "whipple_bicycle", "--at", setting)
    assert result.code == 2 and result.err.count("\n") == 1 and "--at" in result.err


def test_a_steady_about_value_naming_a_symbol_is_one_line(cli, tmp_path):
    from lagrangian.model.examples import example_path

    text = example_path("whipple_bicycle").read_text().replace(
        'keep = ["phi", "delta"]', 'keep = ["phi", "delta"]\nabout = { phi = "v" }')
    path = tmp_path / "bike.toml"
    path.write_text(text)
    result = cli("speeds", str(path))
    assert result.code == 2 and result.err.count("\n") == 1
    assert "steady.about.phi" in result.err and "must be a number" in result.err
