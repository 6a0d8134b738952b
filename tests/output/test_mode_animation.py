"""The mechanism oscillating in a mode (output/mode_animation.py, ModalAnalysis.animate and
`lagrangian modes --animate`): in phase and out of phase read from the positions the animation
draws, against the closed-form shapes of worked example 3 and of the double pendulum."""

from __future__ import annotations

import math

import numpy as np
import pytest
from PIL import Image

import lagrangian
from lagrangian.cli import main
from lagrangian.errors import ModelError


def _displacements(panel) -> np.ndarray:
    """Each drawn particle's displacement from where it is drawn at phase 90 degrees (the
    configuration at rest, q = q0 + a Re(u e^(i phi))), (frames, particles, 2)."""
    particles = panel.frame.particles
    rest = particles[len(particles) // 4]
    return particles - rest


def test_worked_example_3_in_phase_then_out_of_phase():
    """Two masses on three springs: mode 1 (1 rad/s, shape (1, 1)) moves both the same way in
    every frame, mode 2 (sqrt 3 rad/s, shape (1, -1)) the two against each other, by equal
    amounts; measured on the blocks as drawn."""
    analysis = lagrangian.load("two_mass").modes()
    animation = analysis.animate()
    assert [round(m.mode.frequency, 9) for m in animation.motions] == [1.0, round(math.sqrt(3), 9)]
    first, second = (_displacements(p)[..., 0] for p in animation.panels)
    moving = np.abs(first[:, 0]) > 1e-9
    assert moving.sum() > 10
    assert np.all(np.sign(first[moving, 0]) == np.sign(first[moving, 1]))
    assert np.all(np.sign(second[moving, 0]) == -np.sign(second[moving, 1]))
    assert np.allclose(first[:, 0], first[:, 1]) and np.allclose(second[:, 0], -second[:, 1])
    assert "the model gives no positions" in animation._fig._suptitle.get_text()


def test_double_pendulum_modes_from_the_drawn_bobs():
    """Equal masses and lengths: theta2/theta1 = +sqrt 2 in mode 1 and -sqrt 2 in mode 2
    (omega^2 = (2 -+ sqrt 2) g/l); the angles are read back from the bobs' drawn positions,
    and the lower bob's sideways motion has the upper one's sign in mode 1, the other in mode 2
    (it swings past the vertical: l1 theta1 + l2 theta2 = (1 - sqrt 2) l theta1)."""
    analysis = lagrangian.load("double_pendulum").modes()
    animation = analysis.animate(size=(640, 320), fps=10)
    for panel, sign in zip(animation.panels, (1, -1), strict=True):
        bob1, bob2 = panel.frame.particles[:, 0], panel.frame.particles[:, 1]
        theta1 = np.arctan2(bob1[:, 0], -bob1[:, 1])
        theta2 = np.arctan2(bob2[:, 0] - bob1[:, 0], -(bob2[:, 1] - bob1[:, 1]))
        swinging = np.abs(theta1) > 1e-3
        assert np.allclose(theta2[swinging] / theta1[swinging], sign * math.sqrt(2), rtol=1e-9)
        x1, x2 = _displacements(panel)[swinging, 0, 0], _displacements(panel)[swinging, 1, 0]
        assert np.all(np.sign(x1) == sign * np.sign(x2))
    assert len(animation.times) == 20  # one period in 2 s at 10 frames a second


def test_amplitude_is_small_and_motion_is_one_period():
    """The angle of largest swing stays within 0.35 rad; the last frame leads back to the first
    (q(2 pi) = q(0)), so the loop does not jump."""
    analysis = lagrangian.load("double_pendulum").modes()
    for motion in analysis.animate().motions:
        swing = np.max(np.abs(motion.q - np.array([0.0, 0.0])), axis=0)
        assert swing.max() <= 0.35 + 1e-12
        step = motion.phases[1] - motion.phases[0]
        assert motion.phases[-1] + step == pytest.approx(2 * math.pi)


def test_cli_writes_a_gif_of_the_size_and_rate_asked(tmp_path, capsys):
    out = tmp_path / "modes.gif"
    with pytest.raises(SystemExit) as exit_info:
        main(["modes", "two_mass", "--animate", str(out), "--size", "480x240", "--fps", "10"])
    assert exit_info.value.code in (0, None)
    assert "animated to" in capsys.readouterr().out
    with Image.open(out) as gif:
        assert gif.size == (480, 240)
        assert gif.n_frames == 20
        assert gif.info["duration"] == 100


def test_cli_writes_an_html_player_and_an_mp4(tmp_path, capsys):
    imageio_ffmpeg = pytest.importorskip("imageio_ffmpeg")
    page = tmp_path / "mode2.html"
    video = tmp_path / "modes.mp4"
    for target, extra in ((page, ["--mode", "2"]), (video, ["--size", "320x200", "--fps", "8"])):
        with pytest.raises(SystemExit) as exit_info:
            main(["modes", "double_pendulum", "--animate", str(target), *extra])
        assert exit_info.value.code in (0, None)
    text = page.read_text(encoding="utf-8")
    assert "lagrangian-animation" in text and "Mode 2 of Double pendulum" in text
    assert "phase 90°" in text and "http" not in text
    reader = imageio_ffmpeg.read_frames(str(video))
    meta = next(reader)
    assert tuple(meta["size"]) == (320, 200) and meta["fps"] == pytest.approx(8)
    assert sum(1 for _ in reader) == 16


def test_a_file_that_is_not_ours_is_never_overwritten(tmp_path, capsys):
    for name in ("notes.gif", "talk.mp4", "index.html"):
        target = tmp_path / name
        target.write_text("my own file\n")
        with pytest.raises(SystemExit) as exit_info:
            main(["modes", "two_mass", "--animate", str(target)])
        assert exit_info.value.code == 2
        err = capsys.readouterr().err
        assert err.startswith("error: --animate: ") and "refusing to overwrite" in err
        assert err.count("\n") == 1 and "Traceback" not in err
        assert target.read_text() == "my own file\n"
    link = tmp_path / "link.gif"
    link.symlink_to(tmp_path / "elsewhere.gif")
    with pytest.raises(SystemExit):
        main(["modes", "two_mass", "--animate", str(link)])
    assert "symbolic link" in capsys.readouterr().err and not (tmp_path / "elsewhere.gif").exists()


def test_our_own_animation_is_replaced(tmp_path, capsys):
    out = tmp_path / "modes.gif"
    for fps in ("5", "8"):
        with pytest.raises(SystemExit) as exit_info:
            main(["modes", "two_mass", "--animate", str(out), "--fps", fps])
        assert exit_info.value.code in (0, None)
    with Image.open(out) as gif:
        assert gif.n_frames == 16


@pytest.mark.parametrize("args, message", [
    (["--animate", "m.gif", "--mode", "3"], "error: --mode: modes are numbered 1 to 2 (as printed), "
                                            "got 3"),
    (["--animate", "m.gif", "--size", "big"], "error: --size: expected WIDTHxHEIGHT in pixels "
                                              "(e.g. 800x600), got 'big'"),
    (["--animate", "m.gif", "--size", "10x10"], "error: --size: the size must be between 64 and "
                                                "4096 pixels a side, got 10x10"),
    (["--animate", "m.gif", "--fps", "0"], "error: --fps: frames a second must be a number from 1 "
                                           "to 120, got 0"),
    (["--animate", "m.avi"], "error: --animate: cannot write m.avi: use a .gif, .html or .mp4 "
                             "file name"),
    (["--fps", "10"], "error: --fps: frames a second are only used with --animate"),
    (["--mode", "1"], "error: --mode: a mode number is only used with --animate"),
])
def test_bad_input_is_one_line_naming_the_flag(tmp_path, monkeypatch, capsys, args, message):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exit_info:
        main(["modes", "two_mass", *args])
    assert exit_info.value.code == 2
    assert capsys.readouterr().err == message + "\n"
    assert not (tmp_path / "m.gif").exists()


def test_api_bad_mode_and_no_model():
    analysis = lagrangian.load("two_mass").modes()
    with pytest.raises(ModelError, match="numbered 1 to 2"):
        analysis.animate(mode=0)
    from lagrangian.analysis.modes import modal_analysis

    bare = modal_analysis(analysis.linear_model, "bare")
    assert not hasattr(bare, "animate")  # the analysis layer's result draws nothing


def test_simulate_takes_size_and_fps(tmp_path, capsys):
    out = tmp_path / "run.gif"
    with pytest.raises(SystemExit) as exit_info:
        main(["simulate", "double_pendulum", "--t-end", "1", "--animate", str(out),
              "--size", "300x200", "--fps", "10"])
    assert exit_info.value.code in (0, None)
    with Image.open(out) as gif:
        assert gif.size == (300, 200)
        assert gif.n_frames == 11  # 1 s at 10 frames a second, both ends
    page = tmp_path / "run.html"
    with pytest.raises(SystemExit) as exit_info:
        main(["simulate", "double_pendulum", "--t-end", "0.5", "--animate", str(page),
              "--size", "300x200"])
    assert exit_info.value.code in (0, None)
    assert 'width="300" height="200"' in page.read_text(encoding="utf-8")
    capsys.readouterr()
    with pytest.raises(SystemExit) as exit_info:
        main(["simulate", "double_pendulum", "--t-end", "1", "--size", "300x200"])
    assert exit_info.value.code == 2
    assert capsys.readouterr().err.endswith("error: --size: a frame size is only used with "
                                            "--animate\n")


def test_mp4_without_its_extra_is_refused_naming_it(tmp_path, monkeypatch, capsys):
    import sys

    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)  # as where it is not installed
    target = tmp_path / "modes.mp4"
    with pytest.raises(SystemExit) as exit_info:
        main(["modes", "two_mass", "--animate", str(target)])
    assert exit_info.value.code == 2
    assert capsys.readouterr().err == (
        'error: --animate: writing MP4 needs the optional extra: pip install "lagrangian[mp4]" '
        "(imageio-ffmpeg, which ships the encoder); or write .gif or .html\n")
    assert not target.exists()


def test_a_still_picture_puts_the_bobs_where_the_angles_say():
    """mechanism_picture (the drawing a report or a notebook shows of the model): the double
    pendulum's bobs at l1 (sin t1, -cos t1) and that plus l2 (sin t2, -cos t2), l = 1 m."""
    from lagrangian.output.animation import mechanism_picture

    model = lagrangian.load("double_pendulum").model
    figure = mechanism_picture(model, {"theta1": 0.3, "theta2": -0.4}, size=(300, 200))
    assert tuple(figure.get_size_inches() * figure.dpi) == (300, 200)
    x = [math.sin(0.3), math.sin(0.3) + math.sin(-0.4)]
    y = [-math.cos(0.3), -math.cos(0.3) - math.cos(-0.4)]
    assert any(np.allclose(line.get_xdata(), x) and np.allclose(line.get_ydata(), y)
               for line in figure.axes[0].lines)
    assert figure._repr_png_().startswith(b"\x89PNG")
    with pytest.raises(ModelError, match="nothing to animate"):
        mechanism_picture(lagrangian.load("pendulum").model)  # given by its energies only
