"""Shared test set-up: headless rendering through EGL (docs/mujoco_notes.md#headless-rendering),
torch's thread count restored after every test, and SB3 run folders restored from git history
(the repository keeps their pickle-free exports only)."""

import os
import shutil
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
import torch

os.environ.setdefault("MUJOCO_GL", "egl")

TORCH_THREADS = torch.get_num_threads()  # the process default, before any test changes it
ROOT = Path(__file__).resolve().parents[1]
# An SB3 run folder's files, as acl-train writes them (acl_env.training.runs).
SB3_RUN_FILES = ("model.zip", "vecnormalize.pkl", "config.yml", "args.json", "summary.json")


@pytest.fixture(autouse=True)
def _restore_torch_threads() -> Iterator[None]:
    """Loading a policy in-process (``acl_env.training.policy.load_policy``, as evaluation does)
    sets torch to one thread for the rest of the process; a later test would then run its torch
    code under another thread count, whose float reductions differ in the last bits."""
    yield
    if torch.get_num_threads() != TORCH_THREADS:
        torch.set_num_threads(TORCH_THREADS)


@pytest.fixture(scope="session")
def clean_source(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The project's files as a clean checkout has them (tracked, and untracked but not ignored),
    copied apart: a wheel built from the working folder would also pack stale files left in its
    ignored build/ folder by an earlier build."""
    root = Path(__file__).resolve().parents[1]
    listed = subprocess.run(
        ["git", "ls-files", "-co", "--exclude-standard", "-z"],
        cwd=root,
        capture_output=True,
        check=False,
    )
    if listed.returncode != 0:  # not a git checkout (an sdist): build from it as it is
        return root
    target = tmp_path_factory.mktemp("source")
    for name in filter(None, listed.stdout.decode().split("\0")):
        source = root / name
        if source.is_symlink():  # acl_env/assets -> ../assets: kept a link
            (target / name).parent.mkdir(parents=True, exist_ok=True)
            (target / name).symlink_to(os.readlink(source))
        elif source.is_file():
            (target / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, target / name)
    return target


@pytest.fixture(scope="session")
def installed_wheel(clean_source: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The project built as a wheel from :func:`clean_source` and installed, without its
    dependencies, into a folder of its own (returned): put it on PYTHONPATH to run the package
    as a user's non-editable install has it."""
    wheel_dir = tmp_path_factory.mktemp("wheel")
    target = tmp_path_factory.mktemp("site")
    build = ["wheel", "--no-deps", "--no-build-isolation", "-q", "-w", str(wheel_dir)]
    subprocess.run([sys.executable, "-m", "pip", *build, str(clean_source)], check=True)
    (wheel,) = wheel_dir.glob("acl_env-*.whl")
    install = ["install", "--no-deps", "-q", "-t", str(target), str(wheel)]
    subprocess.run([sys.executable, "-m", "pip", *install], check=True)
    return target


DOCS_EXTRA = 'the docs extra is not installed (pip install -e ".[docs]")'


@pytest.fixture(scope="session")
def built_site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The documentation site, built once per session with ``mkdocs build --strict`` (a warning
    fails it); skipped without the docs extra."""
    for module in ("mkdocs", "material", "mkdocstrings", "mkdocstrings_handlers.python"):
        pytest.importorskip(module, reason=DOCS_EXTRA)
    site_dir = tmp_path_factory.mktemp("site")
    proc = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(site_dir)],
        cwd=Path(__file__).resolve().parents[1],
        env={**os.environ, "NO_MKDOCS_2_WARNING": "1"},
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-5000:]
    return site_dir


def _git(*args: str) -> bytes:
    return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, check=True).stdout


@pytest.fixture(scope="session")
def sb3_from_history(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str], Path]:
    """A function from a folder's path in the repository (``experiments/<topic>/<run>``, a
    shipped policy's ``acl_env/data/policies/<name>``) to that SB3 run folder as it was before its
    pickles left the tree: ``model.zip``, ``vecnormalize.pkl`` and the run's JSON and YAML files
    taken from git history into a folder of the same name. Skips the test where the history is
    not here (a shallow clone, an sdist)."""
    root = tmp_path_factory.mktemp("sb3_history")
    restored: dict[str, Path] = {}

    def restore(rel: str) -> Path:
        if rel in restored:
            return restored[rel]
        try:
            # The last commit that touched the model: it added it, or its parent had it.
            rev = _git("rev-list", "-1", "HEAD", "--", f"{rel}/model.zip").decode().strip()
        except (OSError, subprocess.CalledProcessError):
            pytest.skip("no git history here")
        if not rev:
            pytest.skip(f"git history has no {rel}/model.zip")
        folder = root / rel
        folder.mkdir(parents=True)
        for file in SB3_RUN_FILES:
            for ref in (rev, f"{rev}^"):
                try:
                    (folder / file).write_bytes(_git("show", f"{ref}:{rel}/{file}"))
                    break
                except subprocess.CalledProcessError:
                    continue
            else:
                pytest.skip(f"git history has no {rel}/{file}")
        restored[rel] = folder
        return folder

    return restore
