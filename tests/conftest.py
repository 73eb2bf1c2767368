"""Shared test set-up: headless rendering through EGL (docs/mujoco_notes.md#headless-rendering)."""

import os

os.environ.setdefault("MUJOCO_GL", "egl")
