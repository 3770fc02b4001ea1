"""Shared fixtures: the repository's folders and the CLI binary."""

import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
PAPER = ROOT / "meshes" / "paper-wedge"


@pytest.fixture(scope="session")
def cli_binary() -> pathlib.Path:
    """The release CLI (`cargo build --release` builds it; `.ci/run` has built it before the
    Python tests). Built here if missing."""
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    exe = target / "release" / "fricbound"
    if not exe.exists():
        subprocess.run(
            ["cargo", "build", "--release", "--bin", "fricbound"], cwd=ROOT, check=True
        )
    return exe
