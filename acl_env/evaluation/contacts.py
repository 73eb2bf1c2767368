"""Where the snake touches the pole: the active snake-pole contacts per module, and the arc of
each module's circumference they touched (the protocol's ``touched_arc_deg``).

After every step, each active snake-pole contact is expressed in the frame of its module's link
(x along the module's axis) and binned by its angle about that axis into :data:`ARC_BINS` bins; a
module's touched arc is the shortest arc that covers every bin it touched in the episode (360
minus the largest untouched gap), and the metric is the largest over modules. 360 means no spot
on the skin stayed clear of the pole, i.e. no place for a sensor.
"""

from __future__ import annotations

import gymnasium
import numpy as np

from acl_env.constants import POLE_GEOM, link_name, shell_name

ARC_BINS = 36  # 10-degree bins about each module's axis


class PoleContacts:
    """The active snake-pole contacts of an env's current state, per module.

    ``env`` is any (wrapped) ``ACLClimbEnv``; the ids are looked up once. Calling the object
    returns ``(module, local, world)``: the module index (0 = head) of each contact, the contact
    point in that module's link frame (x along the module's axis) and in the world frame.
    """

    def __init__(self, env: gymnasium.Env) -> None:
        base = env.unwrapped
        self.model, self.data = base.model, base.data
        n_modules = int(base.n_joints) + 1
        self.n_modules = n_modules
        self.pole = self.model.geom(POLE_GEOM).id
        self.module_of_geom = np.full(self.model.ngeom, -1)
        for k in range(n_modules):
            self.module_of_geom[self.model.geom(shell_name(k)).id] = k
        self.bodies = np.array([self.model.body(link_name(k)).id for k in range(n_modules)])

    def __call__(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        data, ncon = self.data, self.data.ncon
        geoms = data.contact.geom[:ncon]
        other = np.where(geoms[:, 0] == self.pole, geoms[:, 1], geoms[:, 0])
        on_pole = (
            (geoms == self.pole).any(axis=1)
            & (self.module_of_geom[other] >= 0)
            & (data.contact.efc_address[:ncon] >= 0)  # excluded contacts exert nothing
        )
        module = self.module_of_geom[other[on_pole]]
        world = data.contact.pos[:ncon][on_pole].copy()
        local = np.einsum("kji,kj->ki", self.rotations(module), world - self.positions(module))
        return module, local, world

    def rotations(self, modules: np.ndarray) -> np.ndarray:
        """World rotation matrices of the modules' link frames, shape ``(len(modules), 3, 3)``."""
        return self.data.xmat[self.bodies[modules]].reshape(-1, 3, 3)

    def positions(self, modules: np.ndarray) -> np.ndarray:
        """World positions of the modules' link frames, shape ``(len(modules), 3)``."""
        return self.data.xpos[self.bodies[modules]]


def arc_bins(local: np.ndarray, bins: int = ARC_BINS) -> np.ndarray:
    """Bin of each point's angle about the module axis (x): ``atan2(z, y)`` in ``bins`` bins."""
    angle = np.arctan2(local[:, 2], local[:, 1]) % (2.0 * np.pi)
    return np.minimum((angle * bins / (2.0 * np.pi)).astype(int), bins - 1)


def covering_arc_deg(touched: np.ndarray) -> np.ndarray:
    """Per row of touched bins (modules x bins, bool): the shortest arc covering every touched
    bin, in degrees: 0 if none, 360 minus the largest circular run of untouched bins otherwise."""
    touched = np.atleast_2d(np.asarray(touched, dtype=bool))
    bins = touched.shape[1]
    arcs = np.zeros(len(touched))
    for row, mask in enumerate(touched):
        if not mask.any():
            continue
        gap = run = 0
        for clear in np.concatenate([~mask, ~mask]):  # twice round: gaps across bin 0
            run = run + 1 if clear else 0
            gap = max(gap, run)
        arcs[row] = 360.0 * (bins - min(gap, bins)) / bins
    return arcs
