"""Bad command lines of the open-loop tuner (``acl-tune-gait``): each is refused before any work,
with exit status 2 and one stderr line naming the option, no traceback, and nothing written (no
study database, tuned-gaits file or figure), run from an empty folder where the default outputs
would land."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from acl_env.tuning.cli import main

ROOT = Path(__file__).resolve().parents[1]
HUGE = "9" * 400  # a 400-digit integer
# Tiny episodes, so that a case that wrongly got through would still end quickly.
TINY = ["--steps-per-cycle", "20", "--cycles", "1", "--n-trials", "1", "--no-progress-bar"]
# Files some cases read, made in the folder before the command runs (and so not "written").
CONFIGS = {
    "misspelt.yml": "acl_env/ACLClimb-v1:\n  env_kwargs:\n    reward_weight: {climb: 1.0}\n",
    "unknown_name.yml": "acl_env/ACLClimb-v1:\n  n_timestep: 1000\n",
    "bad_weight.yml": "acl_env/ACLClimb-v1:\n  env_kwargs:\n    reward_weights: {climb: abc}\n",
    "not_a_mapping.yml": "acl_env/ACLClimb-v1: [1, 2]\n",
    "not_gaits.json": "[1, 2]\n",
}

CASES: list[tuple[str, list[str]]] = [
    ("--seeds", ["--seeds", "-1"]),
    ("--seeds", ["--seeds", HUGE]),
    ("--seeds", ["--seeds", "abc"]),
    ("--seeds", ["--seeds", "1.5"]),
    ("--seeds", ["--seeds", "0", "0"]),
    ("--seeds", ["--seeds", str(2**31)]),
    ("--n-trials", ["--n-trials", "0"]),
    ("--n-trials", ["--n-trials", HUGE]),
    ("--n-trials", ["--n-trials", "1e3"]),
    ("--n-jobs", ["--n-jobs", "0"]),
    ("--n-jobs", ["--n-jobs", "5000"]),
    ("--steps-per-cycle", ["--steps-per-cycle", "1"]),
    ("--steps-per-cycle", ["--steps-per-cycle", "99999"]),
    ("--cycles", ["--cycles", "0"]),
    ("--cycles", ["--cycles", "9"]),
    ("--validate-seeds", ["--validate-seeds", "-1"]),
    ("--validate-top", ["--validate-top", "0"]),
    ("--sampler-seed", ["--sampler-seed", "-1"]),
    ("--sampler-seed", ["--sampler-seed", HUGE]),
    ("--heartbeat", ["--heartbeat", "-1"]),
    ("--heartbeat", ["--heartbeat", "1.5"]),
    ("--heartbeat", ["--heartbeat", HUGE]),
    ("--max-clipped", ["--max-clipped", "nan"]),
    ("--max-clipped", ["--max-clipped", "1e309"]),
    ("--max-clipped", ["--max-clipped", "-0.1"]),
    ("--max-arc", ["--max-arc", "inf"]),
    ("--max-arc", ["--max-arc", "-5"]),
    ("--reward-weights", ["--reward-weights", "climb:abc"]),
    ("--reward-weights", ["--reward-weights", "climb:1e309"]),
    ("--reward-weights", ["--reward-weights", "climb:-1e309"]),
    ("--reward-weights", ["--reward-weights", f"climb:{HUGE}"]),
    ("--reward-weights", ["--reward-weights", "climb:1e7"]),
    ("--reward-weights", ["--reward-weights", "climb:True"]),
    ("--reward-weights", ["--reward-weights", "height:1"]),
    ("--reward-weights", ["--reward-weights", "climb:1", "climb:2"]),
    ("--condition", ["--condition", "friction:abc"]),
    ("--condition", ["--condition", "friction:1e309"]),
    ("--condition", ["--condition", f"friction:{HUGE}"]),
    ("--condition", ["--condition", "friction:[]"]),
    ("--condition", ["--condition", "kp:-1"]),
    ("--condition", ["--condition", "pole_radius:5"]),
    ("--condition", ["--condition", "friction:[0.5,0.5]"]),
    ("--space", ["--space", "pitch:0.07:inf"]),
    ("--space", ["--space", f"pitch:0.07:{HUGE}"]),
    ("--space", ["--space", "squeeze:a:b"]),
    ("--space", ["--space", "pitch:0.2:0.1"]),
    ("--output", ["--output", "/proc/x.yml"]),
    ("--output", ["--output", "/proc/no/such/x.json"]),
    ("--output", ["--output", "tuned.txt"]),
    ("--output", ["--output", "."]),
    ("--output", ["--output", "not_gaits.json"]),  # other entries are kept: it must be one
    ("--output", ["--output", "misspelt.yml/x.json"]),  # a file where a folder should be
    ("--plot", ["--plot", "/proc/x.png"]),
    ("--plot", ["--plot", "x{0}.png"]),
    ("--plot", ["--plot", "x{foo}.png"]),
    ("--plot", ["--plot", "x{.png"]),
    ("--plot", ["--plot", "x{key.y}.png"]),
    ("--plot", ["--plot", "frontier.unknown"]),
    ("--storage", ["--storage", "/proc/db.sqlite"]),
    ("--storage", ["--storage", "."]),
    ("--storage", ["--storage", "nosuchdriver://x/y"]),
    ("--storage", ["--storage", "not_gaits.json"]),  # a file that is no database
    ("--config", ["--config", "misspelt.yml"]),  # reward_weight: for reward_weights:
    ("--config", ["--config", "unknown_name.yml"]),
    ("--config", ["--config", "bad_weight.yml"]),
    ("--config", ["--config", "not_a_mapping.yml"]),
    ("--config", ["--config", "no/such/recipe.yml"]),
    ("--objective", ["--objective", "speed"]),
    ("--env", ["--env", "CartPole-v1"]),
    ("--also-plot", ["--also-plot", "nosuch"]),
    ("--policy-point", ["--policy-point", "no/such/eval.json"]),
]


def _files(folder: Path) -> dict[Path, bytes | None]:
    """Every path under ``folder`` with its content (None for a folder)."""
    return {
        p.relative_to(folder): p.read_bytes() if p.is_file() else None for p in folder.rglob("*")
    }


def _prepared(folder: Path) -> dict[Path, bytes | None]:
    for name, text in CONFIGS.items():
        (folder / name).write_text(text)
    return _files(folder)


@pytest.mark.parametrize(("option", "extra"), CASES, ids=[" ".join(e)[:40] for _, e in CASES])
def test_a_bad_command_line_is_refused_by_name_and_writes_nothing(
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    option: str,
    extra: list[str],
) -> None:
    before = _prepared(tmp_path)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exc:
        main([*TINY, *extra])
    err = capsys.readouterr().err
    assert exc.value.code == 2, err
    assert err.count("\n") == 1 and f"argument {option}:" in err, err
    assert "Traceback" not in err and len(err) < 2000, err
    assert _files(tmp_path) == before  # no database, no tuned gaits, no figure, no folder


def test_at_least_40_cases() -> None:
    assert len(CASES) >= 40


@pytest.mark.parametrize(
    ("option", "extra"),
    [
        ("--seeds", ["--seeds", "-1"]),
        ("--plot", ["--plot", "x{0}.png"]),
        ("--config", ["--config", "misspelt.yml"]),
        ("--reward-weights", ["--reward-weights", "climb:abc"]),
    ],
)
def test_the_script_prints_one_line_and_no_traceback(
    tmp_path: Path, option: str, extra: list[str]
) -> None:
    before = _prepared(tmp_path)
    proc = subprocess.run(
        [sys.executable, "-m", "acl_env.tuning", *TINY, *extra],
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"acl-tune-gait: error: argument {option}:")
    assert _files(tmp_path) == before
