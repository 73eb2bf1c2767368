"""Policy networks beyond SB3's ``MlpPolicy``, named in a config by their dotted path.

``policy: acl_env.training.networks.LayerNormCriticPolicy`` (or ``AsymmetricCriticPolicy``) in a
zoo-format entry (this package's trainer resolves the path; the RL Zoo itself only knows SB3's
aliases).
"""

from __future__ import annotations

from typing import Any

import torch
from stable_baselines3.common.policies import ActorCriticPolicy
from stable_baselines3.common.type_aliases import Schedule
from torch import nn

from acl_env.envs.observations import PRIVILEGED
from acl_env.validation import check_int


class LayerNormCriticPolicy(ActorCriticPolicy):
    """``MlpPolicy`` whose critic normalises each hidden layer (Linear, LayerNorm, activation).

    Layer normalisation keeps the critic's hidden activations at a fixed scale while its targets
    move (Ba et al. 2016; used in the critics of DroQ, Hiraoka et al. 2022, and CrossQ-style
    methods). The actor is left as ``MlpPolicy`` builds it, so a zero-mean residual still starts
    as the open-loop gait.
    """

    def _build_mlp_extractor(self) -> None:
        super()._build_mlp_extractor()
        layers: list[nn.Module] = []
        for module in self.mlp_extractor.value_net:
            layers.append(module)
            if isinstance(module, nn.Linear):
                layers.append(nn.LayerNorm(module.out_features))
        self.mlp_extractor.value_net = nn.Sequential(*layers)


class AsymmetricCriticPolicy(ActorCriticPolicy):
    """``MlpPolicy`` whose critic sees the whole observation and whose actor does not see its
    last ``critic_only`` entries: by default the env's privileged block (``privileged_obs=True``:
    the centre of mass and the physics a robot cannot sense, ``envs/observations.py``).

    An asymmetric actor-critic (Pinto et al. 2018; the teacher's critic in Lee et al. 2020): the
    value of a state depends on the pole's friction and the springs, which the advantage then
    carries, while the actor stays a policy of the robot's own sensors. The actor's first layer
    keeps the full width, so the network exports as ``MlpPolicy``'s; its weights on the hidden
    entries are zero, their gradient masked, and zeroed again whenever weights are loaded.
    """

    def __init__(self, *args: Any, critic_only: int = len(PRIVILEGED), **kwargs: Any) -> None:
        self.critic_only = check_int("critic_only", critic_only, 1, 10**6)
        super().__init__(*args, **kwargs)

    def _build(self, lr_schedule: Schedule) -> None:
        super()._build(lr_schedule)
        first = self.actor_input_layer
        if first.in_features <= self.critic_only:
            raise ValueError(
                f"critic_only={self.critic_only} hides every one of the actor's "
                f"{first.in_features} inputs"
            )
        mask = torch.ones_like(first.weight)
        mask[:, -self.critic_only :] = 0.0
        self.register_buffer("actor_input_mask", mask, persistent=False)
        first.weight.register_hook(lambda grad: grad * self.actor_input_mask)
        self._hide_from_actor()

    @property
    def actor_input_layer(self) -> nn.Linear:
        """The actor's first hidden layer."""
        layers = list(self.mlp_extractor.policy_net)
        if not layers or not isinstance(layers[0], nn.Linear):
            raise ValueError("AsymmetricCriticPolicy needs a hidden layer in the actor (net_arch)")
        return layers[0]

    def _hide_from_actor(self) -> None:
        with torch.no_grad():
            self.actor_input_layer.weight.mul_(self.actor_input_mask)

    def load_state_dict(self, *args: Any, **kwargs: Any) -> Any:
        """Load weights (SB3's load, ``--init-from``), the hidden entries' kept at zero."""
        result = super().load_state_dict(*args, **kwargs)
        self._hide_from_actor()
        return result

    def _get_constructor_parameters(self) -> dict[str, Any]:
        return {**super()._get_constructor_parameters(), "critic_only": self.critic_only}
