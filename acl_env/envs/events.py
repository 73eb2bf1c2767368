"""Events within an episode: the pole turning slippery at a random time (``friction_step``).

The robot does not choose its pole, nor when rain makes it slippery: with ``friction_step=f``
the skin's and the pole's sliding friction drop from the episode's friction to ``f`` at a step
drawn uniformly at reset from the episode's second step to its last. In training the event is
randomised with ``domain_randomization={"friction_step": (low, high)}``: every episode's pole
then changes friction, to a value drawn uniformly from the range (below the episode's friction
a step down, above it a step up). Its draws come after every other draw of the reset, so an env
without the option plays as before, bit for bit.
"""

from __future__ import annotations

import mujoco
import numpy as np

from acl_env.envs.randomize import RandomizedElements


class FrictionStep:
    """The friction step of one env: its new friction, and the step it happens at."""

    def __init__(
        self,
        friction: float,
        elements: RandomizedElements,
        drawn: tuple[float, float] | None = None,
    ) -> None:
        self.friction = friction
        self.drawn = drawn  # the (low, high) range each episode's friction is drawn from
        self._geoms = np.append(elements.snake_geoms, elements.pole_geom)
        self.at = 0  # the step whose physics plays on the slippery pole (set at each reset)

    def reset(self, rng: np.random.Generator, episode_steps: int) -> None:
        """Draw the step of this episode's friction step, then its friction when randomised."""
        self.at = int(rng.integers(1, max(2, episode_steps)))
        if self.drawn is not None:
            self.friction = float(rng.uniform(*self.drawn))

    def before_step(self, model: mujoco.MjModel, step: int) -> bool:
        """Write the new friction into ``model`` when ``step`` (steps played so far) is the
        drawn one; whether the pole is slippery for this step."""
        if step == self.at:
            model.geom_friction[self._geoms, 0] = self.friction
        return step >= self.at


__all__ = ["FrictionStep"]
