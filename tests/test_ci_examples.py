"""The CI recipes in ``docs/ci/`` (a GitHub Actions workflow and a GitLab job for a repository
of robot models) run as written: each is read as YAML, its ``dyncheck`` command is run here in
a scratch model repository written by the test (one good model, one broken: a negative mass,
which the check fails), and what the recipe then uploads exists; its install step installs
from the dyncheck source the recipe itself fetches (never from a package index dyncheck is not
on). Expected outcomes: the check's exit codes (0 good, 1 a finding) and the files the recipe
names."""

from __future__ import annotations

import shlex
import subprocess
import sys
from pathlib import Path

import pytest

yaml = pytest.importorskip("yaml")

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "tests" / "check" / "models"
RECIPES = sorted((ROOT / "docs" / "ci").glob("*.yml"))


def _commands(recipe: Path) -> list[str]:
    """The shell lines of a workflow's ``run:`` steps or a job's ``script:``."""
    data = yaml.safe_load(recipe.read_text())
    lines: list[str] = []
    for job in data.get("jobs", {}).values():
        lines += [s["run"] for s in job.get("steps", []) if "run" in s]
    for key, job in data.items():
        if isinstance(job, dict) and "script" in job and key != "jobs":
            lines += job["script"]
    return lines


def _models(tmp_path: Path, *, broken: bool) -> Path:
    repo = tmp_path / "repo"
    (repo / "robots").mkdir(parents=True)
    (repo / "robots" / "arm.urdf").write_text((MODELS / "branches.urdf").read_text())
    if broken:
        (repo / "robots" / "heavy.urdf").write_text(
            (MODELS / "branches.urdf").read_text().replace('<mass value="1.5"/>',
                                                           '<mass value="-1.5"/>'))
    return repo


def test_there_are_recipes_for_github_and_gitlab():
    assert {p.name for p in RECIPES} >= {"github-actions.yml", "gitlab-ci.yml"}


@pytest.mark.parametrize("recipe", RECIPES, ids=lambda p: p.stem)
def test_the_recipe_installs_from_the_source_it_fetches(recipe):
    """The install line names the folder an earlier step of the same recipe fetches dyncheck
    into (a checkout step's path or a git clone's target), with the checkout's pins."""
    text = recipe.read_text()
    install = next(c for c in _commands(recipe) if c.startswith("pip install"))
    folder = ".dyncheck-src"
    assert f'"./{folder}[' in install and f"-c {folder}/constraints.txt" in install
    assert f"path: {folder}" in text or f"git clone --depth 1 \"$DYNCHECK_REPOSITORY\" " \
        f"{folder}" in text
    assert "pip install \"dyncheck" not in text  # (no index holds dyncheck)


@pytest.mark.parametrize("broken", [False, True], ids=["good", "broken"])
@pytest.mark.parametrize("recipe", RECIPES, ids=lambda p: p.stem)
def test_the_recipe_s_check_runs_and_leaves_what_it_uploads(tmp_path, recipe, broken):
    repo = _models(tmp_path, broken=broken)
    line = next(c for c in _commands(recipe) if c.startswith("dyncheck "))
    argv = shlex.split(line)
    done = subprocess.run([sys.executable, "-m", "dyncheck", *argv[1:], "--states", "5"],
                          cwd=repo, capture_output=True, text=True, timeout=600)
    assert done.returncode == (1 if broken else 0), done.stdout + done.stderr
    text = recipe.read_text()
    assert "dyncheck.xml" in text and (repo / "dyncheck.xml").is_file()
    assert "dyncheck-pages" in text and (repo / "dyncheck-pages" / "arm.md").is_file()
