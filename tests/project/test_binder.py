"""The Binder configuration builds what Binder would build, and the built wheel installs and runs there.

No Docker engine is needed: repo2docker's Python build pack creates one environment with
JupyterLab 4 / Notebook 7 / ipywidgets 8 and then, because ``binder/requirements.txt`` names a
local path, copies the whole repository and runs ``pip install -r binder/requirements.txt`` with
the repository root as working directory: ``.[notebooks]``, the package built from the source
tree with its ``notebooks`` extra.

The slow tests share one fresh venv (module-scoped: built once): Binder's base image, then the
wheel that ``python -m build --no-isolation`` made from this repository (tests/project/test_wheel.py)
with the extra that ``binder/requirements.txt`` names -- the same install as Binder's, but from
the release artefact, so the wheel is proven to install and work away from the source tree.
Then: the package is imported from the venv, its server extension is enabled, the lab extensions
are there, and every notebook runs with nbval (from a copy outside the repository).

Deselect them locally with ``-m "not slow"``; the default test command (and CI) runs them.
"""

import json
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import pytest

from test_wheel import build_dists

ROOT = Path(__file__).resolve().parents[2]
BINDER = ROOT / "binder"
REQUIREMENTS = BINDER / "requirements.txt"
NOTEBOOK = "notebooks/01_pentachoron.ipynb"

#: What Binder's base environment provides before the repository's requirements (repo2docker's
#: conda/environment.yml pins these series).
BASE_IMAGE = ["jupyterlab>=4,<5", "notebook>=7,<8", "ipywidgets>=8,<9", "jupyter_server>=2,<3"]
#: Only to run the notebooks here; not part of the Binder image.
TEST_TOOLS = ["pytest>=8", "nbval>=0.11"]
#: Lab extensions the widget needs in the browser, by the names `jupyter labextension list` shows.
LAB_EXTENSIONS = ["jupyter-threejs", "ipyevents", "anywidget", "@jupyter-widgets/jupyterlab-manager"]

ANSI = re.compile(r"\x1b\[[0-9;]*m")


def _requirement_lines():
    lines = []
    for raw in REQUIREMENTS.read_text().splitlines():
        line = raw.split("#", 1)[0].strip()
        if line:
            lines.append(line)
    return lines


# --------------------------------------------------------------------------- fast checks
def test_binder_folder_installs_this_package_from_the_repository_root():
    lines = _requirement_lines()
    local = [line for line in lines if line.lstrip("-e ").startswith(".")]
    assert local == [".[notebooks]"], f"binder/requirements.txt must install the package as '.[notebooks]', got {lines}"
    # pip resolves it against the working directory, which repo2docker sets to the repository root
    assert (ROOT / local[0].split("[")[0] / "pyproject.toml").is_file()
    # and the extra exists: what the notebooks import beyond the package
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10: the test extra brings tomli
        import tomli as tomllib

    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    assert any(r.startswith("py-pde") for r in extras["notebooks"])
    # with a binder/ folder, repo2docker ignores root-level config; nothing here may switch build pack
    for other in ("environment.yml", "Dockerfile", "Project.toml", "install.R"):
        assert not (BINDER / other).exists(), f"binder/{other} would change how Binder builds"


def test_readme_binder_badge_opens_notebook_01():
    readme = (ROOT / "README.md").read_text()
    links = re.findall(r"https://mybinder\.org/v2/gh/[^\s)]+", readme)
    assert links, "README.md has no Binder badge"
    for link in links:
        assert link.endswith(f"?urlpath=lab/tree/{NOTEBOOK}"), link
        assert (ROOT / NOTEBOOK).is_file()


# --------------------------------------------------------------------------- the slow one
def _clean_env(tmp: Path, venv: Path) -> dict:
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("PYTHON", "JUPYTER", "VIRTUAL_ENV", "CONDA", "IPYTHON"))}
    env["VIRTUAL_ENV"] = str(venv)
    env["PATH"] = f"{venv / 'bin'}{os.pathsep}{env.get('PATH', '')}"
    env["PYTHONNOUSERSITE"] = "1"
    for name in ("JUPYTER_CONFIG_DIR", "JUPYTER_DATA_DIR", "JUPYTER_RUNTIME_DIR", "IPYTHONDIR"):
        (tmp / name.lower()).mkdir(exist_ok=True)
        env[name] = str(tmp / name.lower())  # only the venv's own (sys-prefix) extensions count
    env["MPLBACKEND"] = "Agg"
    env["PIP_DISABLE_PIP_VERSION_CHECK"] = "1"
    return env


def _run(cmd, *, env, cwd, timeout=1200):
    t0 = time.monotonic()
    proc = subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, text=True, timeout=timeout)
    took = time.monotonic() - t0
    if proc.returncode:
        tail = "\n".join((proc.stdout + proc.stderr).splitlines()[-40:])
        pytest.fail(f"{' '.join(map(str, cmd))} failed ({proc.returncode}) after {took:.0f} s:\n{tail}")
    print(f"[{took:6.1f} s] {' '.join(map(str, cmd))}")
    return proc


def _venv_binder_line() -> str:
    """The line of binder/requirements.txt that installs this package ('.[notebooks]')."""
    return next(line for line in _requirement_lines() if line.lstrip("-e ").startswith("."))


@pytest.fixture(scope="module")
def binder_venv(tmp_path_factory):
    """A fresh venv as Binder builds it, with the built wheel in place of the source tree."""
    t0 = time.monotonic()
    tmp = tmp_path_factory.mktemp("binder")
    _, wheel = build_dists(tmp / "dist")
    venv = tmp / "binder-venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, timeout=300)
    py = str(venv / "bin" / "python")
    env = _clean_env(tmp, venv)
    pip = [py, "-m", "pip", "install", "--quiet"]

    # 1. Binder's base image, 2. what binder/requirements.txt names: this package with its extra,
    # here the built wheel ('.[notebooks]' -> '<wheel>[notebooks]'), installed from outside the repo
    extra = _venv_binder_line().lstrip("-e ")[1:]
    _run([*pip, "--upgrade", "pip"], env=env, cwd=tmp)
    _run([*pip, *BASE_IMAGE], env=env, cwd=tmp)
    others = [line for line in _requirement_lines() if line != _venv_binder_line()]  # anything else it names
    _run([*pip, f"{wheel}{extra}", *others], env=env, cwd=tmp)
    _run([py, "-m", "pip", "check"], env=env, cwd=tmp)
    # only to run the notebooks here; not part of the Binder image
    _run([*pip, *TEST_TOOLS], env=env, cwd=tmp)
    print(f"[{time.monotonic() - t0:6.1f} s] venv ready")
    return SimpleNamespace(venv=venv, py=py, env=env, tmp=tmp, wheel=wheel)


@pytest.mark.slow
def test_the_venv_runs_the_installed_wheel_not_the_source_tree(binder_venv):
    b = binder_venv
    code = ("import json, pathlib, importlib.metadata as m, rot4d_widget as r;"
            "d = m.distribution('rot4d_widget');"
            "print(json.dumps([r.__file__, r.__version__, d.read_text('direct_url.json')]))")
    where, version, direct_url = json.loads(_run([b.py, "-c", code], env=b.env, cwd=b.tmp).stdout)
    assert Path(where).is_relative_to(b.venv), where
    assert version == b.wheel.name.split("-")[1]
    assert '"editable": true' not in (direct_url or "") and b.wheel.name in (direct_url or ""), direct_url
    pkg = Path(where).parent
    assert (pkg / "view" / "page" / "companion.js").is_file() and list((pkg / "view" / "glsl").glob("*.vert"))
    assert (b.venv / "etc" / "jupyter" / "jupyter_server_config.d" / "rot4d_widget.json").is_file()


@pytest.mark.slow
def test_the_server_extension_is_enabled(binder_venv):
    b = binder_venv
    proc = _run([str(b.venv / "bin" / "jupyter"), "server", "extension", "list"], env=b.env, cwd=b.tmp)
    listing = ANSI.sub("", proc.stdout + proc.stderr)
    print(listing)
    # enabled by the config the wheel installed into the venv (sys-prefix), and it loads
    section = listing.split(f"Config dir: {b.venv / 'etc' / 'jupyter'}", 1)
    assert len(section) == 2, f"no config dir in the venv:\n{listing}"
    section = section[1].split("Config dir:", 1)[0]
    assert re.search(r"^\s*rot4d_widget\._server\s+enabled\s*$", section, re.MULTILINE), listing
    assert re.search(r"^\s*rot4d_widget\._server\s+(\S+\s+)?OK\s*$", section, re.MULTILINE), listing


@pytest.mark.slow
def test_binder_environment_has_the_lab_extensions(binder_venv):
    b = binder_venv
    # the browser side: prebuilt lab extensions, enabled and OK
    proc = _run([str(b.venv / "bin" / "jupyter"), "labextension", "list"], env=b.env, cwd=b.tmp)
    listing = ANSI.sub("", proc.stdout + proc.stderr)
    print(listing)
    for name in LAB_EXTENSIONS:
        line = re.search(rf"^\s*{re.escape(name)}\s+v\S+\s+(.*)$", listing, re.MULTILINE)
        assert line, f"{name} is not installed:\n{listing}"
        status = line.group(1).split()
        assert status[:2] == ["enabled", "OK"], f"{name}: {line.group(0).strip()}\n{listing}"


@pytest.mark.slow
def test_binder_environment_runs_the_notebooks(binder_venv):
    b = binder_venv
    # the notebooks, run by nbval in that environment (a copy, away from the repository's config
    # and source tree: the kernel can only import the installed wheel)
    work = b.tmp / "run"
    shutil.copytree(ROOT / "notebooks", work / "notebooks", ignore=shutil.ignore_patterns(".ipynb_checkpoints"))
    (work / "pytest.ini").write_text("[pytest]\n")
    proc = _run(
        [b.py, "-m", "pytest", "-p", "no:cacheprovider", "--nbval-lax", "--nbval-current-env", "-q", "notebooks"],
        env=b.env, cwd=work,
    )
    summary = proc.stdout.strip().splitlines()[-1]
    assert "failed" not in summary and "error" not in summary, proc.stdout[-3000:]
    # nbval makes one test item per code cell: every cell of every notebook ran
    import nbformat

    n_cells = sum(
        sum(c.cell_type == "code" for c in nbformat.read(path, as_version=4).cells)
        for path in (ROOT / "notebooks").glob("*.ipynb")
    )
    passed = re.search(r"(\d+) passed", summary)
    assert passed and int(passed.group(1)) == n_cells, f"expected {n_cells} cells to pass: {summary}"
    assert (ROOT / NOTEBOOK).is_file() and (work / NOTEBOOK).is_file()
