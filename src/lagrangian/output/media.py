"""Animation media: the frames of a built animation as a GIF, a self-contained HTML player
(a page, or a fragment for a notebook) or an MP4 video, written atomically; and the checks of
what a user asks for (file name, size in pixels, frames a second, the target file).

MP4 goes through imageio-ffmpeg, whose wheel ships the ffmpeg encoder (no system download);
it is the optional extra ``lagrangian[mp4]`` (docs/dependencies.md), refused in one line naming
the extra where it is missing.
"""

from __future__ import annotations

import base64
import html
import io
import os
import re
import tempfile
import uuid
from pathlib import Path

import numpy as np

from ..errors import InputError
from .files import atomic_write

ANIMATION_FORMATS = (".gif", ".html", ".mp4")
# A drawing's pixels per inch: 400 px square by default (5 in), the HTML player's at HTML_DPI.
ANIMATION_DPI = 80
DEFAULT_SIZE = (400, 400)
# The limits of --size and --fps: a frame a lecture screen can hold, a rate a player can play.
SIZE_LIMITS = (64, 4096)
FPS_LIMITS = (1, 120)


# The HTML player's frames are drawn smaller than the GIF's (80 dpi, 400 px): a page of
# many embedded images stays small.
HTML_DPI = 64
# Colours in the GIF's shared palette (the drawing has a dozen colours and their antialiasing).
GIF_COLOURS = 64


def _frame_images(figure, draw, count: int, *, dpi: float | None = None, progress=None):
    """RGB frames (H, W, 3) uint8: the still parts (axes, ticks, labels) are drawn once and
    restored as a background; each frame draws only the artists ``draw(k)`` moves (blitting).
    ``progress(frame, frames)`` is called after each frame."""
    canvas = figure.canvas
    if dpi is not None:
        figure.set_dpi(dpi)
    moving = draw(0)
    for artist in moving:
        artist.set_animated(True)  # left out of the full draw: the background
    try:
        canvas.draw()
        background = canvas.copy_from_bbox(figure.bbox)
        for k in range(count):
            canvas.restore_region(background)
            for artist in draw(k):
                artist.axes.draw_artist(artist)
            yield np.asarray(canvas.buffer_rgba())[..., :3].copy()
            if progress is not None:
                progress(k, count)
    finally:
        for artist in moving:
            artist.set_animated(False)


def _palette_frames(frames) -> list:
    """The frames as palette images sharing one palette (taken from a few spread frames), so
    the GIF needs no per-frame quantization search and its colours do not flicker."""
    from PIL import Image

    frames = list(frames)
    picks = sorted({0, len(frames) // 3, 2 * len(frames) // 3, len(frames) - 1})
    mosaic = Image.fromarray(np.concatenate([frames[i] for i in picks], axis=0))
    palette = mosaic.quantize(colors=GIF_COLOURS, method=Image.Quantize.MEDIANCUT)
    # Pillow maps a colour to a palette entry through a coarse lookup, so pure white landed on
    # a near-white neighbour (an off-white background): an entry within 12 levels of a more
    # used one becomes that one.
    entries = np.array(palette.getpalette()[:3 * GIF_COLOURS]).reshape(-1, 3)
    used = np.array(palette.histogram()[:len(entries)])
    for a in np.argsort(-used, kind="stable"):
        near = (used < used[a]) & (np.abs(entries - entries[a]).max(axis=1) <= 12)
        entries[near] = entries[a]
    palette.putpalette([int(c) for c in entries.ravel()])
    return [Image.fromarray(f).quantize(palette=palette, dither=Image.Dither.NONE)
            for f in frames]


def gif_bytes(frames, fps: float) -> bytes:
    """An endlessly looping GIF of the RGB frames at ``fps``."""
    images = _palette_frames(frames)
    buffer = io.BytesIO()
    images[0].save(buffer, format="GIF", save_all=True, append_images=images[1:],
                   duration=round(1000 / fps), loop=0)
    return buffer.getvalue()


def player_html(frames, *, fps: float, times: np.ndarray, title: str = "",
                fragment: bool = False, clock: str = "t = {:.2f} s") -> str:
    """A self-contained HTML page that plays the RGB frames: play/pause, step, a slider and
    the time; every image is embedded (palette PNG, base64) and nothing is loaded from
    elsewhere, so it works offline. ``fragment``: the player alone (a <div> and its script),
    to put in a notebook's output or another page. ``clock`` formats each frame's time."""
    images = _palette_frames(frames)
    encoded = []
    for image in images:
        buffer = io.BytesIO()
        image.save(buffer, format="PNG", optimize=True)
        encoded.append(base64.b64encode(buffer.getvalue()).decode("ascii"))
    lines = "\n".join(f'frames[{k}] = "data:image/png;base64,{data}";'
                      for k, data in enumerate(encoded))
    labels = ", ".join('"' + html.escape(clock.format(t), quote=True) + '"'
                       for t in times[:len(encoded)])
    player = _PLAYER.format(id=f"lagrangian-{uuid.uuid4().hex[:12]}",
                            title=html.escape(title or "animation"), frames=lines,
                            labels=labels, count=len(encoded), last=len(encoded) - 1,
                            interval=round(1000 / fps), width=images[0].width,
                            height=images[0].height)
    if fragment:
        return player
    return _PAGE.format(title=html.escape(title or "animation"), player=player)


_PAGE = """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>{title}</title></head>
<body style="font-family: sans-serif">
{player}
</body></html>
"""

_PLAYER = """<div class="lagrangian-animation" id="{id}">
<img id="{id}-frame" alt="{title}" width="{width}" height="{height}"
 style="display: block">
<div>
<button id="{id}-back" title="previous frame">&#9664;&#9664;</button>
<button id="{id}-play" title="play / pause">&#9654;</button>
<button id="{id}-next" title="next frame">&#9654;&#9654;</button>
<input id="{id}-slider" type="range" min="0" max="{last}" value="0" style="width: 60%">
<span id="{id}-clock"></span>
<label><input id="{id}-loop" type="checkbox" checked> loop</label>
</div>
</div>
<script>
(function () {{
// The animation's frames, embedded: this page needs nothing from the network. Ids carry a
// prefix of their own, so several players on one page (a notebook) stay apart.
var frames = new Array({count});
{frames}
var labels = [{labels}];
var k = 0, timer = null;
function part(name) {{ return document.getElementById("{id}-" + name); }}
var img = part("frame"), slider = part("slider"), play = part("play"), clock = part("clock");
function show(i) {{
  k = (i + frames.length) % frames.length;
  img.src = frames[k]; slider.value = k; clock.textContent = labels[k];
}}
function stop() {{ clearInterval(timer); timer = null; play.innerHTML = "&#9654;"; }}
function tick() {{
  if (k == frames.length - 1 && !part("loop").checked) {{ stop(); return; }}
  show(k + 1);
}}
play.onclick = function () {{
  if (timer) {{ stop(); return; }}
  timer = setInterval(tick, {interval}); play.innerHTML = "&#10074;&#10074;";
}};
part("back").onclick = function () {{ stop(); show(k - 1); }};
part("next").onclick = function () {{ stop(); show(k + 1); }};
slider.oninput = function () {{ stop(); show(parseInt(slider.value)); }};
show(0);
}})();
</script>
"""




def save_animation(animation, path: str | Path, *, fps: int = 25,
                   protect: tuple[Path, ...] = (), progress=None) -> Path:
    """Save a built animation as .gif, .html (a self-contained player) or .mp4, through a
    temporary file and a rename. ``progress(frame, frames)`` is called as each frame is drawn."""
    path = check_animation_path(path)
    if not hasattr(animation, "frame_images"):  # any other matplotlib animation
        return _save_with_matplotlib(animation, path, fps=fps, protect=protect,
                                     progress=progress)
    fps = _rate(animation, fps)
    suffix = path.suffix.lower()
    if suffix == ".html":
        frames = animation.frame_images(dpi=getattr(animation, "html_dpi", HTML_DPI),
                                        progress=progress)
        page = player_html(frames, fps=fps, times=animation.times, title=animation.title,
                           clock=getattr(animation, "clock_format", "t = {:.2f} s"))
        return atomic_write(path, page, protect=protect)
    if suffix == ".mp4":
        return write_mp4(animation.frame_images(progress=progress), path, fps, protect=protect)
    return atomic_write(path, gif_bytes(animation.frame_images(progress=progress), fps),
                        protect=protect)


def _rate(animation, fps: float) -> float:
    """The playback rate: real time (playback_rate) for a run; ``fps`` itself for an
    animation whose frames are not real time (a mode played over one period)."""
    if getattr(animation, "real_time", True):
        return playback_rate(animation.times, fps)
    return float(fps)


def write_mp4(frames, path: str | Path, fps: float, *, protect: tuple[Path, ...] = ()) -> Path:
    """An H.264 MP4 (yuv420p, which every player plays) of the RGB frames at ``fps``, encoded
    by the ffmpeg that imageio-ffmpeg's wheel ships, into a temporary file beside ``path`` and
    renamed over it."""
    path = Path(path)
    for guarded in protect:
        if path.exists() and guarded.exists() and path.resolve() == guarded.resolve():
            raise FileExistsError(f"{path}: refusing to overwrite an input file")
    imageio_ffmpeg = require_mp4_encoder()
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".mp4")
    os.close(handle)
    try:
        writer = None
        for frame in frames:
            # yuv420p needs even sides: one row or column of the edge colour where odd.
            height, width = frame.shape[:2]
            frame = np.pad(frame, ((0, height % 2), (0, width % 2), (0, 0)), mode="edge")
            if writer is None:
                writer = imageio_ffmpeg.write_frames(
                    temporary, (frame.shape[1], frame.shape[0]), fps=float(fps),
                    codec="libx264", pix_fmt_out="yuv420p", macro_block_size=1, quality=7,
                    ffmpeg_log_level="error", output_params=["-movflags", "+faststart"])
                writer.send(None)  # start ffmpeg
            writer.send(np.ascontiguousarray(frame))
        if writer is None:
            raise InputError("no frames to write", field="animation")
        writer.close()
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(temporary, 0o666 & ~umask)
        os.replace(temporary, path)
    finally:
        if os.path.exists(temporary):
            os.unlink(temporary)
    return path


def require_mp4_encoder():
    """imageio_ffmpeg, or a ModelError naming the extra that installs it."""
    try:
        import imageio_ffmpeg
    except ImportError:
        raise InputError('writing MP4 needs the optional extra: pip install "lagrangian[mp4]" '
                         "(imageio-ffmpeg, which ships the encoder); or write .gif or .html",
                         field="animation") from None
    return imageio_ffmpeg


def playback_rate(times: np.ndarray, fps: float) -> float:
    """Frames a second that play the frames in real time: ``fps``, or fewer where the run was
    longer than ``max_frames`` allow at ``fps`` (the frames are then further apart)."""
    span = float(times[-1] - times[0]) if len(times) > 1 else 0.0
    return min(float(fps), (len(times) - 1) / span) if span > 0 else float(fps)


def _save_with_matplotlib(animation, path: Path, *, fps, protect, progress) -> Path:
    if path.suffix.lower() == ".html":
        return atomic_write(path, animation.to_jshtml(fps=fps), protect=protect)
    from matplotlib.animation import PillowWriter

    handle, temporary = tempfile.mkstemp(suffix=".gif")
    os.close(handle)
    try:
        animation.save(temporary, writer=PillowWriter(fps=fps), progress_callback=progress)
        data = Path(temporary).read_bytes()
    finally:
        os.unlink(temporary)
    return atomic_write(path, data, protect=protect)


def check_animation_path(path: str | Path) -> Path:
    """The path, if it names a .gif, .html or .mp4 file (.mp4 only with its encoder installed)."""
    path = Path(path)
    if path.suffix.lower() not in ANIMATION_FORMATS:
        raise InputError(f"cannot write {path}: use a .gif, .html or .mp4 file name",
                         field="animation")
    if path.suffix.lower() == ".mp4":
        require_mp4_encoder()
    return path


# What each kind of file we write begins with (an HTML player: its marker, near its start).
_SIGNATURES = {".gif": lambda head: head.startswith((b"GIF87a", b"GIF89a")),
               ".mp4": lambda head: head[4:8] == b"ftyp",
               ".html": lambda head: b"lagrangian-animation" in head}


def check_animation_target(path: str | Path, field: str = "animation") -> Path:
    """An animation's target, checked before any work: free, empty, or a file of the kind
    this project writes there (a GIF, an MP4, one of our HTML pages); a link, a directory or
    another file is refused, never overwritten."""
    path = check_animation_path(path)
    if path.is_symlink():
        raise InputError(f"{path} is a symbolic link: refusing to write through it", field=field)
    if not path.exists():
        return path
    if not path.is_file():
        raise InputError(f"cannot write {path}: it exists and is not a file", field=field)
    try:
        with open(path, "rb") as handle:
            head = handle.read(65536)
    except OSError as exc:
        raise InputError(f"cannot read {path}: {exc.strerror or exc}", field=field) from None
    if head and not _SIGNATURES[path.suffix.lower()](head):
        raise InputError(f"{path} exists and is not a {path.suffix.lower().lstrip('.').upper()} "
                         "animation written by lagrangian: refusing to overwrite it (move it "
                         "away or choose another name)", field=field)
    return path


def check_size(size: object, field: str = "size") -> tuple[int, int] | None:
    """The frame size (width, height) in pixels, from "WxH" (1280x720) or a pair; None keeps
    the default (400 x 400)."""
    if size is None:
        return None
    if isinstance(size, str):
        match = re.fullmatch(r"\s*(\d{1,5})\s*[xX×]\s*(\d{1,5})\s*", size)
        if match is None:
            raise InputError(f"expected WIDTHxHEIGHT in pixels (e.g. 800x600), got {size!r}",
                             field=field)
        width, height = int(match[1]), int(match[2])
    else:
        try:
            width, height = (int(p) for p in size)
        except (TypeError, ValueError):
            raise InputError(f"expected (width, height) in pixels, got {size!r}",
                             field=field) from None
    low, high = SIZE_LIMITS
    if not (low <= width <= high and low <= height <= high):
        raise InputError(f"the size must be between {low} and {high} pixels a side, got "
                         f"{width}x{height}", field=field)
    return width, height


def check_fps(fps: object, field: str = "fps") -> float:
    """Frames a second, from 1 to 120 (a whole number comes back as an int)."""
    low, high = FPS_LIMITS
    # the range test alone: it refuses NaN and inf, and np.isfinite takes no int beyond int64
    if isinstance(fps, bool) or not isinstance(fps, (int, float, np.integer, np.floating)) or \
            not low <= fps <= high:
        raise InputError(f"frames a second must be a number from {low} to {high}, got {fps!r}",
                         field=field)
    return int(fps) if fps == int(fps) else float(fps)
