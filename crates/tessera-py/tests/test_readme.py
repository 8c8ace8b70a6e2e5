"""The README's Python example and the scripts in examples/python run as a newcomer runs them:
from the repository root, with the shared models beside it."""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]


def readme_example() -> str:
    text = (REPO / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert blocks, "README.md has no python example"
    return blocks[0]


@pytest.fixture
def workdir(data, tmp_path):
    """A folder whose ../shared/data is the shared models, as beside a checkout."""
    (tmp_path / "shared").mkdir()
    (tmp_path / "shared" / "data").symlink_to(data, target_is_directory=True)
    work = tmp_path / "tessera"
    work.mkdir()
    return work


def run(code_or_script, cwd, *args):
    command = [sys.executable, *(["-c", code_or_script] if "\n" in code_or_script else [code_or_script]), *args]
    out = subprocess.run(command, cwd=cwd, capture_output=True, text=True, env=dict(os.environ, MPLBACKEND="Agg"))
    assert out.returncode == 0, out.stderr
    return out.stdout


def test_the_readme_example_runs(workdir):
    out = run(readme_example(), workdir)
    assert "(" in out and (workdir / "teapot.glb").stat().st_size > 0


def test_the_quickstart_is_the_readme_example(workdir):
    script = (REPO / "examples" / "python" / "quickstart.py").read_text()
    assert readme_example().strip() in script
    run(str(REPO / "examples" / "python" / "quickstart.py"), workdir)


def test_the_error_plot_example_runs(workdir):
    import matplotlib  # noqa: F401  (scripts/test installs it; a missing one fails here, loudly)

    out = run(str(REPO / "examples" / "python" / "error_plot.py"), workdir, "-o", "plot.png")
    assert (workdir / "plot.png").stat().st_size > 0
    assert "transition" in out
