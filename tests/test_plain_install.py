"""The main job from a plain install: a wheel, no torch, no Stable-Baselines3, no PyYAML, run
from a folder outside the repository."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

# Imported first by the interpreter below (sitecustomize): the train extra's packages fail to
# import, as on a machine where they were never installed.
BLOCKER = """
import importlib.abc, sys
BLOCKED = ("torch", "stable_baselines3", "yaml", "optuna", "tensorboard", "rl_zoo3")
class Blocker(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in BLOCKED:
            raise ImportError(f"{name} is not installed (plain install)")
        return None
sys.meta_path.insert(0, Blocker())
"""

# Drops an editable install's import hook (pip install -e), which would find acl_env.assets in
# this checkout whatever the source tree on the path lacks.
NO_EDITABLE = """
import sys
sys.meta_path[:] = [f for f in sys.meta_path if "__editable__" not in getattr(f, "__module__", "")]
"""


@pytest.mark.slow
def test_wheel_without_torch_evaluates_the_shipped_policy(
    tmp_path: Path, installed_wheel: Path
) -> None:
    target, blocker = installed_wheel, tmp_path / "blocker"
    blocker.mkdir()
    (blocker / "sitecustomize.py").write_text(BLOCKER)
    work = tmp_path / "elsewhere"
    work.mkdir()
    env = {
        "PYTHONPATH": os.pathsep.join([str(blocker), str(target)]),
        "PATH": os.environ.get("PATH", "/usr/bin:/bin"),
        "MUJOCO_GL": "egl",
    }
    probe = subprocess.run(
        [sys.executable, "-c", "import torch"], cwd=work, env=env, capture_output=True, text=True
    )
    assert probe.returncode != 0 and "not installed" in probe.stderr
    run = subprocess.run(
        [sys.executable, "-m", "acl_env.evaluation", "--episodes", "2", "--json", "e.json"],
        cwd=work,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 0, run.stderr[-3000:]
    assert "climb per gait cycle" in run.stdout and "policy" in run.stdout
    record = json.loads((work / "e.json").read_text())
    assert record["controllers"]["policy"]["climb_per_gait_cycle_m"]["n"] == 2
    assert str(target) in record["policy"] or record["policy"].startswith("acl_env")


@pytest.mark.slow
def test_readme_python_example_runs_from_the_clones_root(
    clean_source: Path, installed_wheel: Path, tmp_path: Path
) -> None:
    """After ``pip install .``, the README's Python example run from the clone's root, where the
    source tree's ``acl_env`` comes first on the path (its ``assets`` is a link to the top-level
    assets/), as from anywhere else."""
    text = (clean_source / "README.md").read_text()
    start = text.index("## Python API")
    code = text[
        text.index("```python", start) + len("```python") : text.index(
            "```", text.index("```python", start) + 9
        )
    ]
    # As on a machine where only the wheel is installed: no editable install of this checkout.
    unedit = tmp_path / "unedit"
    unedit.mkdir()
    (unedit / "sitecustomize.py").write_text(NO_EDITABLE)
    env = {
        "PYTHONPATH": os.pathsep.join([str(unedit), str(installed_wheel)]),
        "PATH": os.environ.get("PATH", "/usr/bin:/bin"),
        "MUJOCO_GL": "egl",
    }
    run = subprocess.run(
        [sys.executable, "-c", code],
        cwd=clean_source,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 0, run.stderr[-3000:]
    assert "climb_per_gait_cycle_m" in run.stdout
    for script, usage in (("train_ppo.py", "acl-train"), ("evaluate.py", "acl-evaluate")):
        shown = subprocess.run(
            [sys.executable, f"train/{script}", "--help"],
            cwd=clean_source,
            env=env,
            capture_output=True,
            text=True,
            timeout=600,
        )
        assert shown.returncode == 0, shown.stderr[-3000:]
        assert shown.stdout.startswith(f"usage: {usage}")


def test_the_wheel_lists_every_subpackage() -> None:
    """Every package of ``acl_env/`` is in pyproject's ``packages`` (a missing one installs
    without it: the wheel tests above would only see that when run)."""
    import tomllib

    root = Path(__file__).resolve().parents[1]
    listed = set(
        tomllib.loads((root / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"]
    )
    found = {
        ".".join(init.parent.relative_to(root).parts)
        for init in (root / "acl_env").rglob("__init__.py")
    }
    assert found <= listed, sorted(found - listed)
