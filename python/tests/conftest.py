"""Shared helpers: the repository's data and the release binary the Python results are compared
with (built by `cargo build --release`; RESTITUTION_BIN overrides its path)."""

import json
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "data"


def cli_path() -> Path:
    return Path(os.environ.get("RESTITUTION_BIN", ROOT / "target" / "release" / "restitution"))


def run_cli(*args, check=True, cwd=ROOT):
    """Runs the CLI, by default from the repository root (so paths print as in the README)."""
    exe = cli_path()
    if not exe.exists():
        pytest.fail(f"{exe} is missing: run `cargo build --release` first (the comparisons need it)")
    p = subprocess.run([str(exe), *map(str, args)], cwd=cwd, capture_output=True, text=True)
    if check and p.returncode != 0:
        raise AssertionError(f"restitution {' '.join(map(str, args))} failed: {p.stderr}")
    return p


def cli_json(*args):
    return json.loads(run_cli(*args, "--format", "json").stdout)


def cli_error(*args, cwd=None) -> str:
    """The CLI's one error line, without its 'restitution: error: ' prefix, run in `cwd` (the
    current directory by default, as the Python call it is compared with)."""
    p = run_cli(*args, check=False, cwd=cwd or os.getcwd())
    assert p.returncode != 0, p.stdout
    lines = [l for l in p.stderr.splitlines() if l.startswith("restitution: error: ")]
    assert len(lines) == 1, p.stderr
    return lines[0][len("restitution: error: "):]


@pytest.fixture
def in_root(monkeypatch):
    """Run with the repository root as working directory, so relative paths match the CLI's."""
    monkeypatch.chdir(ROOT)
    return ROOT
