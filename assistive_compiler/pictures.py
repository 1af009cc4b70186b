"""Pictures of an episode: its frames (:func:`episode_frames`, from a Gymnasium env's
``render()``) and the files they go into: a GIF or MP4 of every frame, or a PNG strip of four
(:func:`write_picture`). Used by ``render``, ``demo``, ``evaluate --render`` and ``results``."""

from __future__ import annotations

import importlib.util
import os
from pathlib import Path

import numpy as np

from .errors import SpecError


def episode_frames(env, policy, seed: int, every: int) -> tuple[list[np.ndarray], dict]:
    """Frames of one episode (every ``every`` steps, plus the first and last) and its summary."""
    obs, _ = env.reset(seed=seed)
    frames, total, done, info = [env.render()], 0.0, False, {}
    while not done:
        obs, reward, terminated, truncated, info = env.step(policy(obs))
        total += reward
        done = terminated or truncated
        if env.steps % every == 0 or done:
            frames.append(env.render())
    return frames, {"return": total, "success": bool(info.get("task_success")), "steps": env.steps}


MONTAGE_AT = (0.0, 0.1, 0.25, 1.0)
"""Where in an episode the PNG strip's frames are taken: the start, the approach (most motion in
these tasks happens early), and the end."""


def montage(frames: list[np.ndarray], at: tuple[float, ...] = MONTAGE_AT) -> np.ndarray:
    """Frames at fractions ``at`` of the episode, side by side: the episode at a glance."""
    idx = [round(f * (len(frames) - 1)) for f in at]
    return np.concatenate([frames[i] for i in idx], axis=1)


PICTURE_SUFFIXES = (".gif", ".mp4", ".png")
"""What ``render --out`` writes: a GIF or an MP4 of every recorded frame, or a PNG strip."""


def check_picture_path(out: Path) -> None:
    """Refuse an output ``render`` cannot write before anything is simulated."""
    if out.suffix.lower() not in PICTURE_SUFFIXES:
        raise SpecError.at(
            str(out),
            f"--out must end in {', '.join(PICTURE_SUFFIXES)} (a GIF or MP4 of the episode, a PNG strip), got '{out.suffix or out.name}'",
        )
    if out.is_dir():
        raise SpecError.at(str(out), "--out is a directory; expected a file name ending in .gif, .mp4 or .png")
    parent = out.parent if str(out.parent) else Path(".")
    existing = next((p for p in (parent, *parent.parents) if p.exists()), Path("."))
    if not existing.is_dir() or not os.access(existing, os.W_OK):
        raise SpecError.at(str(out), f"cannot write here: {existing} is not a writable folder")
    if out.suffix.lower() == ".mp4" and importlib.util.find_spec("av") is None:
        raise SpecError.at(
            str(out),
            "MP4 output needs the optional 'av' package (PyAV, which carries its own FFmpeg): "
            "pip install 'assistive-compiler[video]'; or write a .gif",
        )


def write_picture(frames: list[np.ndarray], out: Path, fps: float) -> None:
    """``out``: a GIF or an MP4 of every frame at ``fps`` frames per second, or a PNG strip (:func:`montage`)."""
    from PIL import Image

    check_picture_path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    suffix = out.suffix.lower()
    if suffix == ".gif":
        images = [Image.fromarray(f) for f in frames]
        # GIF frame delays are whole hundredths of a second.
        images[0].save(
            out, save_all=True, append_images=images[1:], duration=10 * max(1, round(100 / fps)), loop=0, optimize=False
        )
    elif suffix == ".mp4":
        write_mp4(frames, out, fps)
    else:
        Image.fromarray(montage(frames)).save(out)


def write_mp4(frames: list[np.ndarray], out: Path, fps: float) -> None:
    """An H.264 MP4 (yuv420p, so every player shows it; odd sizes cropped to even) at ``fps``."""
    from fractions import Fraction

    import av

    height, width = (frames[0].shape[0] // 2) * 2, (frames[0].shape[1] // 2) * 2
    with av.open(str(out), mode="w") as container:
        stream = container.add_stream("libx264", rate=Fraction(fps).limit_denominator(1000))
        stream.width, stream.height, stream.pix_fmt = width, height, "yuv420p"
        for frame in frames:
            for packet in stream.encode(
                av.VideoFrame.from_ndarray(np.ascontiguousarray(frame[:height, :width]), format="rgb24")
            ):
                container.mux(packet)
        for packet in stream.encode():
            container.mux(packet)
