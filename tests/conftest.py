"""Shared test set-up: headless rendering through EGL (DESIGN.md section 4)."""

import os

os.environ.setdefault("MUJOCO_GL", "egl")
