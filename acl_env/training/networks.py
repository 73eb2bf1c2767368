"""Policy networks beyond SB3's ``MlpPolicy``, named in a config by their dotted path.

``policy: acl_env.training.networks.LayerNormCriticPolicy`` in a zoo-format entry (this package's
trainer resolves the path; the RL Zoo itself only knows SB3's aliases).
"""

from __future__ import annotations

from stable_baselines3.common.policies import ActorCriticPolicy
from torch import nn


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
