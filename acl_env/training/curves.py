"""Plot learning curves of training runs from their TensorBoard logs.

    acl-plot-curves runs/<run_a> runs/<run_b> --labels A B --out curves.png

Panels: episode climb (m), contact slip per step (m), episode return (normalised reward) and the
policy's action std, against environment steps. ``--json PATH`` also writes the curves.
``--start-steps`` shifts each run's steps: a run warm-started (``--init-from``) from another's
policy counts its steps from 0, and starts where that one ended.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

from acl_env import cli
from acl_env.io import atomic_output, console_script, write_json

FIGURE_SUFFIXES = (".png", ".pdf", ".svg")
PANELS = {
    "charts/episode_climb": "episode climb (m)",
    "charts/slip": "slip per step (m)",
    "charts/energy": "energy per step (J)",
    "rollout/ep_rew_mean": "episode return",
    # With gSDE (use_sde) SB3 logs the std of the noise weights, not of the actions.
    "train/std": "action std (gSDE: noise weights)",
}


def read_curves(run_dir: str | Path) -> dict[str, list[tuple[int, float]]]:
    """Scalars of ``PANELS`` from every TensorBoard event file under ``run_dir``, by step."""
    curves: dict[str, dict[int, float]] = {tag: {} for tag in PANELS}
    for events in sorted(Path(run_dir).rglob("events.out.tfevents*")):
        acc = EventAccumulator(str(events), size_guidance={"scalars": 0})
        acc.Reload()
        for tag in PANELS:
            if tag in acc.Tags()["scalars"]:
                curves[tag].update({e.step: e.value for e in acc.Scalars(tag)})
    return {tag: sorted(points.items()) for tag, points in curves.items()}


def main(argv: Sequence[str] | None = None) -> None:
    """Entry point (``acl-plot-curves``): plot the runs' curves, optionally write them as JSON."""
    parser = cli.ArgumentParser(prog="acl-plot-curves", description=(__doc__ or "").splitlines()[0])
    parser.add_argument(
        "runs", nargs="+", type=cli.existing_dir, help="run folders (with tb/ logs)"
    )
    parser.add_argument("--labels", nargs="*", help="one label per run (default: folder names)")
    parser.add_argument(
        "--out",
        required=True,
        type=cli.output_file(*FIGURE_SUFFIXES),
        help=f"image file ({', '.join(FIGURE_SUFFIXES)})",
    )
    parser.add_argument("--json", type=cli.output_file(".json"), help="write the curves as JSON")
    parser.add_argument(
        "--start-steps",
        nargs="*",
        type=cli.int_at_least(0, cli.MAX_COUNT),
        help="env steps each run starts at (default 0): a warm start's source run's length",
    )
    args = parser.parse_args(argv)
    labels = args.labels or [Path(run).name for run in args.runs]
    if len(labels) != len(args.runs):
        parser.error("--labels needs one label per run")
    starts = args.start_steps or [0] * len(args.runs)
    if len(starts) != len(args.runs):
        parser.error("--start-steps needs one number per run")
    data = {
        label: {
            tag: [(step + start, value) for step, value in points]
            for tag, points in read_curves(run).items()
        }
        for label, run, start in zip(labels, args.runs, starts, strict=True)
    }
    fig, axes = plt.subplots(
        1, len(PANELS), figsize=(4.2 * len(PANELS), 3.4 + 0.2 * len(data)), layout="constrained"
    )
    # Matplotlib's default cycle repeats after 10 colours; tab20 keeps up to 20 runs apart.
    colours = plt.get_cmap("tab10" if len(data) <= 10 else "tab20").colors
    for ax, (tag, title) in zip(axes, PANELS.items(), strict=True):
        for i, (label, curves) in enumerate(data.items()):
            if curves[tag]:
                steps, values = zip(*curves[tag], strict=True)
                ax.plot(steps, values, label=label, lw=1.2, color=colours[i % len(colours)])
        ax.set_title(title)
        ax.set_xlabel("env steps")
        ax.grid(alpha=0.3)
    # One legend under the panels: long labels neither cover the curves nor squeeze the panels.
    handles, names = axes[0].get_legend_handles_labels()
    fig.legend(handles, names, loc="outside lower center", ncols=2, fontsize=9, frameon=False)
    with atomic_output(args.out) as path:
        fig.savefig(path, dpi=110)
    plt.close(fig)
    if args.json:  # every file first, then the printing
        write_json(args.json, data, indent=None)
    print(f"wrote {args.out}")


# The console script (pyproject.toml).
run = console_script(main)

if __name__ == "__main__":
    run()
