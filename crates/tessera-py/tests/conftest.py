"""Shared fixtures: the model folder (``TESSERA_DATA``, default ``../shared/data`` beside the
checkout) and the ``tessera`` command line (``TESSERA_CLI``, default the workspace's
``target/debug/tessera``, which ``cargo test`` builds) to compare with."""

import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]
DATA = Path(os.environ.get("TESSERA_DATA", REPO.parent / "shared" / "data"))
CLI = Path(os.environ.get("TESSERA_CLI", REPO / "target" / "debug" / "tessera"))


@pytest.fixture(scope="session")
def data() -> Path:
    if not (DATA / "patches" / "teapot.patches").is_file():
        pytest.fail(f"test data not found at {DATA}: put the shared data folder beside the checkout or set TESSERA_DATA")
    return DATA


@pytest.fixture(scope="session")
def cli():
    """Runs the command line; fails (never skips) when it is not built."""
    if not CLI.is_file():
        pytest.fail(f"the tessera command line is not built at {CLI}: run `cargo build -p tessera-cli` or set TESSERA_CLI")

    def run(*args, check=True):
        out = subprocess.run([str(CLI), *map(str, args)], capture_output=True, text=True)
        if check and out.returncode != 0:
            raise AssertionError(f"tessera {' '.join(map(str, args))} exited {out.returncode}: {out.stderr}")
        return out

    return run
