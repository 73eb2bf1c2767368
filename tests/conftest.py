"""Shared test set-up: headless rendering through EGL (docs/mujoco_notes.md#headless-rendering),
and torch's thread count restored after every test."""

import os
from collections.abc import Iterator

import pytest
import torch

os.environ.setdefault("MUJOCO_GL", "egl")

TORCH_THREADS = torch.get_num_threads()  # the process default, before any test changes it


@pytest.fixture(autouse=True)
def _restore_torch_threads() -> Iterator[None]:
    """Loading a policy in-process (``acl_env.training.policy.load_policy``, as evaluation does)
    sets torch to one thread for the rest of the process; a later test would then run its torch
    code under another thread count, whose float reductions differ in the last bits."""
    yield
    if torch.get_num_threads() != TORCH_THREADS:
        torch.set_num_threads(TORCH_THREADS)
