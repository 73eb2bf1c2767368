"""How well a gait's joint table plays its backbone: the FK fit per keyframe and a printed
summary (``python -m acl_env.gait``, ``benchmarks/bench_gait.py``)."""

from __future__ import annotations

import numpy as np

from acl_env.gait.gaits import Gait
from acl_env.gait.kinematics import backbone_fit_rms


def cycle_fit_rms(gait: Gait) -> np.ndarray:
    """Per keyframe, rms distance (m) of the FK joints from the backbone, best rigid fit."""
    phases = np.arange(gait.steps_per_cycle) / gait.steps_per_cycle
    backbones = gait.backbones(phases)
    return np.array(
        [
            backbone_fit_rms(angles, points, gait.module_length)[0]
            for angles, points in zip(gait.cycle(), backbones, strict=True)
        ]
    )


def summary(name: str, gait: Gait) -> str:
    """A few lines on one gait: amplitude, saturation, FK fidelity, measured rolls."""
    deg = np.degrees(gait.cycle())
    sat = gait.saturation
    rms = cycle_fit_rms(gait)
    return "\n".join(
        [
            f"{name}: radius {gait.radius:.4f} m, pitch {gait.pitch:.3f} m, "
            f"{gait.n_joints} joints, {gait.steps_per_cycle} keyframes",
            f"  joint angles     {deg.min():+.1f} .. {deg.max():+.1f} deg",
            f"  saturation       {sat.keyframe_fraction:.1%} of keyframes, "
            f"{sat.sample_fraction:.1%} of angles, max excess {np.degrees(sat.max_excess):.1f} deg",
            f"  FK fit rms       mean {100 * rms.mean():.2f} cm, max {100 * rms.max():.2f} cm",
            f"  rolls per cycle  {gait.measured_rolls_per_cycle():+.3f} measured "
            f"({gait.rolls_per_cycle:+g} commanded)",
        ]
    )
