"""Animation writing: the mechanism's GIF and HTML, ours against matplotlib's own writers.

Reproduce: ``python benchmarks/bench_animation.py`` (about a minute; ``--quick`` skips the slow
matplotlib GIF). Prints, for a 10 s double pendulum:

- the whole command ``lagrangian simulate double_pendulum --t-end 10 --animate out.gif`` in fresh
  processes (wall and CPU, median of three), and the same command without ``--animate``;
- in one process, the same animation written by ours (``save_animation``: one full draw, then
  blitting, one shared palette) and by matplotlib's ``Animation.save(PillowWriter)`` (what this
  project used before): CPU time of the write alone;
- for 5 s, the HTML page: ours (palette PNG frames at 64 dpi, own player) against
  ``FuncAnimation.to_jshtml`` (PNG frames at the figure's 80 dpi, a remote icon font) in bytes.

CPU time is given beside wall time because the development machine is shared: the load
average is printed with each figure.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def load() -> str:
    return "load average " + ", ".join(f"{x:.2f}" for x in os.getloadavg())


def whole_command(args: list[str], runs: int = 3) -> tuple[float, float]:
    """Median wall and CPU (user + sys of the child) seconds of ``lagrangian *args``."""
    walls, cpus = [], []
    for _ in range(runs):
        before = os.times()
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "lagrangian", *args], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        walls.append(time.perf_counter() - start)
        after = os.times()
        cpus.append(after.children_user - before.children_user +
                    after.children_system - before.children_system)
    return statistics.median(walls), statistics.median(cpus)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--quick", action="store_true", help="skip matplotlib's GIF writer")
    options = parser.parse_args()
    folder = Path(tempfile.mkdtemp())
    gif = folder / "out.gif"
    print(load())
    wall, cpu = whole_command(["simulate", "double_pendulum", "--t-end", "10", "--animate",
                               str(gif)])
    print(f"simulate --t-end 10 --animate out.gif: wall {wall:.2f} s, CPU {cpu:.2f} s, "
          f"{gif.stat().st_size / 1e3:.0f} kB   ({load()})")
    wall0, cpu0 = whole_command(["simulate", "double_pendulum", "--t-end", "10"])
    print(f"simulate --t-end 10 (no animation):   wall {wall0:.2f} s, CPU {cpu0:.2f} s   "
          f"({load()})")

    from matplotlib.animation import FuncAnimation
    from PIL import Image

    import lagrangian
    from lagrangian.output.animation import _save_with_matplotlib, save_animation

    run = lagrangian.load("double_pendulum").simulate(10.0)
    clock = time.process_time
    animation = run.animate()  # built, not written
    start = clock()
    save_animation(animation, folder / "ours.gif", fps=animation.fps)
    ours = clock() - start
    with Image.open(folder / "ours.gif") as image:
        frames = image.n_frames
    print(f"in process, {frames} frames at {animation.fps} a second: ours {ours:.2f} s CPU "
          f"({load()})")
    if not options.quick:
        animation = run.animate()
        start = clock()
        _save_with_matplotlib(animation, folder / "matplotlib.gif", fps=animation.fps,
                              protect=(), progress=None)
        theirs = clock() - start
        print(f"  matplotlib PillowWriter {theirs:.2f} s CPU: {theirs / ours:.0f}x ours "
              f"({load()})")

    short = lagrangian.load("double_pendulum").simulate(5.0)
    animation = short.animate()
    save_animation(animation, folder / "ours.html", fps=animation.fps)
    matplotlib_page = FuncAnimation.to_jshtml(short.animate(), fps=animation.fps)
    print(f"5 s HTML, {len(animation.times)} frames: ours "
          f"{(folder / 'ours.html').stat().st_size / 1e3:.0f} kB, matplotlib to_jshtml "
          f"{len(matplotlib_page.encode()) / 1e3:.0f} kB (remote font: "
          f"{'https://' in matplotlib_page})")


if __name__ == "__main__":
    main()
