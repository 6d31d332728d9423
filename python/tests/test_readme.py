"""Every command of the README runs as written, from the repository root: each line of its `sh`
blocks through bash, in order, then its `python` blocks. What they write there (box.msh,
case/, the venv v/, ...) is removed afterwards. Not run: `scripts/test.sh`, the whole suite,
which runs this test."""

import re
import shutil
import subprocess
import sys

import pytest

from conftest import ROOT

NOT_RUN = {"scripts/test.sh": "the whole suite, which runs this test"}


def blocks(language):
    text = (ROOT / "README.md").read_text()
    return re.findall(rf"^```{language}\n(.*?)^```", text, flags=re.S | re.M)


def shell_commands():
    lines = [line for block in blocks("sh") for line in block.splitlines() if line.strip()]
    return [line for line in lines if not any(line.startswith(skip) for skip in NOT_RUN)]


def new_paths(before):
    """The paths at the root that git does not know of and that were not there `before`."""
    out = subprocess.run(
        ["git", "status", "--porcelain", "--ignored", "--untracked-files=normal"],
        cwd=ROOT, capture_output=True, text=True, check=True,
    ).stdout
    now = {line[3:].rstrip("/") for line in out.splitlines() if line[:2] in ("??", "!!")}
    return now - before if before is not None else now


@pytest.fixture
def clean_root():
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("needs a git checkout to tell the README's outputs from the repository's files")
    before = new_paths(None)
    yield
    for name in new_paths(before):
        path = ROOT / name
        shutil.rmtree(path) if path.is_dir() and not path.is_symlink() else path.unlink()


def test_the_skipped_commands_are_still_in_the_readme():
    text = (ROOT / "README.md").read_text()
    assert all(command in text for command in NOT_RUN)


def test_readme_commands_run_as_written(clean_root):
    commands = shell_commands()
    assert any("pip install ." in c for c in commands) and any("blmesh check" in c for c in commands)
    for command in commands:
        run = subprocess.run(["bash", "-c", command], cwd=ROOT, capture_output=True, text=True, timeout=1800)
        assert run.returncode == 0, f"{command}\n{run.stdout[-3000:]}\n{run.stderr[-3000:]}"
    for code in blocks("python"):
        run = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=600)
        assert run.returncode == 0, f"{code}\n{run.stderr[-3000:]}"
        assert run.stdout.strip().endswith("True"), run.stdout
