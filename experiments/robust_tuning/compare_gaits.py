"""The paper's gait, the nominal tuned gait and the robust one, open loop on the SEA, and each
tuned gait with its tuned compliant grip, under the conditions where the tuned gait lost the
pole, on the same seeds.

``python experiments/robust_tuning/compare_gaits.py [--episodes 8] [--workers 2] [--json PATH]``

Each condition is a set of env keyword arguments over ``ACLClimb-v3``'s defaults. The three
controllers are the evaluation's own (``acl_env.evaluation.baselines.build_controllers`` for the
SEA task): ``open_loop_acl`` (the paper's gait), and ``open_loop_tuned`` and ``compliant_acl``
played with the entries ``acl_sea`` and ``acl_sea_robust`` of the shipped tuned gaits (and their
grips, ``acl_sea_grip`` and ``acl_sea_robust_grip``).
"""

from __future__ import annotations

import os
from typing import Any

os.environ.setdefault("MUJOCO_GL", "egl")

import gait_grid  # this folder's script (on the path when run as one): the controllers
import numpy as np

from acl_env.evaluation.runner import make_pool, run_controllers
from acl_env.io import console_script
from acl_env.scripts import make_parser, seeds, write_output

# The conditions where acl_sea was seen to lose the pole, the nominal pole, the grid's thinnest
# and thickest, and the friction step.
CONDITIONS: dict[str, dict[str, float]] = {
    "nominal": {},
    "friction 0.5, spring 12": {"friction": 0.5, "spring_stiffness": 12.0},
    "friction 0.5, spring 12, pole 0.08, latency 0.2": {
        "friction": 0.5,
        "spring_stiffness": 12.0,
        "pole_radius": 0.08,
        "control_latency": 0.2,
    },
    "friction 0.5, pole 0.08": {"friction": 0.5, "pole_radius": 0.08},
    "friction 0.5, latency 0.2": {"friction": 0.5, "control_latency": 0.2},
    "pole 0.055": {"pole_radius": 0.055},
    "pole 0.12": {"pole_radius": 0.12},
    # the pole turning slippery (1.0 -> 0.5) at a random step, on the nominal and the soft spring
    "friction step 0.5": {"friction_step": 0.5},
    "friction step 0.5, spring 12": {"friction_step": 0.5, "spring_stiffness": 12.0},
}
GAITS = {
    "open_loop_acl": "paper's gait",
    "acl_sea": "tuned (nominal)",
    "acl_sea_robust": "robust",
    "acl_sea_grip": "compliant (nominal)",
    "acl_sea_robust_grip": "compliant robust",
}


def controllers_for(condition: dict[str, float]) -> list[Any]:
    """The five controllers under ``condition``, named by :data:`GAITS`' keys."""
    return gait_grid.controllers_for(condition, ["acl_sea", "acl_sea_robust"], grips=True)


def _summary(episodes: list[Any]) -> dict[str, Any]:
    """Falls, and the climb per gait cycle and slip per metre over the episodes that held on."""
    held = [e.metrics() for e in episodes if not e.fell]
    return {
        "falls": sum(e.fell for e in episodes),
        "climb_per_gait_cycle_m": (
            float(np.mean([m["climb_per_gait_cycle_m"] for m in held])) if held else None
        ),
        "slip_per_m": float(np.mean([m["slip_per_m"] for m in held])) if held else None,
    }


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = make_parser(__doc__, plot=False, seed=0, episodes=8, workers=2, progress=True)
    args = parser.parse_args(argv)
    played = seeds(args)
    pool = make_pool(args.workers)
    document: dict[str, Any] = {"seeds": played, "conditions": {}}
    try:
        for label, condition in CONDITIONS.items():
            results = run_controllers(
                controllers_for(condition), played, pool, progress=not args.no_progress_bar
            )
            row = {name: _summary(episodes) for name, episodes in results.items()}
            document["conditions"][label] = {"env_kwargs": condition, "controllers": row}
    finally:
        if pool is not None:
            pool.shutdown()
    write_output(args.json, document)  # the record first: a closed pipe loses nothing
    for label, entry in document["conditions"].items():
        cells = [
            f"{GAITS[n]}: "
            + (
                f"{100 * r['climb_per_gait_cycle_m']:.1f} cm"
                if r["climb_per_gait_cycle_m"] is not None
                else "-"
            )
            + f", falls {r['falls']}/{len(played)}"
            for n, r in entry["controllers"].items()
        ]
        print(f"{label:50s} " + "; ".join(cells))
    return document


if __name__ == "__main__":
    console_script(main)()
