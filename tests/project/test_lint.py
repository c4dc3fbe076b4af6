"""The package passes ruff with the project's configuration ([tool.ruff] in pyproject.toml)."""

from __future__ import annotations

import pathlib
import shutil
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def _ruff():
    exe = shutil.which("ruff") or str(pathlib.Path(sys.executable).with_name("ruff"))
    if not pathlib.Path(exe).exists():
        pytest.fail("ruff is not installed: pip install -e '.[test]' installs it")
    return exe


def test_the_package_passes_ruff():
    out = subprocess.run([_ruff(), "check", "rot4d_widget"], cwd=ROOT, capture_output=True, text=True)
    assert out.returncode == 0, out.stdout + out.stderr


def test_ruff_sees_a_fault(tmp_path):
    """The check can fail: an unused import in a file of the package's shape is reported."""
    bad = tmp_path / "rot4d_widget" / "bad.py"
    bad.parent.mkdir()
    bad.write_text("import os\n")
    (tmp_path / "pyproject.toml").write_text((ROOT / "pyproject.toml").read_text())
    out = subprocess.run([_ruff(), "check", "rot4d_widget"], cwd=tmp_path, capture_output=True, text=True)
    assert out.returncode == 1 and "F401" in out.stdout
