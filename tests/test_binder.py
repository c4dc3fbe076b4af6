"""The Binder configuration builds what Binder would build, and the notebooks run there.

No Docker engine is needed: repo2docker's Python build pack creates one environment with
JupyterLab 4 / Notebook 7 / ipywidgets 8 and then, because ``binder/requirements.txt`` names a
local path, copies the whole repository and runs ``pip install -r binder/requirements.txt`` with
the repository root as working directory.  The slow test does the same in a fresh venv, then
checks the lab extensions and runs the notebooks with nbval against the *installed* package.

Deselect it locally with ``-m "not slow"``; the default test command (and CI) runs it.
"""

import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
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
    import tomllib

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


@pytest.mark.slow
def test_binder_environment_has_the_extensions_and_runs_the_notebooks(tmp_path):
    venv = tmp_path / "binder-venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, timeout=300)
    py = str(venv / "bin" / "python")
    env = _clean_env(tmp_path, venv)
    pip = [py, "-m", "pip", "install", "--quiet"]

    # 1. Binder's base image, 2. binder/requirements.txt from the repository root (as repo2docker)
    _run([*pip, "--upgrade", "pip"], env=env, cwd=tmp_path)
    _run([*pip, *BASE_IMAGE], env=env, cwd=tmp_path)
    _run([*pip, "-r", str(REQUIREMENTS.relative_to(ROOT))], env=env, cwd=ROOT)
    _run([py, "-m", "pip", "check"], env=env, cwd=tmp_path)

    # the kernel imports the installed package, not the source tree
    where = _run([py, "-c", "import rot4d_widget; print(rot4d_widget.__file__)"], env=env, cwd=tmp_path)
    assert Path(where.stdout.strip()).is_relative_to(venv), where.stdout

    # the browser side: prebuilt lab extensions, enabled and OK
    proc = _run([str(venv / "bin" / "jupyter"), "labextension", "list"], env=env, cwd=tmp_path)
    listing = ANSI.sub("", proc.stdout + proc.stderr)
    print(listing)
    for name in LAB_EXTENSIONS:
        line = re.search(rf"^\s*{re.escape(name)}\s+v\S+\s+(.*)$", listing, re.MULTILINE)
        assert line, f"{name} is not installed:\n{listing}"
        status = line.group(1).split()
        assert status[:2] == ["enabled", "OK"], f"{name}: {line.group(0).strip()}\n{listing}"

    # the notebooks, run by nbval in that environment (a copy, away from the repository's config)
    _run([*pip, *TEST_TOOLS], env=env, cwd=tmp_path)
    work = tmp_path / "run"
    shutil.copytree(ROOT / "notebooks", work / "notebooks", ignore=shutil.ignore_patterns(".ipynb_checkpoints"))
    (work / "pytest.ini").write_text("[pytest]\n")
    proc = _run(
        [py, "-m", "pytest", "-p", "no:cacheprovider", "--nbval-lax", "--nbval-current-env", "-q", "notebooks"],
        env=env, cwd=work,
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
