"""Parameter studies and ensembles on an in-process Dask cluster: the Dataset equals a serial
loop of the single-point API, closed forms hold, a failing point is recorded while the rest
complete, and an interrupted study resumed equals one run straight through."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

import lagrangian
from lagrangian.analysis.study import parse_distribution
from lagrangian.errors import ModelError
from lagrangian.output.sweep import read_study

distributed = pytest.importorskip("dask.distributed")


@pytest.fixture(scope="module")
def two_mass():
    return lagrangian.load("two_mass")


def test_modes_sweep_equals_serial_api_and_closed_form(client, two_mass):
    """Two masses m on springs k, k_c, k: omega = sqrt(k/m) and sqrt((k + 2 k_c)/m)."""
    k, m = np.linspace(10, 100, 4), [1.0, 2.0, 5.0]
    ds = two_mass.sweep({"k": k, "m": m}, compute="modes", client=client, chunk_size=5)
    assert ds["frequency"].dims == ("k", "m", "mode")
    assert (ds["status"] == "ok").all()
    K, M = np.meshgrid(k, m, indexing="ij")
    np.testing.assert_allclose(ds["frequency"].sel(mode=1), np.sqrt(K / M), rtol=1e-12)
    np.testing.assert_allclose(ds["frequency"].sel(mode=2), np.sqrt((K + 2.0) / M), rtol=1e-12)
    for (i, ki), (j, mj) in itertools.product(enumerate(k), enumerate(m)):
        one = two_mass.with_parameters(k=ki, m=mj).modes()
        point = ds.isel(k=i, m=j)
        np.testing.assert_allclose(point["frequency"], one.natural_frequencies, rtol=1e-12)
        np.testing.assert_allclose(point["shape"].values, one.mode_shapes.T, atol=1e-12)
        assert bool(point["stable"]) == one.stable


def test_damped_and_unstable_modes_equal_serial_api(client):
    """Bead on a hoop about the equilibrium nearest its initial value: the bottom loses its
    stability at Omega^2 = g/R (growth rate > 0 past it on the branch the API picks)."""
    bead = lagrangian.load("bead_on_hoop")
    omegas = np.linspace(0.0, 10.0, 11)
    ds = bead.sweep({"Omega": omegas}, compute="modes", client=client, chunk_size=4)
    for i, omega in enumerate(omegas):
        one = bead.with_parameters(Omega=float(omega)).modes()
        np.testing.assert_allclose(ds["frequency"][i, : len(one)], one.natural_frequencies,
                                   rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(ds["growth_rate"][i, : len(one)],
                                   [m.growth_rate for m in one.modes], rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(ds["equilibrium"][i], list(one.equilibrium.values()),
                                   atol=1e-9)
    damped = lagrangian.load("damped_oscillator")
    name = damped.model.parameters[0].name
    value = damped.model.parameters[0].value
    ds = damped.sweep({name: [value, 2 * value]}, compute="modes", client=client)
    for i, v in enumerate([value, 2 * value]):
        one = damped.with_parameters(**{name: v}).modes()
        np.testing.assert_allclose(ds["damping_ratio"][i, : len(one)],
                                   [md.damping_ratio for md in one.modes], rtol=1e-10)


def test_equilibria_sweep_shows_the_pitchfork(client):
    """Below Omega^2 = g/R: bottom (stable) and top; above: the bottom turns unstable and two
    stable equilibria at cos(theta) = g/(R Omega^2) appear."""
    bead = lagrangian.load("bead_on_hoop")
    g, R = 9.81, 0.5
    critical = math.sqrt(g / R)
    omegas = np.array([0.5 * critical, 0.9 * critical, 1.2 * critical, 2.0 * critical])
    ds = bead.sweep({"Omega": omegas}, compute="equilibria", client=client, chunk_size=3)
    np.testing.assert_array_equal(ds["count"], [2, 2, 4, 4])
    for i, omega in enumerate(omegas):
        one = bead.with_parameters(Omega=float(omega)).equilibria()
        found = ds["configuration"][i].sel(coordinate="theta").values[: len(one)]
        np.testing.assert_allclose(found, [e.coordinates["theta"] for e in one], atol=1e-9)
        np.testing.assert_array_equal(ds["stable"][i].values[: len(one)],
                                      [float(e.stable) for e in one])
        if omega > critical:
            side = np.arccos(g / (R * omega**2))
            np.testing.assert_allclose(sorted(np.abs(found))[1], side, rtol=1e-9)


def test_failing_point_is_recorded_and_the_rest_complete(client, two_mass):
    ds = two_mass.sweep({"m": [1.0, 0.0, 4.0]}, compute="modes", client=client)
    status = list(ds["status"].values)
    assert status[0] == "ok" and status[2] == "ok"
    assert "singular" in status[1]
    assert np.isnan(ds["frequency"][1]).all()
    np.testing.assert_allclose(ds["frequency"][2], [0.5, math.sqrt(3) / 2], rtol=1e-12)
    assert ds.attrs["failed"] == 1


def test_interrupted_study_resumed_equals_a_straight_run(client, two_mass, tmp_path):
    vary = {"k": np.linspace(1, 9, 9), "k_c": [0.5, 1.5]}
    straight = two_mass.sweep(vary, compute="modes", client=client, chunk_size=4)
    out = tmp_path / "study.nc"
    calls = []

    def interrupt(done, total):
        calls.append(done)
        if done >= 4:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        two_mass.sweep(vary, compute="modes", client=client, chunk_size=4, out=out,
                       progress=interrupt)
    partial = read_study(out)
    finished = int((partial["status"] == "ok").sum())
    assert 4 <= finished < 18 and (partial["status"] == "not computed").sum() == 18 - finished
    resumed = two_mass.sweep(vary, compute="modes", client=client, chunk_size=4, out=out,
                             resume=True)
    assert resumed.equals(straight)
    assert read_study(out).equals(straight)
    assert not (tmp_path / "study.nc.partial").exists()


def test_ensemble_equals_serial_simulations(client, tmp_path):
    """Each member is the single-point simulation with its drawn values; the energy of the
    conservative double pendulum drifts by less than 1e-6."""
    pendulum = lagrangian.load("double_pendulum")
    ds = pendulum.sweep({"theta2": [0.1, 0.4]}, compute="simulate", t_end=1.0, samples=11,
                        sample={"theta1": "normal(0.3, 0.01)"}, members=3, seed=4,
                        trajectories=True, client=client, out=tmp_path / "e.zarr")
    assert ds["final"].dims == ("theta2", "member", "state")
    for i, j in itertools.product(range(2), range(3)):
        theta1 = float(ds["theta1"][j])
        one = pendulum.simulate(1.0, initial={"theta1": theta1, "theta2": float(ds["theta2"][i])},
                                samples=11)
        point = ds.isel(theta2=i, member=j)
        state = np.concatenate([one.q[-1], one.q_dot[-1]])
        np.testing.assert_allclose(point["final"], state, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(point["trajectory"].values[:, :2], one.q, rtol=1e-12,
                                   atol=1e-14)
        assert float(point["invariant_drift"]) == pytest.approx(one.invariant_drift, rel=1e-6)
        assert float(point["invariant_drift"]) < 1e-6
    assert read_study(tmp_path / "e.zarr").equals(ds)
    # Drawn from normal(0.3, 0.01): three values near 0.3, reproducible by seed.
    assert np.all(np.abs(ds["theta1"].values - 0.3) < 0.05)


def test_failing_member_of_an_ensemble_is_recorded_and_the_rest_complete(client):
    """A lower rod of zero length makes the mass matrix singular: that member is NaN with the
    time its integration failed, the others equal the single-point simulation."""
    pendulum = lagrangian.load("double_pendulum")
    ds = pendulum.sweep({"l2": [1.0, 0.0, 0.5]}, compute="simulate", t_end=1.0, samples=11,
                        sample={"theta1": "uniform(0.1, 0.5)"}, members=5, seed=1,
                        trajectories=True, client=client, chunk_size=7)
    failed = ds.sel(l2=0.0)
    assert list(failed["status"].values) == ["integration failed at t = 0 s"] * 5
    assert np.all(np.isnan(failed["final"])) and np.all(np.isnan(failed["trajectory"]))
    for length, j in itertools.product([1.0, 0.5], range(5)):
        point = ds.sel(l2=length).isel(member=j)
        assert point["status"] == "ok"
        one = pendulum.with_parameters(l2=length).simulate(
            1.0, initial={"theta1": float(ds["theta1"][j])}, samples=11)
        np.testing.assert_allclose(point["final"], [*one.q[-1], *one.q_dot[-1]], rtol=1e-12,
                                   atol=1e-14)
        assert float(point["invariant_drift"]) == pytest.approx(one.invariant_drift, rel=1e-6)


def test_ensemble_loads_the_cached_module_without_generating_c(client, monkeypatch):
    """A second study of the same equations finds the compiled module by the equations' key:
    no C is generated again (that cost seconds per process for larger models)."""
    from lagrangian.compile import codegen, compiled

    if not compiled.available():
        pytest.skip("no C compiler")
    pendulum = lagrangian.load("double_pendulum")
    first = pendulum.sweep(compute="simulate", t_end=0.5, samples=3,
                           sample={"theta1": "uniform(0.1, 0.2)"}, members=2, client=client)

    def refuse(eom):
        raise AssertionError("C generated again for equations already compiled")

    monkeypatch.setattr(codegen, "generate", refuse)
    again = pendulum.sweep(compute="simulate", t_end=0.5, samples=3,
                           sample={"theta1": "uniform(0.1, 0.2)"}, members=2, client=client)
    assert again.equals(first)
    assert list(again["status"].values) == ["ok", "ok"]


def test_stop_condition_time_per_member(client):
    pendulum = lagrangian.load("pendulum")
    ds = pendulum.sweep({"theta": [0.2, 0.5]}, compute="simulate", t_end=3.0, samples=31,
                        stop_when="theta < 0", client=client)
    for i, theta in enumerate([0.2, 0.5]):
        one = pendulum.simulate(3.0, initial={"theta": theta}, samples=31, stop_when="theta < 0")
        assert one.status == "stopped"
        assert float(ds["stop_time"][i]) == pytest.approx(float(one.t[-1]), rel=1e-12)


def test_bad_input_is_named(two_mass):
    with pytest.raises(ModelError, match="'kk' is not a parameter.*did you mean 'k'"):
        two_mass.sweep({"kk": [1, 2]})
    with pytest.raises(ModelError, match="compute must be one of"):
        two_mass.sweep({"k": [1, 2]}, compute="frequencies")
    with pytest.raises(ModelError, match="needs t_end"):
        two_mass.sweep({"k": [1, 2]}, compute="simulate")
    with pytest.raises(ModelError, match="x1"):
        two_mass.sweep({"x1": [1, 2]}, compute="modes")  # a coordinate: only for simulations
    with pytest.raises(ModelError, match="NetCDF"):
        two_mass.sweep({"k": [1, 2]}, out="study.csv")
    with pytest.raises(ModelError, match="finite"):
        two_mass.sweep({"k": [1, float("nan")]})
    with pytest.raises(ModelError) as info:
        two_mass.sweep(compute="simulate", t_end=1, sample={"x1": "gauss(0, 1)"}, members=3)
    assert info.value.field == "sample.x1" or "normal(MEAN, STD)" in str(info.value)


@pytest.mark.parametrize("text, expected", [
    ("normal(0.3,0.01)", ("normal", 0.3, 0.01)), (" uniform( -1 , 2e-1 ) ", ("uniform", -1, 0.2)),
])
def test_distribution_grammar(text, expected):
    d = parse_distribution(text)
    assert (d.kind, d.a, d.b) == expected


@pytest.mark.parametrize("text", ["normal(0.3)", "normal(0, -1)", "uniform(2, 1)",
                                  "__import__('os')", "normal(1e999, 1)", "lognormal(0, 1)",
                                  "normal(0.3, 0.01) + 1"])
def test_distribution_grammar_refuses(text):
    with pytest.raises(ModelError):
        parse_distribution(text)


def test_ensemble_of_a_damped_model_monitors_its_work_balance(client):
    """Where T + V is not conserved each member is the single-point simulation: same final
    state and the same invariant drift (the work balance closes)."""
    damped = lagrangian.load("damped_oscillator")
    x = damped.model.coordinates[0].name
    ds = damped.sweep({x: [0.1, 0.2]}, compute="simulate", t_end=2.0, samples=21, client=client)
    for i, x0 in enumerate([0.1, 0.2]):
        one = damped.simulate(2.0, initial={x: x0}, samples=21)
        np.testing.assert_allclose(ds["final"][i], [*one.q[-1], *one.q_dot[-1]], rtol=1e-12)
        assert float(ds["invariant_drift"][i]) == pytest.approx(one.invariant_drift, rel=1e-9)
    assert ds.attrs["invariant"] != "energy"


def test_modes_where_lengths_and_masses_enter_the_search(client):
    """Double pendulum over l1 (a length: the search spans change) and m2 (enters m g): each
    point equals System.modes; at l1 = l2 = 1, m1 = m2 the frequencies are
    sqrt((2 -+ sqrt 2) g / l)."""
    pendulum = lagrangian.load("double_pendulum")
    lengths, masses = [0.5, 1.0], [1.0, 3.0]
    ds = pendulum.sweep({"l1": lengths, "m2": masses}, compute="modes", client=client,
                        chunk_size=3)
    for (i, l1), (j, m2) in itertools.product(enumerate(lengths), enumerate(masses)):
        one = pendulum.with_parameters(l1=l1, m2=m2).modes()
        np.testing.assert_allclose(ds["frequency"][i, j], one.natural_frequencies, rtol=1e-10)
        np.testing.assert_allclose(ds["equilibrium"][i, j], list(one.equilibrium.values()),
                                   atol=1e-9)
    g = 9.81
    np.testing.assert_allclose(ds["frequency"].sel(l1=1.0, m2=1.0),
                               np.sqrt([(2 - math.sqrt(2)) * g, (2 + math.sqrt(2)) * g]),
                               rtol=1e-10)


def test_modes_about_a_named_equilibrium_show_the_pitchfork(client):
    """About the bottom of the hoop: omega^2 = g/R - Omega^2 below the pitchfork, growth rate
    sqrt(Omega^2 - g/R) above it (the bottom turns unstable at Omega^2 = g/R)."""
    bead = lagrangian.load("bead_on_hoop")
    g, R = 9.81, 0.5
    omegas = np.array([0.0, 2.0, 4.0, 5.0, 8.0])
    ds = bead.sweep({"Omega": omegas}, compute="modes", about={"theta": 0.0}, client=client)
    below = omegas**2 < g / R
    np.testing.assert_allclose(ds["frequency"][below, 0], np.sqrt(g / R - omegas[below]**2),
                               rtol=1e-10)
    np.testing.assert_allclose(ds["growth_rate"][~below, 0], np.sqrt(omegas[~below]**2 - g / R),
                               rtol=1e-10)
    np.testing.assert_array_equal(ds["stable"], below.astype(float))
    one = bead.with_parameters(Omega=5.0).modes(about={"theta": 0.0})
    assert float(ds["growth_rate"][3, 0]) == pytest.approx(one.modes[0].growth_rate, rel=1e-12)
    # a configuration that is not an equilibrium is a status, not a crash
    ds = bead.sweep({"Omega": [2.0, 3.0]}, compute="modes", about={"theta": 0.3}, client=client)
    assert all("not an equilibrium" in s for s in ds["status"].values)
    with pytest.raises(ModelError, match="about"):
        bead.sweep({"Omega": [2.0]}, compute="equilibria", about={"theta": 0.0})


def test_a_parameter_without_value_must_be_given_or_varied(client):
    builder = lagrangian.SystemBuilder("Spring")
    x = builder.coordinate("x", unit="m")
    m, k = builder.parameter("m", 2.0), builder.parameter("k", None)
    builder.add_particle("bob", m, (x, 0))
    builder.add_potential_energy(k * x**2 / 2)
    system = builder.build()
    with pytest.raises(ModelError, match="'k' has no value"):
        system.sweep({"m": [1.0, 2.0]})
    ds = system.sweep({"k": [2.0, 8.0]}, client=client)
    np.testing.assert_allclose(ds["frequency"][:, 0], [1.0, 2.0], rtol=1e-12)
