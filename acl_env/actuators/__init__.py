"""The joint actuator models, by the name ``actuator_model`` gives them.

Each model is one module holding an :class:`~acl_env.actuators.base.ActuatorModel`: its options
(default and range, declared once), how it edits the MjSpec, how its joints are read, its energy
count and its randomisation ranges. The env, the model builder, the randomisation and the
evaluation ask the model found here; none of them names one. To add a model, write its module and
add it to :data:`ACTUATOR_MODELS`.

* ``"servo"``: ideal position servos (:mod:`acl_env.actuators.servo`);
* ``"sea"``: the CMU SEA snake's series elastic actuators (:mod:`acl_env.actuators.sea`);
* ``"sea_rotor"``: the SEA with its motor's rotor inertia behind the spring
  (:mod:`acl_env.actuators.sea_rotor`).
"""

from __future__ import annotations

from acl_env.actuators.base import ActuatorModel, Option
from acl_env.actuators.sea import SEA
from acl_env.actuators.sea_rotor import RotorSEA
from acl_env.actuators.servo import Servo

DEFAULT_MODEL = "servo"  # the env's actuator_model unless a task sets one
ACTUATOR_MODELS: dict[str, ActuatorModel] = {
    model.name: model for model in (Servo(), SEA(), RotorSEA())
}


def actuator_model(name: str) -> ActuatorModel:
    """The model registered as ``name`` (``ValueError`` lists the registered ones)."""
    try:
        return ACTUATOR_MODELS[name]
    except KeyError:
        known = ", ".join(map(repr, ACTUATOR_MODELS))
        raise ValueError(f"actuator_model must be one of {known}; got {name!r}") from None


def all_options() -> dict[str, Option]:
    """Every registered model's options by name (models may share one: the SEAs' spring)."""
    return {o.name: o for model in ACTUATOR_MODELS.values() for o in model.options}


def owners(option: str) -> tuple[str, ...]:
    """The models that have ``option``."""
    return tuple(
        m.name for m in ACTUATOR_MODELS.values() if any(o.name == option for o in m.options)
    )


__all__ = [
    "ACTUATOR_MODELS",
    "DEFAULT_MODEL",
    "ActuatorModel",
    "Option",
    "actuator_model",
    "all_options",
    "owners",
]
