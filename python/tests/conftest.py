"""Shared fixtures: the repository root (tests run from it, so scene paths are the CLI's), and
the `weft` binary the results are compared with, built by cargo if it is not there yet."""

import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(autouse=True)
def at_repo_root(monkeypatch):
    """Every test runs from the repository root, as the CLI's examples do."""
    monkeypatch.chdir(REPO)


@pytest.fixture(scope="session")
def weft_bin():
    """The `weft` binary of this checkout (WEFT_BIN, or cargo's dev build of it)."""
    given = os.environ.get("WEFT_BIN")
    if given:
        return Path(given)
    # Without incremental state, as CI and scripts/test.sh build: the same artefacts.
    env = {**os.environ, "CARGO_INCREMENTAL": os.environ.get("CARGO_INCREMENTAL", "0")}
    subprocess.run(
        ["cargo", "build", "--quiet", "--bin", "weft"],
        cwd=REPO, check=True, env=env,
    )
    target = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    if not target.is_absolute():
        target = REPO / target
    return target / "debug" / "weft"


def run_weft(weft_bin, *args, check=True):
    """Runs the CLI from the repository root; returns the finished process."""
    return subprocess.run(
        [str(weft_bin), *map(str, args)],
        cwd=REPO,
        capture_output=True,
        text=True,
        check=check,
    )
