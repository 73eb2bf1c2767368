"""An evaluation's figures: the centre of mass's rise over time, and side-by-side videos."""

from __future__ import annotations

import os

# Videos render offscreen; MuJoCo picks its GL backend when first imported, so say it now.
os.environ.setdefault("MUJOCO_GL", "egl")

from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from acl_env.evaluation.baselines import (
    AT_POLICY_CADENCE,
    Controller,
    is_policy,
)
from acl_env.evaluation.intervals import mean_ci95
from acl_env.evaluation.protocol import Episode, run_episode


def _rise(episodes: Sequence[Episode]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Time, and the mean and 95 % CI half-width over ``episodes`` of the centre of mass's rise
    above its start (an episode that ended early counts until it ended)."""
    length = max(len(e.com_height) for e in episodes)
    rise = np.full((len(episodes), length), np.nan)
    for row, e in zip(rise, episodes, strict=True):
        row[: len(e.com_height)] = e.com_height - e.com_height[0]
    stats = [mean_ci95(column) for column in rise.T]
    mean = np.array([s["mean"] for s in stats])
    half = np.nan_to_num(np.array([s["half_width"] for s in stats]))
    return np.arange(length) * episodes[0].dt, mean, half


def plot_heights(
    results: dict[str, list[Episode]],
    path: str | Path,
    labels: dict[str, str] | None = None,
    title: str = "",
) -> None:
    """Centre-of-mass rise above its start against time, mean and 95 % CI band per controller
    (legend: ``labels``, else the names; ``title``: the task and seeds). The controllers at the
    policy's cadence climb nearly alike: a second panel zooms on them over the episode's last
    fifth, where their bands show."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = labels or {}
    group = [n for n in results if is_policy(n) or n in AT_POLICY_CADENCE]
    zoom = len(group) > 1
    fig, axes = plt.subplots(
        1, 2 if zoom else 1, figsize=(11 if zoom else 7, 4.6), layout="constrained", squeeze=False
    )
    palette = plt.get_cmap("tab10" if len(results) <= 10 else "tab20").colors
    colours = {name: palette[i % len(palette)] for i, name in enumerate(results)}
    curves = {name: _rise(episodes) for name, episodes in results.items()}
    for name, (t, mean, half) in curves.items():
        ax = axes[0, 0]
        ax.plot(t, mean, color=colours[name], lw=1.4, label=labels.get(name, name))
        ax.fill_between(t, mean - half, mean + half, color=colours[name], alpha=0.3, lw=0)
    n = len(next(iter(results.values())))
    axes[0, 0].set_title(f"all controllers: mean and 95 % CI over {n} episodes", fontsize=10)
    if zoom:
        ax = axes[0, 1]
        low, high = np.inf, -np.inf
        for name in group:
            t, mean, half = curves[name]
            window = t >= 0.8 * t[-1]
            ax.plot(t[window], mean[window], color=colours[name], lw=1.4)
            ax.fill_between(
                t[window],
                (mean - half)[window],
                (mean + half)[window],
                color=colours[name],
                alpha=0.3,
                lw=0,
            )
            low = min(low, float(np.nanmin((mean - half)[window])))
            high = max(high, float(np.nanmax((mean + half)[window])))
        margin = 0.05 * (high - low or 1.0)
        ax.set_ylim(low - margin, high + margin)
        ax.set_title("at the policy's cadence, last fifth of the episode", fontsize=10)
    for ax in axes[0]:
        ax.set_xlabel("time (s)")
        ax.set_ylabel("centre of mass above start (m)")
        ax.grid(alpha=0.3)
    fig.legend(loc="outside lower center", ncols=3, fontsize=10, frameon=False)
    if title:
        fig.suptitle(title, fontsize=12)
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
        panels.append([_label(frame, controller.title) for frame in frames])
    length = max(len(frames) for frames in panels)
    video = [
        np.concatenate([frames[min(i, len(frames) - 1)] for frames in panels], axis=1)
        for i in range(length)
    ]
    fps = max(1, round(speedup / env.unwrapped.dt))
    if Path(path).suffix.lower() == ".gif":  # imageio's GIF writer takes a frame duration (ms)
        imageio.mimsave(path, video, duration=1000.0 / fps)
    else:
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
