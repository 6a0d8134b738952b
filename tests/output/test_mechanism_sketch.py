"""The mechanism drawn as a user sketches it: rods from pivots and between points, blocks on
their tracks, a wheel on its surface (found from the model's structure, asserted against the
closed-form positions), and the offline, small HTML player."""

from __future__ import annotations

import re

import numpy as np
import pytest
import sympy as sp

import lagrangian
from lagrangian.output.animation import mechanism_animation
from lagrangian.output.geometry import mechanism


def drawn(animation, k: int, label: str) -> list[np.ndarray]:
    """The (x, y) points of the artists labelled ``label`` after drawing frame k."""
    animation.draw(k)
    found = []
    for artist in animation._fig.axes[0].get_children():
        if getattr(artist, "get_label", lambda: None)() != label:
            continue
        if hasattr(artist, "get_xy"):
            found.append(np.asarray(artist.get_xy(), dtype=float))
        else:
            found.append(np.column_stack([np.asarray(a, dtype=float) for a in artist.get_data()]))
    return found


@pytest.fixture(scope="module")
def double():
    run = lagrangian.load("double_pendulum").simulate(1.0, samples=101)
    return run, mechanism_animation(run, fps=10)


def test_double_pendulum_rods_run_from_the_pivot_to_bob1_and_from_bob1_to_bob2(double):
    run, animation = double
    l1 = l2 = 1.0
    for k, t in enumerate(animation.times):
        th1, th2 = np.interp(t, run.t, run["theta1"]), np.interp(t, run.t, run["theta2"])
        bob1 = l1 * np.array([np.sin(th1), -np.cos(th1)])
        bob2 = bob1 + l2 * np.array([np.sin(th2), -np.cos(th2)])
        rods = sorted(drawn(animation, k, "rod"), key=lambda r: np.linalg.norm(r[0]))
        assert len(rods) == 2
        assert rods[0] == pytest.approx(np.array([[0, 0], bob1]), abs=1e-12)
        assert rods[1] == pytest.approx(np.array([bob1, bob2]), abs=1e-12)
        # the rods keep their lengths: rigid links, not springs
        assert np.linalg.norm(rods[1][1] - rods[1][0]) == pytest.approx(l2, rel=1e-12)
        pivot, = drawn(animation, k, "pivot")
        assert pivot == pytest.approx(np.zeros((1, 2)), abs=1e-15)


def test_cart_is_a_block_on_its_track_with_the_pendulum_rod_hinged_on_it():
    run = lagrangian.load("cart_pendulum").simulate(0.5, samples=51, initial={"x_dot": 0.4})
    geometry = mechanism(run.model, run.parameters)
    assert geometry.blocks == ((0, (1.0, 0.0)),)  # the cart moves along x
    assert geometry.pivot_count == 0  # the pendulum hangs from the cart, not a fixed pivot
    animation = mechanism_animation(run, fps=10)
    l = 0.6
    for k, t in enumerate(animation.times):
        x, th = np.interp(t, run.t, run["x"]), np.interp(t, run.t, run["theta"])
        rod, = drawn(animation, k, "rod")
        assert rod == pytest.approx(np.array([[x, 0], [x + l * np.sin(th), -l * np.cos(th)]]),
                                    abs=1e-12)
        box, = drawn(animation, k, "block")
        box = box[:4]  # the closed outline repeats its first corner
        assert box.mean(axis=0) == pytest.approx([x, 0], abs=1e-12)  # centred on the cart
        assert np.ptp(box[:, 0]) > np.ptp(box[:, 1]) > 0  # longer along its track
    track = [a for a in animation._fig.axes[0].get_lines() if a.get_label() == "surface"]
    assert len(track) == 1
    ys = track[0].get_ydata()
    assert ys[0] == ys[1] < 0  # horizontal, under the cart (against gravity)


def test_a_driven_support_is_a_moving_pivot():
    run = lagrangian.load("support_pendulum").simulate(0.5, samples=51)
    animation = mechanism_animation(run, fps=20)
    a, omega, length = 0.02, 5.0, 0.5  # A, Omega, L
    for k in (0, 4, 9):
        t = animation.times[k]
        th = np.interp(t, run.t, run["theta"])
        support = np.array([a * np.cos(omega * t), 0.0])
        rod, = drawn(animation, k, "rod")
        assert rod == pytest.approx(np.array(
            [support, support + length * np.array([np.sin(th), -np.cos(th)])]), abs=1e-12)
        assert drawn(animation, k, "pivot")[0] == pytest.approx(support[None], abs=1e-15)


def test_rolling_disc_is_a_wheel_of_its_radius_on_the_incline():
    """x_dot = R phi_dot with the centre at (x, 0): the contact point is (x, -R), the surface
    the line y = -R, and the wheel's radius R."""
    run = lagrangian.load("rolling_disk").simulate(0.5, samples=51)
    geometry = mechanism(run.model, run.parameters)
    (body, radius, normal), = geometry.rolling
    assert body == 0 and radius == pytest.approx(0.1, rel=1e-12)
    assert normal == pytest.approx((0.0, 1.0), abs=1e-12)
    animation = mechanism_animation(run, fps=10)
    surface, = [a for a in animation._fig.axes[0].get_lines() if a.get_label() == "surface"]
    assert surface.get_ydata() == pytest.approx([-0.1, -0.1], abs=1e-12)
    k = len(animation.times) - 1
    x = np.interp(animation.times[k], run.t, run["x"])
    wheel, = drawn(animation, k, "wheel")
    rim = wheel[:41]
    assert np.linalg.norm(rim - [x, 0], axis=1) == pytest.approx(0.1, rel=1e-12)
    assert drawn(animation, k, "bar") == []  # drawn as a wheel, not a bar


def test_linkages_get_their_ground_pivots_and_no_spurious_rods():
    four_bar = lagrangian.load("four_bar")
    geometry = mechanism(four_bar.model, four_bar.parameters)
    assert geometry.rod_count == 0  # the bars are the links
    state = np.array([[1.0, 0.6588403091590338, 1.4680282484796007]])
    pivots = geometry.frame(state, np.zeros_like(state), np.zeros(1)).pivots[0]
    assert pivots[np.argsort(pivots[:, 0])] == pytest.approx(np.array([[0, 0], [0.3, 0]]),
                                                            abs=1e-15)
    slider = lagrangian.load("slider_crank")
    geometry = mechanism(slider.model, slider.parameters)
    assert geometry.rod_count == 0 and geometry.blocks == ((0, (1.0, 0.0)),)
    atwood = lagrangian.load("atwood")
    tracks = [d for _, d in mechanism(atwood.model, atwood.parameters).blocks]
    assert np.array(tracks) == pytest.approx(np.array([[0, 1], [0, 1]]), abs=1e-12)


def test_a_pendulum_hung_off_the_origin_gets_its_rod_from_its_own_pivot():
    b = lagrangian.SystemBuilder("offset pendulum")
    th = b.coordinate("theta")
    b.set_gravity(9.81, (0, -1))
    b.add_particle("bob", 1.0, (0.3 + 0.5 * sp.sin(th), 0.2 - 0.5 * sp.cos(th)))
    system = b.build()
    geometry = mechanism(system.model, system.parameters)
    state = np.array([[0.7]])
    frame = geometry.frame(state, np.zeros_like(state), np.zeros(1))
    bob = [0.3 + 0.5 * np.sin(0.7), 0.2 - 0.5 * np.cos(0.7)]
    assert frame.rods[0] == pytest.approx(np.array([[[0.3, 0.2], bob]]), abs=1e-12)
    assert frame.pivots[0] == pytest.approx(np.array([[0.3, 0.2]]), abs=1e-12)


@pytest.mark.slow
def test_html_player_is_offline_and_small(tmp_path):
    """5 s of the double pendulum: no URL to fetch anything from, every frame embedded, and
    well under the 2.5 MB that matplotlib's to_jshtml wrote."""
    run = lagrangian.load("double_pendulum").simulate(5.0, samples=501)
    animation = run.animate(tmp_path / "run.html")
    page = (tmp_path / "run.html").read_text()
    assert not re.search(r"https?://", page)
    assert not re.search(r"""(src|href)\s*=\s*["'](?!data:)""", page)  # nothing linked
    assert page.count("data:image/png;base64,") == len(animation.times) == 101  # 20 a second
    assert len(page.encode()) < 1_000_000


def test_the_notebook_player_is_self_contained_too():
    animation = lagrangian.load("slider_crank").simulate(0.3, samples=31).animate(fps=10)
    page = animation.to_jshtml()
    assert not re.search(r"https?://", page) and page.count("data:image/png;base64,") == 4


def test_a_rod_held_by_a_constraint_is_drawn_from_its_pivot():
    """The Cartesian pendulum: x^2 + y^2 - L^2 = 0 ties the bob to the origin by a rod of L."""
    run = lagrangian.load("cartesian_pendulum").simulate(0.5, samples=51)
    animation = mechanism_animation(run, fps=10)
    for k in (0, 5):
        t = animation.times[k]
        bob = [np.interp(t, run.t, run["x"]), np.interp(t, run.t, run["y"])]
        rod, = drawn(animation, k, "rod")
        assert rod == pytest.approx(np.array([[0, 0], bob]), abs=1e-12)
        assert np.hypot(*bob) == pytest.approx(0.5, rel=1e-6)  # the constraint holds
    # a constraint that is not a distance draws no rod (the slider-crank's loop closure)
    slider = lagrangian.load("slider_crank")
    assert mechanism(slider.model, slider.parameters).rod_count == 0


def test_a_link_pinned_at_its_end_is_drawn_from_the_pivot_whatever_its_angle_reference():
    """virtual_work_link: centre L/2 (sin th, -cos th), angle th (from the downward vertical,
    not along the link): the uniform bar of inertia m L^2 / 12 reaches the pivot, so it is drawn
    from the origin to the tip L (sin th, -cos th), with no separate rod."""
    run = lagrangian.load("virtual_work_link").simulate(0.3, samples=31)
    animation = mechanism_animation(run, fps=10)
    length = 0.5
    for k in (0, 3):
        th = np.interp(animation.times[k], run.t, run["theta"])
        bar, = drawn(animation, k, "bar")
        assert bar == pytest.approx(np.array([[0, 0], length * np.array(
            [np.sin(th), -np.cos(th)])]), abs=1e-12)
        assert drawn(animation, k, "rod") == []
