"""The release artefacts: ``python -m build --no-isolation`` makes an sdist and a wheel.

``build`` and ``hatchling`` are in the test extra, so building needs no download of a build
backend (no isolated build environment).  ``build`` makes the sdist first and the wheel *from the
sdist*, so a file the sdist forgets is missing from the wheel too.  The checks here read the
archives; tests/project/test_binder.py installs the built wheel into a fresh venv (slow).
"""

from __future__ import annotations

import email
import json
import subprocess
import sys
import tarfile
import time
try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10: the test extra brings tomli
    import tomli as tomllib
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
NAME, VERSION = PROJECT["name"], PROJECT["version"]
SERVER_CONFIG = "etc/jupyter/jupyter_server_config.d/rot4d_widget.json"


def build_dists(outdir: Path) -> tuple[Path, Path]:
    """``python -m build --no-isolation`` of this repository into ``outdir``: (sdist, wheel)."""
    for module in ("build", "hatchling"):
        if subprocess.run([sys.executable, "-c", f"import {module}"], capture_output=True).returncode:
            pytest.fail(f"{module} is not installed (it is in the test extra): pip install -e '.[test]'", pytrace=False)
    t0 = time.monotonic()
    proc = subprocess.run(
        [sys.executable, "-m", "build", "--no-isolation", "--outdir", str(outdir), str(ROOT)],
        capture_output=True, text=True, timeout=600,
    )
    assert proc.returncode == 0, (proc.stdout + proc.stderr)[-4000:]
    print(f"[{time.monotonic() - t0:6.1f} s] python -m build --no-isolation")
    sdists, wheels = sorted(outdir.glob("*.tar.gz")), sorted(outdir.glob("*.whl"))
    assert len(sdists) == 1 and len(wheels) == 1, sorted(p.name for p in outdir.iterdir())
    return sdists[0], wheels[0]


@pytest.fixture(scope="module")
def dists(tmp_path_factory):
    return build_dists(tmp_path_factory.mktemp("dist"))


@pytest.fixture(scope="module")
def wheel_names(dists):
    with zipfile.ZipFile(dists[1]) as z:
        return z.namelist()


def _package_files() -> set[str]:
    """The package's files in the source tree, as wheel paths (no caches)."""
    pkg = ROOT / "rot4d_widget"
    return {
        p.relative_to(ROOT).as_posix() for p in pkg.rglob("*")
        if p.is_file() and "__pycache__" not in p.parts and p.suffix not in (".pyc", ".pyo")
    }


def test_names_and_version(dists):
    sdist, wheel = dists
    assert sdist.name == f"{NAME}-{VERSION}.tar.gz"
    assert wheel.name == f"{NAME}-{VERSION}-py3-none-any.whl"  # pure Python: installs anywhere, no compiler
    home = (ROOT / "rot4d_widget" / "core" / "version.py").read_text()
    assert f'__version__ = "{VERSION}"' in home, "rot4d_widget.__version__ differs from pyproject's version"


def test_wheel_carries_the_package_its_javascript_and_glsl(wheel_names):
    names = set(wheel_names)
    assert "rot4d_widget/view/page/companion.js" in names and "rot4d_widget/view/page/package.json" in names
    glsl = {n for n in names if n.startswith("rot4d_widget/view/glsl/")}
    assert glsl and glsl == {f for f in _package_files() if f.startswith("rot4d_widget/view/glsl/")}
    # every file of the package, no more and no less (a new module or shader cannot be forgotten)
    assert {n for n in names if n.startswith("rot4d_widget/")} == _package_files()


def test_wheel_carries_the_server_extension_config_and_the_license(dists, wheel_names):
    data = f"{NAME}-{VERSION}.data/data/{SERVER_CONFIG}"
    assert data in wheel_names, "the server extension's config must install to <prefix>/" + SERVER_CONFIG
    with zipfile.ZipFile(dists[1]) as z:
        config = json.loads(z.read(data))
        license_text = z.read(f"{NAME}-{VERSION}.dist-info/licenses/LICENSE").decode()
        meta = email.message_from_bytes(z.read(f"{NAME}-{VERSION}.dist-info/METADATA"))
    assert config == json.loads((ROOT / "jupyter-config" / "jupyter_server_config.d" / "rot4d_widget.json").read_text())
    assert config == {"ServerApp": {"jpserver_extensions": {"rot4d_widget._server": True}}}
    assert license_text == (ROOT / "LICENSE").read_text()
    assert license_text.startswith("BSD 3-Clause License") and "rot4d_widget developers" in license_text
    assert meta["License-Expression"] == "BSD-3-Clause" and meta.get_all("License-File") == ["LICENSE"]


def test_wheel_is_pure_python_with_no_binary_or_c_source(dists, wheel_names):
    """No compiled code of our own: the wheel says it is pure and carries nothing to compile or load."""
    with zipfile.ZipFile(dists[1]) as z:
        tags = email.message_from_bytes(z.read(f"{NAME}-{VERSION}.dist-info/WHEEL"))
    assert tags["Root-Is-Purelib"] == "true" and tags.get_all("Tag") == ["py3-none-any"]
    native = [n for n in wheel_names if n.endswith((".so", ".pyd", ".dll", ".dylib", ".c", ".h"))]
    assert not native, native


def test_wheel_has_nothing_from_tests_notebooks_or_caches(wheel_names):
    dist_info, data = f"{NAME}-{VERSION}.dist-info/", f"{NAME}-{VERSION}.data/"
    stray = [n for n in wheel_names if not n.startswith(("rot4d_widget/", dist_info, data))]
    assert not stray, f"outside the package: {stray}"
    bad = [n for n in wheel_names
           if "tests/" in n or "/test_" in n or "conftest" in n or n.endswith((".pyc", ".ipynb"))
           or "__pycache__" in n or ".ipynb_checkpoints" in n]
    assert not bad, bad


def test_metadata_is_ready_for_a_release(dists):
    with zipfile.ZipFile(dists[1]) as z:
        meta = email.message_from_bytes(z.read(f"{NAME}-{VERSION}.dist-info/METADATA"))
    assert meta["Name"] == NAME and meta["Version"] == VERSION
    assert meta["Requires-Python"] == PROJECT["requires-python"]
    # the core dependencies are the wheel's unconditional requirements, as written
    from packaging.requirements import Requirement

    core = {str(Requirement(r)) for r in meta.get_all("Requires-Dist") if "extra ==" not in r}
    assert core == {str(Requirement(r)) for r in PROJECT["dependencies"]}
    urls = dict(u.split(", ", 1) for u in meta.get_all("Project-URL"))
    assert {"Homepage", "Changelog", "Issues", "Binder"} <= set(urls)
    readme = (ROOT / "README.md").read_text()
    for label, url in urls.items():
        assert "OWNER/REPO" in url, (label, url)  # placeholders until the repository is public
    assert urls["Binder"] in readme, "the Binder URL is the README badge's"
    classifiers = meta.get_all("Classifier")
    assert "Framework :: Jupyter :: JupyterLab :: 4" in classifiers
    assert not [c for c in classifiers if c.startswith("License ::")], "the license is the SPDX expression"
    assert meta["Description-Content-Type"] == "text/markdown" and "# rot4d_widget" in meta.get_payload()


def test_changelog_has_the_release(dists):
    changelog = (ROOT / "CHANGELOG.md").read_text()
    assert f"## [{VERSION}]" in changelog, f"CHANGELOG.md has no entry for {VERSION}"


def test_sdist_builds_the_wheel_from_what_it_carries(dists):
    with tarfile.open(dists[0]) as t:
        names = {n.split("/", 1)[1] for n in t.getnames() if "/" in n}
    for needed in ("pyproject.toml", "README.md", "LICENSE", "CHANGELOG.md", "PKG-INFO",
                   "jupyter-config/jupyter_server_config.d/rot4d_widget.json", "rot4d_widget/view/page/companion.js"):
        assert needed in names, needed
    assert not [n for n in names if n.startswith(("test-artifacts/", ".ci-venv/", ".venv/", "dist/"))
                or "__pycache__" in n or n.endswith(".pyc")]
