"""Paths shared by the tests of the Python package."""

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"


@pytest.fixture
def examples() -> Path:
    return EXAMPLES


@pytest.fixture
def cli() -> Path:
    """The command line built by the README's commands (`cargo build --release`
    or the test command before pytest)."""
    exe = ROOT / "target" / "release" / "rothe"
    if not exe.is_file():
        pytest.fail(f"{exe} is missing: build it with `cargo build --release` first")
    return exe
