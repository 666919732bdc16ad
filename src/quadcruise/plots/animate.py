"""An animation of one vehicle's flight: top view and altitude, a moving marker and a trail.

Frames are drawn by blitting on matplotlib's Agg canvas: the static part (reference,
whole path, axes) is drawn once and only the moving artists are drawn per frame, instead
of redrawing the whole figure for each frame (as ``matplotlib.animation`` writers do). A GIF
is written with Pillow; an MP4 is piped to ffmpeg, which must be installed.

Examples
--------
>>> import tempfile, pathlib
>>> import quadcruise as qc
>>> from PIL import Image
>>> from quadcruise.plots.animate import animate_flight
>>> res = qc.fly("step", duration=2.0, log_every=10)
>>> with tempfile.TemporaryDirectory() as tmp:
...     out = animate_flight(res, pathlib.Path(tmp) / "step.gif", fps=10)
...     with Image.open(out) as gif:
...         gif.n_frames                      # 2 s at 10 frames per second
20
"""

from __future__ import annotations

import shutil
import subprocess
from collections.abc import Callable
from pathlib import Path

import numpy as np

from quadcruise.checks import describe
from quadcruise.errors import InputError, SimulationError
from quadcruise.io.files import atomic_path
from quadcruise.plots.thin import thinned

__all__ = ["animate_flight", "check_animation_path"]

MAX_LINE_POINTS = 1500
"""Most points of a line drawn per frame (the trail, the altitude trace)."""


def _ffmpeg() -> str | None:
    """The ffmpeg executable, or None."""
    import matplotlib

    configured = matplotlib.rcParams.get("animation.ffmpeg_path", "ffmpeg")
    return shutil.which(configured) or shutil.which("ffmpeg")


def check_animation_path(path) -> None:
    """Refuse an animation path this machine cannot write: a suffix other than .gif or
    .mp4, or .mp4 without ffmpeg.

    Examples
    --------
    >>> check_animation_path("flight.gif")
    >>> check_animation_path("flight.avi")
    Traceback (most recent call last):
        ...
    quadcruise.errors.InputError: flight.avi: an animation is written as .gif or .mp4, not '.avi'
    """
    path = Path(path)
    kind = path.suffix.lower()
    if kind not in (".gif", ".mp4"):
        raise InputError(f"{path}: an animation is written as .gif or .mp4, not {path.suffix or 'no suffix'!r}")
    if kind == ".mp4" and _ffmpeg() is None:
        raise InputError(
            f"{path}: writing .mp4 needs ffmpeg, which is not installed; write a .gif instead (e.g. flight.gif)"
        )


def _frame_indices(t: np.ndarray, end: int, fps: float, duration_s, every) -> np.ndarray:
    """Logged instant shown in each frame."""
    if every is not None:
        if int(every) != every or every < 1:
            raise InputError(f"every must be a positive integer, got {describe(every)}")
        return np.arange(0, end, int(every))
    span = float(t[end - 1] - t[0])
    duration_s = span if duration_s is None else float(duration_s)
    if not np.isfinite(duration_s) or duration_s <= 0:
        raise InputError(f"duration_s must be positive, got {describe(duration_s)}")
    n = max(2, int(round(fps * duration_s)))
    times = np.linspace(t[0], t[end - 1], n)
    return np.clip(np.searchsorted(t[:end], times, side="right") - 1, 0, end - 1)


def _thin(i0: int, i1: int) -> np.ndarray:
    """At most MAX_LINE_POINTS indices from i0 to i1, both included."""
    return thinned(i0, i1, (i1 - i0) // MAX_LINE_POINTS + 1)


def animate_flight(
    result,
    path,
    *,
    vehicle: int = 0,
    fps: float = 15,
    duration_s: float | None = None,
    every: int | None = None,
    trail_s: float | None = None,
    dpi: int = 80,
    progress: Callable[[int, int], None] | None = None,
) -> Path:
    """Write an animation of one vehicle's flight (.gif by Pillow, .mp4 with ffmpeg), whole or not at all."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from PIL import Image

    from quadcruise.plots.flight import REF_STYLE, describe

    path = Path(path)
    kind = path.suffix.lower()
    check_animation_path(path)
    ffmpeg = _ffmpeg() if kind == ".mp4" else None
    if not 0 <= vehicle < result.n:
        raise InputError(f"vehicle {vehicle} is not in this result of {result.n} vehicle(s)")
    if not (np.isfinite(fps) and fps > 0):
        raise InputError(f"fps must be positive, got {describe(fps)}")
    t = result.t
    pos, ref = result.states[vehicle, :, :3], result.references[vehicle, :, :3]
    psi = result.state("psi")[vehicle]
    live = np.flatnonzero(np.all(np.isfinite(pos), axis=1))
    if live.size < 2:
        raise InputError("the vehicle has fewer than two finite logged states: nothing to animate")
    end = int(live[-1]) + 1
    frames = _frame_indices(t, end, fps, duration_s, every)
    span = float(t[end - 1] - t[0])
    trail_s = 0.1 * span if trail_s is None else float(trail_s)
    gap = np.min(np.diff(t[frames])) if frames.size > 1 else 1.0
    decimals = int(min(4, max(1, np.ceil(-np.log10(max(gap, 1e-4)) + 0.3))))
    has_ref = bool(np.any(np.all(np.isfinite(ref), axis=1)))

    fig = Figure(figsize=(8, 3.6), dpi=dpi, layout="constrained")
    canvas = FigureCanvasAgg(fig)
    top, alt = fig.subplots(1, 2, width_ratios=(1, 1.35))
    whole = _thin(0, end - 1)
    if has_ref:
        top.plot(ref[:, 0], ref[:, 1], **REF_STYLE)
        alt.plot(t, ref[:, 2], **{**REF_STYLE, "label": None})
    top.plot(pos[whole, 0], pos[whole, 1], color="tab:blue", lw=1, alpha=0.25)
    alt.plot(t[whole], pos[whole, 2], color="tab:blue", lw=1, alpha=0.25)
    stopped = int(result.status[vehicle]) != 0
    if stopped:
        top.plot(*pos[end - 1, :2], "X", color="tab:red", ms=8, label=f"stopped, t = {t[end - 1]:.2f} s")
    (trail,) = top.plot([], [], color="tab:blue", lw=2.2, label="trail")
    (heading,) = top.plot([], [], color="k", lw=1.5)
    (ref_dot,) = top.plot([], [], "o", mfc="none", mec="k", ms=7)
    (dot,) = top.plot([], [], "o", color="tab:blue", mec="white", ms=8)
    (z_line,) = alt.plot([], [], color="tab:blue", lw=1.6, label="z")
    (z_dot,) = alt.plot([], [], "o", color="tab:blue", mec="white", ms=7)
    cursor = alt.axvline(t[0], color="0.4", lw=0.8)
    top.set_aspect("equal", adjustable="datalim")
    top.set(xlabel="x [m]", ylabel="y [m]", title="top view")
    alt.set(xlabel="time [s]", ylabel="z [m]", title="altitude", xlim=(t[0], t[-1] if t[-1] > t[0] else t[0] + 1))
    zs = np.concatenate([pos[live, 2], ref[np.isfinite(ref[:, 2]), 2]])
    pad = max(0.08 * (zs.max() - zs.min()), 0.05)
    alt.set_ylim(zs.min() - pad, zs.max() + pad)
    for ax in (top, alt):
        ax.grid(True, alpha=0.3)
    top.legend(loc="upper right", fontsize="x-small", framealpha=0.8)
    label = describe(result, vehicle)
    title = fig.suptitle(f"{label} — t = {t[end - 1]:.{decimals}f} s", fontsize="medium")
    moving = (trail, heading, ref_dot, dot, z_line, z_dot, cursor, title)
    canvas.draw()  # lay out once, with a full-length title
    fig.set_layout_engine("none")  # then freeze it: the frames only blit
    for artist in moving:
        artist.set_animated(True)
    canvas.draw()
    background = canvas.copy_from_bbox(fig.bbox)
    arm = 0.06 * max(np.ptp(pos[live, 0]), np.ptp(pos[live, 1]), 0.5)

    def frame(k: int) -> np.ndarray:
        canvas.restore_region(background)
        first = int(np.searchsorted(t, t[k] - trail_s))
        tr = _thin(first, k)
        trail.set_data(pos[tr, 0], pos[tr, 1])
        dot.set_data([pos[k, 0]], [pos[k, 1]])
        heading.set_data([pos[k, 0], pos[k, 0] + arm * np.cos(psi[k])], [pos[k, 1], pos[k, 1] + arm * np.sin(psi[k])])
        ref_dot.set_data(([ref[k, 0]], [ref[k, 1]]) if has_ref else ([], []))
        zz = _thin(0, k)
        z_line.set_data(t[zz], pos[zz, 2])
        z_dot.set_data([t[k]], [pos[k, 2]])
        cursor.set_xdata([t[k], t[k]])
        title.set_text(f"{label} — t = {t[k]:.{decimals}f} s" + (" (stopped)" if stopped and k == end - 1 else ""))
        for artist in moving:
            fig.draw_artist(artist)
        return np.asarray(canvas.buffer_rgba())

    def drawn():
        for done, k in enumerate(frames, 1):
            yield frame(int(k))
            if progress is not None:
                progress(done, len(frames))

    if progress is not None:
        progress(0, len(frames))
    with atomic_path(path) as tmp:
        if kind == ".gif":
            _write_gif(tmp, drawn(), fps, Image)
        else:
            _write_mp4(tmp, drawn(), fps, ffmpeg, canvas.get_width_height())
    return path


def _write_gif(tmp: Path, rgba_frames, fps: float, Image) -> None:
    images, palette = [], None
    for rgba in rgba_frames:
        img = Image.fromarray(rgba[:, :, :3])
        if palette is None:  # one palette for all frames, from the first
            palette = img.quantize(colors=128, method=Image.Quantize.MEDIANCUT)
        images.append(img.quantize(palette=palette, dither=Image.Dither.NONE))
    images[0].save(
        tmp,
        format="GIF",
        save_all=True,
        append_images=images[1:],
        duration=max(20, int(round(1000 / fps))),
        loop=0,
        optimize=False,
    )


def _write_mp4(tmp: Path, rgba_frames, fps: float, ffmpeg: str, size) -> None:
    w, h = size
    cmd = [
        ffmpeg,
        "-y",
        "-loglevel",
        "error",
        "-f",
        "rawvideo",
        "-pix_fmt",
        "rgba",
        "-s",
        f"{w}x{h}",
        "-r",
        f"{fps:g}",
        "-i",
        "-",
        "-an",
        "-vf",
        "pad=ceil(iw/2)*2:ceil(ih/2)*2",
        "-pix_fmt",
        "yuv420p",
        "-f",
        "mp4",
        str(tmp),
    ]
    proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        for rgba in rgba_frames:
            proc.stdin.write(rgba.tobytes())
    except BrokenPipeError:
        pass  # ffmpeg quit early; its message follows
    except BaseException:
        proc.kill()
        proc.wait()
        raise
    _, err = proc.communicate()
    if proc.returncode != 0:
        raise SimulationError(f"ffmpeg failed to write the animation: {err.decode(errors='replace').strip()[-400:]}")
