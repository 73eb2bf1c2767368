"""Look at the gaits: ``python -m acl_env.gait [--plot FILE]`` (console script ``acl-gait-plot``).

Without ``--plot`` it prints, for the ACL gait (Eq. 1-5) and the rolling helix, the joint-angle
range, the share of the cycle clipped at +-90 deg, how far the jointed chain sits from the
backbone curve (forward kinematics, best rigid fit) and how many times the body rolls per cycle.
With ``--plot FILE`` it draws, per gait, the backbone around the pole at several phases with the
fitted chain on it, and a heatmap of the joint angles over the cycle.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from acl_env.gait.curves import PitchVaryingHelix, sample_curve
from acl_env.gait.gaits import DEFAULT_POLE_RADIUS, ACLGait, Gait, RollingHelixGait
from acl_env.gait.kinematics import place_chain
from acl_env.gait.summary import summary
from acl_env.io import console_script

PLOT_PHASES = (0.0, 0.25, 0.5, 0.75)


def make_gaits(
    radius: float | None = None,
    pitch: float | None = None,
    amp_pitch: float | None = None,
    rolls_per_cycle: float | None = None,
) -> dict[str, Gait]:
    """The ACL gait and the rolling helix, sharing every parameter given (None = default)."""
    shared = {"radius": radius, "pitch": pitch, "rolls_per_cycle": rolls_per_cycle}
    shared = {k: v for k, v in shared.items() if v is not None}
    acl_only = {} if amp_pitch is None else {"amp_pitch": amp_pitch}
    return {"ACL": ACLGait(**shared, **acl_only), "rolling helix": RollingHelixGait(**shared)}


def dense_backbone(gait: Gait, phase: float, n_samples: int = 600) -> np.ndarray:
    """The continuous backbone curve from head to tail tip at ``phase``, shape ``(M, 3)``."""
    curve = getattr(gait, "curve", None) or PitchVaryingHelix(gait.radius, gait.pitch)
    samples = sample_curve(curve, np.array([phase]), gait.body_length, n_samples)
    return samples.points[0, samples.s[0] <= gait.body_length]


def fitted_chain(gait: Gait, phase: float) -> tuple[np.ndarray, np.ndarray]:
    """Chain points (head tip, joints, tail tip) and link z (dorsal) axes, fitted to the curve."""
    chain = place_chain(gait.joint_angles(phase), gait.backbone(phase), gait.module_length)
    return chain.points, chain.frames[:, :, 2]


def _draw_pole(ax, z_low: float, z_high: float) -> None:
    theta, z = np.meshgrid(np.linspace(0, 2 * np.pi, 40), np.array([z_low, z_high]))
    r = DEFAULT_POLE_RADIUS
    ax.plot_surface(r * np.cos(theta), r * np.sin(theta), z, color="tab:brown", alpha=0.18, lw=0)


def _draw_phase(ax, name: str, gait: Gait, phase: float) -> None:
    curve = dense_backbone(gait, phase)
    points, dorsal = fitted_chain(gait, phase)
    z_low, z_high = curve[:, 2].min() - 0.03, curve[:, 2].max() + 0.03
    _draw_pole(ax, z_low, z_high)
    ax.plot(*curve.T, color="tab:blue", lw=1.2, label="backbone")
    ax.plot(*points.T, color="k", lw=2.2, marker="o", ms=2.5, label="chain (FK)")
    ax.scatter(*points[0], color="tab:red", s=30, depthshade=False, label="head")
    # A tick on each link's dorsal side (link z axis) shows the body's roll.
    mids = 0.5 * (points[:-1] + points[1:])
    ticks = np.stack([mids, mids + 0.025 * dorsal], axis=1)
    for i, tick in enumerate(ticks):
        ax.plot(*tick.T, color="tab:orange", lw=1.0, label=None if i else "dorsal side")
    half = gait.radius + 0.04
    ax.set(xlim=(-half, half), ylim=(-half, half), zlim=(z_low, z_high))
    ax.set_box_aspect((2 * half, 2 * half, z_high - z_low))
    ax.set_title(f"{name}, phase {phase:g}", fontsize=10)
    ax.tick_params(labelsize=6)
    ax.set_xlabel("x (m)", fontsize=7)
    ax.set_ylabel("y (m)", fontsize=7)
    ax.set_zlabel("z (m)", fontsize=7)


def plot(gaits: dict[str, Gait], path: str | Path, phases: Sequence[float] = PLOT_PHASES) -> None:
    """Write the figure: per gait, 3-D backbones with the fitted chain, and the angle heatmap."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    n = len(phases)
    fig = plt.figure(figsize=(3.4 * n + 6.0, 4.6 * len(gaits)), layout="constrained")
    grid = fig.add_gridspec(len(gaits), n + 1, width_ratios=[1.0] * n + [1.8])
    for row, (name, gait) in enumerate(gaits.items()):
        for col, phase in enumerate(phases):
            ax = fig.add_subplot(grid[row, col], projection="3d")
            _draw_phase(ax, name, gait, phase)
        if row == 0:
            ax.legend(loc="upper right", fontsize=7, bbox_to_anchor=(1.25, 1.0))
        ax = fig.add_subplot(grid[row, n])
        image = ax.imshow(
            np.degrees(gait.cycle()).T,
            aspect="auto",
            origin="lower",
            cmap="RdBu_r",
            vmin=-90,
            vmax=90,
            extent=(0.0, 1.0, -0.5, gait.n_joints - 0.5),
            interpolation="nearest",
        )
        ax.set(
            xlabel="phase (cycles)",
            ylabel="joint (0 = head; even dorsal, odd lateral)",
            title=f"{name}: joint angles over one cycle",
        )
        ax.set_yticks(np.arange(0, gait.n_joints, 2 if gait.n_joints > 24 else 1))
        ax.tick_params(axis="y", labelsize=7)
        fig.colorbar(image, ax=ax, label="joint angle (deg)")
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv: Sequence[str] | None = None) -> int:
    """Command line: print a summary of both gaits, or draw them with ``--plot FILE``."""
    parser = argparse.ArgumentParser(
        prog="python -m acl_env.gait",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--plot", metavar="FILE", type=Path, help="write the figure to FILE")
    parser.add_argument("--radius", type=float, help="backbone helix radius r (m)")
    parser.add_argument("--pitch", type=float, help="rise per turn (m)")
    parser.add_argument("--amp-pitch", type=float, help="ACL axial wave amplitude A_p (m)")
    parser.add_argument("--rolls-per-cycle", type=float, help="body rolls per cycle (whole)")
    args = parser.parse_args(None if argv is None else [str(a) for a in argv])
    try:
        gaits = make_gaits(args.radius, args.pitch, args.amp_pitch, args.rolls_per_cycle)
    except ValueError as err:
        parser.error(str(err))
    if args.plot is None:
        print("\n".join(summary(name, gait) for name, gait in gaits.items()))
    else:
        plot(gaits, args.plot)
        print(f"wrote {args.plot}")
    return 0


# The console script (pyproject.toml) and ``python -m acl_env.gait``.
run = console_script(main)

if __name__ == "__main__":
    run()
