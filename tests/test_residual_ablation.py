"""experiments/noroll_v3/residual_ablation.py: the policy with joint groups' residual zeroed, and
its use of the action's bound."""

from __future__ import annotations

import argparse
import json
import runpy
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from acl_env import shipped

EXPERIMENTS = Path(__file__).resolve().parent.parent / "experiments"
SCRIPT = EXPERIMENTS / "noroll_v3" / "residual_ablation.py"
SHIPPED_NOROLL = shipped.policy_dir("acl_climb_noroll_ppo")


def _ablation() -> dict[str, Any]:
    """The functions of the residual-ablation script (not a module of the package)."""
    return runpy.run_path(str(SCRIPT), run_name="ablation")


def test_joint_range_parses_ranges_and_refuses_bad_ones() -> None:
    joint_range = _ablation()["joint_range"]
    assert joint_range("0-9") == (0, 9)
    assert joint_range("4") == (4, 4)
    for bad in ("9-3", "a-b", "-1", ""):
        with pytest.raises(argparse.ArgumentTypeError):
            joint_range(bad)


def test_masked_policy_zeroes_only_its_columns_and_leaves_the_policy_output() -> None:
    masked = _ablation()["masked"]
    out = np.arange(1.0, 6.0, dtype=np.float32)
    act = masked(lambda obs: out, np.array([1, 3]))
    assert act(np.zeros(1)).tolist() == [1.0, 0.0, 3.0, 0.0, 5.0]
    assert out.tolist() == [1.0, 2.0, 3.0, 4.0, 5.0]


def test_group_past_the_last_joint_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        _ablation()["main"](["--policy", str(SHIPPED_NOROLL), "--groups", "10-20"])
    assert exit_.value.code == 2
    assert "--groups 10-20: the snake's joints are 0-19" in capsys.readouterr().err


def test_zeroing_every_joint_plays_the_gait(tmp_path: Path) -> None:
    out = tmp_path / "ablation.json"
    argv = [
        "--policy", str(SHIPPED_NOROLL), "--episodes", "1", "--groups", "0-19",
        "--env-kwargs", "cycles_per_episode:1", "--json", str(out), "--no-progress-bar",
    ]  # fmt: skip
    _ablation()["main"](argv)
    document = json.loads(out.read_text())
    rows = {r["controller"]: r for r in document["rows"]}
    assert list(rows) == ["policy", "policy, joints 0-19 zeroed", "zero action (its gait)"]
    climb = {name: r["climb_per_gait_cycle_m"]["mean"] for name, r in rows.items()}
    assert climb["policy, joints 0-19 zeroed"] == climb["zero action (its gait)"]
    assert climb["policy"] != climb["zero action (its gait)"]
    assert len(document["mean_abs_action"]) == len(document["saturated_share"]) == 20
    assert all(0.0 < m <= 1.0 for m in document["mean_abs_action"])
    assert all(0.0 <= s <= 1.0 for s in document["saturated_share"])
