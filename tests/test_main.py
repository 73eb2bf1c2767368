"""``python -m acl_env`` without a display: one message on how to record instead, exit status 2,
no traceback, no abort in GLFW; ``--snapshot`` still renders offscreen."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from acl_env.envs.lifecycle import no_display_reason

ROOT = Path(__file__).resolve().parent.parent
DISPLAY_VARIABLES = ("DISPLAY", "WAYLAND_DISPLAY", "MUJOCO_GL")


def _headless_env(**extra: str) -> dict[str, str]:
    """This process's environment without a display or a MuJoCo backend, plus ``extra``."""
    env = {k: v for k, v in os.environ.items() if k not in DISPLAY_VARIABLES}
    return {**env, **extra}


def _run(args: list[str], env: dict[str, str], cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "acl_env", *args],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )


@pytest.mark.parametrize(
    "extra",
    [{}, {"MUJOCO_GL": "egl", "DISPLAY": ":0"}, {"MUJOCO_GL": "osmesa"}],
    ids=["no-display", "mujoco-gl-egl", "mujoco-gl-osmesa"],
)
def test_no_display_says_how_to_record(tmp_path: Path, extra: dict[str, str]) -> None:
    if not extra and not sys.platform.startswith("linux"):
        pytest.skip("a missing DISPLAY means no display on Linux only")
    proc = _run([], _headless_env(**extra), tmp_path)
    assert proc.returncode == 2, proc.stderr[-2000:]
    assert "Traceback" not in proc.stderr
    assert "cannot open MuJoCo's viewer" in proc.stderr
    for hint in ("--video", "--snapshot", "MUJOCO_GL=egl"):
        assert hint in proc.stderr, hint
    assert proc.stdout == ""
    assert list(tmp_path.iterdir()) == []


def test_snapshot_works_headless(tmp_path: Path) -> None:
    png = tmp_path / "snake.png"
    proc = _run(["--cycles", "1", "--snapshot", str(png)], _headless_env(), tmp_path)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert f"wrote {png}" in proc.stdout and "m/cycle" in proc.stdout
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    ("environ", "platform", "usable"),
    [
        ({}, "linux", False),
        ({"DISPLAY": ":0"}, "linux", True),
        ({"WAYLAND_DISPLAY": "wayland-0"}, "linux", True),
        ({"DISPLAY": ":0", "MUJOCO_GL": "egl"}, "linux", False),
        ({"DISPLAY": ":0", "MUJOCO_GL": "OSMesa"}, "linux", False),
        ({"DISPLAY": ":0", "MUJOCO_GL": "glfw"}, "linux", True),
        ({}, "darwin", True),
        ({}, "win32", True),
        ({"MUJOCO_GL": "egl"}, "darwin", False),
    ],
)
def test_no_display_reason(environ: dict[str, str], platform: str, usable: bool) -> None:
    assert (no_display_reason(environ, platform) == "") == usable
