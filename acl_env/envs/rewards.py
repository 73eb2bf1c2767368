"""The reward of the climbing env: one small function per term, weighted by ``reward_weights``.

``reward = sum_term w_term * term(step)``; the env reports each weighted term as
``info["reward_<term>"]``. A new term is a function here and a key of
:data:`DEFAULT_REWARD_WEIGHTS`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import NamedTuple

from acl_env.validation import check_range


class StepMeasures(NamedTuple):
    """What one env step measured (0 for climb and slip when the physics was unstable)."""

    climb: float  # m: rise of the snake's centre of mass along the pole
    slip: float  # m: mean sliding distance of the snake-pole contacts
    # rad: growth of the modules' swept roll range this step (termination.RollSpan), mean over
    # modules; 0 when the physics was unstable
    roll: float = 0.0
    # J: actuator work this step, sum |tau qdot| dt (motors that do not regenerate)
    energy: float = 0.0
    # sum over the action's entries of (a_t - a_{t-1})^2 per joint, in action units (the clipped
    # action; a_{-1} = 0, the zero residual the reset ends on)
    action_rate: float = 0.0


def climb_term(step: StepMeasures) -> float:
    """Progress: the centre-of-mass rise (m)."""
    return step.climb


def slip_term(step: StepMeasures) -> float:
    """Penalty: the mean sliding distance of the contacts on the pole (m), negated."""
    return -step.slip


def roll_term(step: StepMeasures) -> float:
    """Penalty: the growth of the body's swept roll range on the pole (rad), negated. Summed over
    an episode it is minus the mean over modules of the range each module's roll swept, the
    body-frame counterpart of the touched arc (acl_env.evaluation)."""
    return -step.roll


def energy_term(step: StepMeasures) -> float:
    """Penalty: the actuator work of the step (J), negated. The open-loop ACL gait spends about
    1 J per step (1000-1150 J per metre climbed, ~0.2 m per 220-step cycle)."""
    return -step.energy


def action_rate_term(step: StepMeasures) -> float:
    """Penalty: the action's squared change since the last step, negated. A residual that flips
    between the ends of its range at every step reads ~1-4
    (experiments/noroll_climb_gait/action_smoothing.py: such flipping climbs in simulation
    through the soft contact's creep, and shrinks under a harder contact); one smooth over the
    220-step gait cycle reads ~1e-3 or less."""
    return -step.action_rate


REWARD_TERMS: dict[str, Callable[[StepMeasures], float]] = {
    "climb": climb_term,
    "slip": slip_term,
    "roll": roll_term,
    "energy": energy_term,
    "action_rate": action_rate_term,
}
# roll 0: off except on the non-rolling tasks (acl_env/ACLClimbNoRollBase-v3 and those built on
# it), where rolling is what the task forbids; energy and action_rate 0: off unless a recipe asks
# for them. With all three at weight 0 the reward equals climb and slip's to the bit.
DEFAULT_REWARD_WEIGHTS: dict[str, float] = {
    "climb": 1.0,
    "slip": 1.0,
    "roll": 0.0,
    "energy": 0.0,
    "action_rate": 0.0,
}


# Largest |weight|. Every term is bounded (the unstable check zeroes the terms of a step whose state
# is not finite, and MuJoCo resets any value beyond 1e10, so the energy term stays below ~1e12),
# so weights within +-1e6 keep every reward finite; 1.7e308 times a term is inf. A weight is a
# signed scale: the penalties are already negated terms, so a negative weight turns one into a
# bonus (a negative slip weight rewards sliding). That is allowed, for ablations and probes of
# the measures: the reward stays finite, and the env does not second-guess a recipe.
REWARD_WEIGHT_MAX = 1e6


def check_reward_weights(weights: Mapping[str, float] | None) -> dict[str, float]:
    """Validated weights: the defaults overridden by ``weights``, each finite and within
    +-:data:`REWARD_WEIGHT_MAX`; unknown terms raise."""
    merged = {**DEFAULT_REWARD_WEIGHTS, **(weights or {})}
    unknown = set(merged) - set(DEFAULT_REWARD_WEIGHTS)
    if unknown:
        raise ValueError(
            f"reward_weights has unknown terms {sorted(unknown)}; "
            f"known: {sorted(DEFAULT_REWARD_WEIGHTS)}"
        )
    return {
        key: check_range(f"reward_weights[{key!r}]", value, -REWARD_WEIGHT_MAX, REWARD_WEIGHT_MAX)
        for key, value in merged.items()
    }


def reward_terms(weights: Mapping[str, float], step: StepMeasures) -> dict[str, float]:
    """``{"reward_<term>": w_term * term(step)}`` for every term; the reward is their sum."""
    return {f"reward_{name}": weights[name] * term(step) for name, term in REWARD_TERMS.items()}
