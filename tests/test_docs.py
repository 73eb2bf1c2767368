"""The documentation site builds with ``mkdocs build --strict`` (a broken link, a page missing from
the navigation or an API page that does not render fails it), and its results page shows the
numbers of the generated records (docs/hooks/results.py), not retyped ones."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def site(built_site: Path) -> Path:
    """The site as ``mkdocs build --strict`` builds it (conftest.built_site)."""
    return built_site


def test_mkdocs_build_strict(site: Path) -> None:
    for page in ("index", "environments", "results", "experiments", "api/envs"):
        path = site / page / "index.html" if page != "index" else site / "index.html"
        assert path.is_file(), path
    assert "ACLClimbEnv" in (site / "api" / "envs" / "index.html").read_text()


@pytest.mark.parametrize("record", ["eval.json", "eval_noroll.json", "eval_compliant.json"])
def test_results_page_reads_the_records(site: Path, record: str) -> None:
    page = (site / "results" / "index.html").read_text()
    policy = json.loads((ROOT / "docs" / record).read_text())["controllers"]["policy"]
    climb = policy["climb_per_gait_cycle_m"]
    assert f"{100 * climb['mean']:.2f} ± {100 * climb['half_width']:.2f}" in page
    assert "<!-- results:" not in page


@pytest.mark.parametrize("name", ["acl_climb_sea_ppo", "acl_climb_compliant_ppo"])
def test_results_page_names_the_registered_task_of_each_policy(site: Path, name: str) -> None:
    """A record runs a benchmark task as its base id and kwargs; the page names the task the
    policy was trained on, its policy.json's id."""
    page = (site / "results" / "index.html").read_text()
    env_id = json.loads((ROOT / "acl_env/data/policies" / name / "policy.json").read_text())[
        "env_id"
    ]
    assert f"Task:</strong> <code>{env_id}</code>" in page
