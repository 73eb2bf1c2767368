"""The snake's contacts with the pole and the floor, sampled during each step: the ``slip``
measure (mean sliding speed of the snake-pole contacts) and the touches that end an episode."""

from __future__ import annotations

import math

import mujoco
import numpy as np

from acl_env.constants import FLOOR_GEOM

SLIP_SAMPLES = 5  # contact velocities are sampled this many times per step (every 20 ms)


class ContactSampler:
    """Reads MuJoCo's active contacts: which pair of geoms each is, and how fast it slides.

    Holds no MuJoCo memory (a copy of the env keeps it, ``envs/pickling.py``); ``pyramidal`` is
    the model's friction cone, set at every reset so that a cone changed after construction counts.
    """

    def __init__(self, model: mujoco.MjModel, snake_geoms: np.ndarray, pole_geom: int) -> None:
        # Contact pair (g1, g2) -> 1 snake-pole, 2 snake-floor, 0 other, via key g1 * ngeom + g2.
        ngeom = model.ngeom
        pair_kind = np.zeros(ngeom * ngeom, dtype=np.int8)
        for other, code in ((pole_geom, 1), (model.geom(FLOOR_GEOM).id, 2)):
            pair_kind[snake_geoms * ngeom + other] = code
            pair_kind[other * ngeom + snake_geoms] = code
        self.ngeom = ngeom
        self.pair_kind: list[int] = pair_kind.tolist()  # indexed per contact: a list is faster
        self.pyramidal = False

    def sample(self, data: mujoco.MjData) -> tuple[float, bool, bool]:
        """Mean sliding speed (m/s) of the snake-pole contacts; is the pole touched; the floor?

        With an elliptic cone each contact's constraint rows are the normal then the two
        tangential directions; their ``efc_vel`` is the relative sliding velocity. With a
        pyramidal cone the rows are the pyramid's edges ``n +- mu_i t_i``, whose differences
        give the same tangential velocities. Hot path (every contact sample): a plain loop over
        the few contacts costs a third of the vectorised version.
        """
        if data.ncon == 0:
            return 0.0, False, False
        contact = data.contact
        geoms = contact.geom.tolist()
        rows = contact.efc_address.tolist()
        vel = data.efc_vel.tolist()
        friction = contact.friction.tolist() if self.pyramidal else None
        ngeom, pair_kind = self.ngeom, self.pair_kind
        total, count, on_floor = 0.0, 0, False
        for i, ((g1, g2), row) in enumerate(zip(geoms, rows, strict=True)):
            if row < 0:  # excluded by a constraint: not active
                continue
            kind = pair_kind[g1 * ngeom + g2]  # what the contact is (see __init__)
            if kind == 1:
                if friction is None:
                    total += math.hypot(vel[row + 1], vel[row + 2])
                else:  # pyramidal: rows n + mu_j t_j, n - mu_j t_j for j = 1, 2
                    mu = friction[i]
                    total += math.hypot(
                        (vel[row] - vel[row + 1]) / (2.0 * mu[0]),
                        (vel[row + 2] - vel[row + 3]) / (2.0 * mu[1]),
                    )
                count += 1
            elif kind == 2:
                on_floor = True
        return (total / count if count else 0.0), count > 0, on_floor


__all__ = ["SLIP_SAMPLES", "ContactSampler"]
