"""experiments/noroll_climb_gait/action_smoothing.py and the physics overrides it applies
(acl_env.model)."""

from __future__ import annotations

import json
import re
import runpy
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest

from acl_env import shipped
from acl_env.constants import CONTACT_TIMECONST, POLE_GEOM, shell_name
from acl_env.envs.kwargs import make_quietly
from acl_env.model import apply_physics_options, build_model

ROOT = Path(__file__).resolve().parent.parent
SCRIPT = ROOT / "experiments" / "noroll_climb_gait" / "action_smoothing.py"
SHIPPED_NOROLL = shipped.policy_dir("acl_climb_noroll_ppo")
TWO_STAGE_NOROLL = ROOT / "experiments" / "noroll_two_stage" / "noroll_two_stage"


def _smoothing() -> dict[str, Any]:
    """The functions of the action-smoothing script (not a module of the package)."""
    return runpy.run_path(str(SCRIPT), run_name="smoothing")


def test_contact_timeconst_reaches_shells_and_pole_and_nothing_else() -> None:
    model = build_model()
    before = model.geom_solref.copy()
    apply_physics_options(model, {"contact_timeconst": 0.002, "impratio": 20.0})
    changed = np.flatnonzero(model.geom_solref[:, 0] != before[:, 0])
    names = {mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, i) for i in changed}
    assert POLE_GEOM in names and shell_name(0) in names
    assert np.all(before[changed, 0] == CONTACT_TIMECONST)
    assert np.all(model.geom_solref[changed, 0] == 0.002)
    assert model.opt.impratio == 20.0


def test_unknown_physics_option_is_refused_naming_it() -> None:
    with pytest.raises(ValueError, match=r"unknown physics option 'stiffness'.*contact_timeconst"):
        apply_physics_options(build_model(), {"stiffness": 1.0})


def test_held_policy_commands_every_k_steps_from_the_reset() -> None:
    held = _smoothing()["held"]
    calls: list[float] = []

    def policy(obs: np.ndarray) -> np.ndarray:
        calls.append(float(obs[0]))
        return obs.copy()

    act = held(policy, 3)
    out = [float(act(np.array([t], dtype=float))[0]) for t in range(7)]
    assert out == [0, 0, 0, 3, 3, 3, 6]
    assert calls == [0, 3, 6]


def test_high_band_share_tells_flipping_from_a_smooth_residual() -> None:
    high_band_share = _smoothing()["high_band_share"]
    t = np.arange(440)
    flipping = np.where(t % 2 == 0, 1.0, -1.0)[:, None] * np.ones((1, 3))
    smooth = np.sin(2 * np.pi * t / 220)[:, None] * np.ones((1, 3))
    assert high_band_share(flipping) > 0.99
    assert high_band_share(smooth) < 0.01


def test_contact_under_two_steps_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    argv = ["--policy", str(SHIPPED_NOROLL), "--timestep", "0.002", "--contact-timeconsts", "0.003"]
    with pytest.raises(SystemExit) as exit_:
        _smoothing()["main"](argv)
    assert exit_.value.code == 2
    assert re.search(r"--contact-timeconsts 0.003 is under two --timestep", capsys.readouterr().err)


def test_rows_cover_every_setting_and_controller(tmp_path: Path) -> None:
    out = tmp_path / "smoothing.json"
    argv = [
        "--policy", str(SHIPPED_NOROLL), "--episodes", "1", "--holds", "1", "2",
        "--timestep", "0.002", "--contact-timeconsts", "0.004",
        "--env-kwargs", "cycles_per_episode:1", "--json", str(out), "--no-progress-bar",
    ]  # fmt: skip
    document = _smoothing()["main"](argv)
    rows = json.loads(out.read_text())["rows"]
    assert [(r["physics"], r["controller"]) for r in rows] == [
        (physics, controller)
        for physics in ("the env's physics", "2 ms step, 4 ms contact")
        for controller in ("policy", "policy, held 2", "zero action (its gait)")
    ]
    means = [r["climb_per_gait_cycle_m"]["mean"] for r in rows]
    assert means == [r["climb_per_gait_cycle_m"]["mean"] for r in document["rows"]]
    zero = [r for r in rows if r["controller"].startswith("zero")]
    assert all(r["action_step"] == 0.0 for r in zero)
    assert all(np.isfinite(r["climb_per_gait_cycle_m"]["mean"]) for r in rows)


@pytest.mark.parametrize(("folder", "flips"), [(SHIPPED_NOROLL, False), (TWO_STAGE_NOROLL, True)])
def test_shipped_noroll_policy_does_not_flip_its_action(folder: Path, flips: bool) -> None:
    """The non-rolling policy shipped before (two stages, no action-rate penalty) climbed mostly
    by flipping its residual at the control rate: about 0.6 of the range's half width per step
    (README, "Chatter"). The shipped recipe's action-rate term keeps the policy smooth."""

    from acl_env.evaluation import run_episode
    from acl_env.evaluation.tasks import evaluation_env_kwargs
    from acl_env.training.policy import load_policy, read_policy_folder

    policy = read_policy_folder(folder)
    # the policy's own (older) task version, made as its record was: quietly
    env = make_quietly(policy.env_id, **evaluation_env_kwargs(policy), cycles_per_episode=1)
    # Both are pretrained folders (the experiment's SB3 run exported to numpy): no pickle loads.
    episode = run_episode(env, load_policy(policy, env), 0)
    env.close()
    change = episode.metrics()["action_change"]
    assert episode.steps > 100 and not episode.fell
    assert (change > 0.3) if flips else (change < 0.1), change
