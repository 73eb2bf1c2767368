"""An evaluation's figures: the centre of mass's rise over time, and side-by-side videos."""

from __future__ import annotations

import os

# Videos render offscreen; MuJoCo picks its GL backend when first imported, so say it now.
os.environ.setdefault("MUJOCO_GL", "egl")

from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from acl_env.evaluation.baselines import Controller
from acl_env.evaluation.protocol import Episode, mean_ci95, run_episode


def plot_heights(results: dict[str, list[Episode]], path: str | Path) -> None:
    """Centre-of-mass rise above its start against time: mean and 95 % CI band per controller."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4), constrained_layout=True)
    for name, episodes in results.items():
        length = max(len(e.com_height) for e in episodes)
        rise = np.full((len(episodes), length), np.nan)
        for row, e in zip(rise, episodes, strict=True):
            row[: len(e.com_height)] = e.com_height - e.com_height[0]
        stats = [mean_ci95(column) for column in rise.T]
        mean = np.array([s["mean"] for s in stats])
        half = np.nan_to_num(np.array([s["half_width"] for s in stats]))
        t = np.arange(length) * episodes[0].dt
        ax.plot(t, mean, label=name)
        ax.fill_between(t, mean - half, mean + half, alpha=0.25)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("COM height above start (m)")
    ax.set_title(f"mean ± 95 % CI over {len(next(iter(results.values())))} episodes")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def record_video(
    controllers: Sequence[Controller], seed: int, path: str | Path, speedup: float = 1.0
) -> None:
    """One episode (reset ``seed``) of each controller rendered offscreen (``rgb_array``), side
    by side and labelled, to a video file; a shorter episode holds its last frame. ``speedup``
    times real time (one frame per env step)."""
    import imageio

    panels = []
    for controller in controllers:
        env = controller.make_env(render_mode="rgb_array")
        frames: list[np.ndarray] = []
        run_episode(env, controller.make_policy(env), seed, _grab(frames))
        env.close()
        panels.append([_label(frame, controller.name) for frame in frames])
    length = max(len(frames) for frames in panels)
    video = [
        np.concatenate([frames[min(i, len(frames) - 1)] for frames in panels], axis=1)
        for i in range(length)
    ]
    fps = max(1, round(speedup / env.unwrapped.dt))
    imageio.mimsave(path, video, fps=fps)


def _grab(frames: list[np.ndarray]) -> Callable[..., None]:
    """A ``run_episode`` hook that appends each step's rendered frame to ``frames``."""
    return lambda env, *_: frames.append(env.render())


def _label(frame: np.ndarray, text: str) -> np.ndarray:
    """The frame with ``text`` in its top-left corner (Pillow, which matplotlib brings)."""
    from PIL import Image, ImageDraw

    image = Image.fromarray(frame)
    draw = ImageDraw.Draw(image)
    draw.rectangle((0, 0, 8 + 7 * len(text), 18), fill=(0, 0, 0))
    draw.text((4, 3), text, fill=(255, 255, 255))
    return np.asarray(image)
