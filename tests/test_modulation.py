"""Gait modulation actions (acl_env/envs/modulation.py): per-section offsets of the gait's own
parameters, applied through the gait's kinematics."""

from __future__ import annotations

import pickle

import gymnasium as gym
import numpy as np
import pytest

from acl_env import ACL_CLIMB_ID
from acl_env.constants import SEA_MODULE_RADIUS
from acl_env.envs.modulation import GRID, offset_tables, section_weights, table_radius
from acl_env.gait import ACLGait
from acl_env.gait.gaits import helix_radius

SHORT = {"steps_per_cycle": 20, "cycles_per_episode": 1}
MOD = {"squeeze": 0.004, "amp_pitch": 0.01}


def make(**kwargs: object) -> gym.Env:
    return gym.make(ACL_CLIMB_ID, **{**SHORT, **kwargs})


def test_action_layout_joints_then_sections_then_cadence() -> None:
    env = make(gait_modulation=MOD, modulation_sections=3, phase_rate_range=(0.5, 1.5))
    assert env.action_space.shape == (20 + 2 * 3 + 1,)
    env.reset(seed=0)
    action = np.zeros(env.action_space.shape)
    action[-1] = 1.0  # the cadence entry is the last one
    *_, info = env.step(action)
    assert info["phase_rate"] == 1.5


def test_zero_modulation_is_the_plain_env_bit_for_bit() -> None:
    plain, modulated = make(), make(gait_modulation=MOD)
    rng = np.random.default_rng(0)
    for _ in range(2):
        o1, _ = plain.reset(seed=3)
        o2, _ = modulated.reset(seed=3)
        np.testing.assert_array_equal(o1, o2)
        for _ in range(10):
            joints = rng.uniform(-1, 1, 20)
            r1 = plain.step(joints)
            r2 = modulated.step(np.concatenate([joints, np.zeros(8)]))
            np.testing.assert_array_equal(r1[0], r2[0])
            assert r1[1:] == r2[1:]


@pytest.mark.parametrize("fraction", [0.5, -0.75, 0.3])
def test_uniform_squeeze_offset_is_the_tighter_gait(fraction: float) -> None:
    """A uniform offset on every section gives the targets of the gait built with that squeeze:
    exactly on the grid, within 0.01 rad between grid points."""
    env = make(gait_modulation={"squeeze": 0.004}, residual_scale=0.1)
    env.reset(seed=0)
    base = env.unwrapped
    action = np.zeros(env.action_space.shape)
    action[20:] = fraction
    squeeze = base.config.gait.squeeze + 0.004 * fraction
    kwargs = {
        k: v for k, v in base._gait_kwargs(base.config.physics.pole_radius).items() if k != "radius"
    }
    expected = ACLGait(
        **kwargs, radius=helix_radius(base.config.physics.pole_radius, squeeze)
    ).cycle()
    k = int(base._keyframe)
    change = base._modulation(action)
    on_grid = abs(fraction * (GRID - 1) / 2 - round(fraction * (GRID - 1) / 2)) < 1e-12
    tolerance = 1e-12 if on_grid else 0.01
    np.testing.assert_allclose(base._table[k] + change, expected[k], atol=tolerance)
    assert np.abs(change).max() > 0.02  # the offset does bend the joints


def test_one_section_moves_only_its_joints() -> None:
    env = make(gait_modulation={"amp_pitch": 0.01}, modulation_sections=4)
    env.reset(seed=0)
    action = np.zeros(env.action_space.shape)
    action[20] = 1.0  # the head section
    change = env.unwrapped._modulation(action)
    head_centre, next_centre = 0, int(np.ceil(19 / 3))  # section centres at 0, 6.33, ...
    assert np.abs(change[head_centre]) > 0 or np.abs(change[1]) > 0
    np.testing.assert_array_equal(change[next_centre:], 0.0)


def test_section_weights_are_hats_that_sum_to_one() -> None:
    w = section_weights(20, 4)
    np.testing.assert_allclose(w.sum(axis=1), 1.0)
    centres = np.linspace(0, 19, 4)
    for s, c in enumerate(centres):
        if c == round(c):
            assert w[int(c), s] == 1.0
    assert (w >= 0).all()
    np.testing.assert_array_equal(section_weights(5, 1), np.ones((5, 1)))


def test_amplitude_offsets_stop_at_zero() -> None:
    """A wave amplitude cannot go negative: below 0 the offset table stays at the vanished wave."""
    items = tuple(sorted({"radius": 0.09, "amp_radial": 0.002, "n_joints": 8}.items()))
    tables = offset_tables(ACLGait, items, (("amp_radial", 0.004),))
    lowest, zero_wave = tables[0, 0], tables[0, GRID // 4]  # offsets -4 mm and -2 mm
    np.testing.assert_array_equal(lowest, zero_wave)
    assert not tables.flags.writeable


def test_randomized_pole_gets_tables_of_its_radius() -> None:
    """The offset tables follow the pole drawn at reset, computed at its radius rounded to 1 mm."""
    dr = {"pole_radius": [0.065, 0.09]}
    env = make(gait_modulation={"squeeze": 0.004}, domain_randomization=dr)
    tables = {}
    for seed in range(6):
        env.reset(seed=seed)
        base = env.unwrapped
        pole = (
            base.gait.radius + base.config.gait.squeeze - SEA_MODULE_RADIUS
        )  # the gait follows the pole
        tables[table_radius(pole)] = base._offset_tables
    assert len(tables) > 1
    for pole, table in tables.items():
        items = tuple(sorted(base._gait_kwargs(pole).items()))
        expected = offset_tables(ACLGait, items, (("squeeze", 0.004),))
        np.testing.assert_array_equal(table, expected)


def test_modulated_env_pickles_mid_episode() -> None:
    env = make(gait_modulation=MOD)
    env.reset(seed=0)
    rng = np.random.default_rng(1)
    for _ in range(3):
        env.step(rng.uniform(-1, 1, env.action_space.shape))
    copy = pickle.loads(pickle.dumps(env.unwrapped))
    action = rng.uniform(-1, 1, env.action_space.shape)
    a, b = env.unwrapped.step(action), copy.step(action)
    np.testing.assert_array_equal(a[0], b[0])
    assert a[1:] == b[1:]


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"gait_modulation": {"pitch": 0.01}}, "gait_modulation"),
        ({"gait_modulation": {"squeeze": -0.001}}, "gait_modulation\\['squeeze'\\]"),
        ({"gait_modulation": {"squeeze": 0.5}}, "gait_modulation\\['squeeze'\\]"),
        ({"gait_modulation": ["squeeze"]}, "gait_modulation"),
        ({"gait_modulation": MOD, "modulation_sections": 0}, "modulation_sections"),
        ({"gait_modulation": MOD, "modulation_sections": 21}, "modulation_sections"),
        ({"gait_modulation": MOD, "base_gait": "none"}, "gait_modulation"),
    ],
)
def test_bad_modulation_raises_naming_it(kwargs: dict, name: str) -> None:
    with pytest.raises((TypeError, ValueError), match=name):
        make(**kwargs)


def test_action_names_follow_the_action_layout() -> None:
    env = gym.make(
        ACL_CLIMB_ID,
        gait_modulation={"amp_pitch": 0.002, "squeeze": 0.001},
        modulation_sections=3,
        phase_rate_range=(0.5, 1.5),
    )
    names = env.unwrapped.action_names
    assert len(names) == env.action_space.shape[0] == 20 + 2 * 3 + 1
    assert names[:20] == tuple(f"joint_{j}" for j in range(20))
    # Parameter-major, in the order given, then the cadence last (the env's _rate_index).
    assert names[20:26] == (
        *(f"amp_pitch_section_{s}" for s in range(3)),
        *(f"squeeze_section_{s}" for s in range(3)),
    )
    assert names[env.unwrapped._rate_index] == names[-1] == "cadence"
    assert gym.make(ACL_CLIMB_ID).unwrapped.action_names == names[:20]
