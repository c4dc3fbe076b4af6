"""The committed notebooks are fit to be run by nbval (`--nbval-lax --nbval-current-env`).

nbval re-runs every notebook and, in lax mode, compares only the cells marked
``# NBVAL_CHECK_OUTPUT`` with their committed outputs.  It silently skips the comparison for a
cell saved without an execution count, and a cell saved without outputs compares as "nothing to
check".  So the stated facts are only tested if the committed copies carry what is checked here:
execution counts, outputs, no errors, and rounded (platform-independent) numbers.

The checks cover the project's own notebooks, listed by name in ``PROJECT_NOTEBOOKS``: a
notebook a user drops into notebooks/ is not the project's and is not checked here (nbval still
runs it, since pytest's testpaths include notebooks/).  A notebook committed to git but not
listed fails ``test_every_committed_notebook_is_listed``.
"""

import re
import shutil
import subprocess
from pathlib import Path

import nbformat
import pytest

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10: the test extra brings tomli
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[2]
NB_DIR = ROOT / "notebooks"
#: The project's notebooks, numbered 01, 02, ... without gaps; a new one is one line here.
PROJECT_NOTEBOOKS = [
    "01_pentachoron.ipynb",
    "02_regular_polychora.ipynb",
    "03_paper_figures.ipynb",
    "04_time_varying_field.ipynb",
    "05_tomography.ipynb",
    "06_uniform_polychora.ipynb",
    "07_your_data.ipynb",
    "08_real_fmri.ipynb",
    "09_star_polychora.ipynb",
]
NOTEBOOKS = [NB_DIR / name for name in PROJECT_NOTEBOOKS]
MARKER = "NBVAL_CHECK_OUTPUT"
WIDGET_MIME = "application/vnd.jupyter.widget-view+json"


def _is_marked(cell) -> bool:
    """nbval's rule: a comment line that is exactly the marker, or the cell tag nbval-check-output."""
    for line in cell.source.splitlines():
        line = line.strip()
        if line.startswith("#") and line.lstrip("#").strip() == MARKER:
            return True
    return "nbval-check-output" in cell.get("metadata", {}).get("tags", [])


def _text(output) -> str:
    if output.output_type == "stream":
        return output.text
    return output.get("data", {}).get("text/plain", "")


def _load(path):
    nb = nbformat.read(path, as_version=4)
    nbformat.validate(nb)
    return nb


@pytest.fixture(params=NOTEBOOKS, ids=lambda p: p.name)
def notebook(request):
    return request.param, _load(request.param)


def test_the_numbered_notebooks_are_there():
    for i, name in enumerate(PROJECT_NOTEBOOKS, start=1):
        assert re.fullmatch(r"\d\d_[a-z0-9_]+\.ipynb", name), name
        assert int(name[:2]) == i, f"notebooks are numbered 01, 02, ... without gaps: {PROJECT_NOTEBOOKS}"
        assert (NB_DIR / name).is_file(), f"notebooks/{name} is listed but missing"


@pytest.mark.skipif(shutil.which("git") is None or not (ROOT / ".git").exists(), reason="not a git checkout")
def test_every_committed_notebook_is_listed():
    """A notebook the project commits is checked; one a user drops into notebooks/ is not (untracked)."""
    out = subprocess.run(["git", "ls-files", "--", "notebooks/*.ipynb"], cwd=ROOT,
                         capture_output=True, text=True, check=True).stdout
    committed = sorted(Path(line).name for line in out.splitlines())
    assert set(committed) <= set(PROJECT_NOTEBOOKS), f"add to PROJECT_NOTEBOOKS: {sorted(set(committed) - set(PROJECT_NOTEBOOKS))}"


def test_every_notebook_states_checked_facts(notebook):
    path, nb = notebook
    assert any(c.cell_type == "code" and _is_marked(c) for c in nb.cells), f"{path.name} checks nothing"
    assert nb.metadata.get("kernelspec", {}).get("name") == "python3"


def test_marked_cells_have_execution_count_and_outputs(notebook):
    path, nb = notebook
    for i, cell in enumerate(nb.cells):
        if cell.cell_type != "code" or not _is_marked(cell):
            continue
        where = f"{path.name} cell {i}"
        assert isinstance(cell.execution_count, int), f"{where}: no execution count, nbval would skip it"
        assert cell.outputs, f"{where}: no outputs, nbval would compare nothing"
        assert any(_text(o).strip() for o in cell.outputs), f"{where}: no text output to compare"
        assert "assert" in cell.source, f"{where}: a printed fact must also be asserted"
        for out in cell.outputs:
            assert out.output_type != "error", f"{where}: committed with an error"
            assert WIDGET_MIME not in out.get("data", {}), f"{where}: widget views differ between runs"
            text = _text(out)
            # platform-independent: rounded numbers, no object addresses
            assert not re.search(r"\d\.\d{7,}", text), f"{where}: unrounded number in {text!r}"
            assert not re.search(r"0x[0-9a-f]{6,}", text), f"{where}: object address in {text!r}"
            assert "-0.0000" not in text, f"{where}: negative zero in {text!r}"


def test_executed_top_to_bottom_without_errors(notebook):
    """Committed outputs come from one fresh run (counts 1, 2, 3, ...), so they agree with each other."""
    path, nb = notebook
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert [c.execution_count for c in code] == list(range(1, len(code) + 1)), path.name
    for c in code:
        assert all(o.output_type != "error" for o in c.outputs), f"{path.name}: {c.source[:60]!r}"


def test_notebooks_stay_small(notebook):
    path, _ = notebook
    assert path.stat().st_size < 1_000_000, f"{path.name} is {path.stat().st_size} bytes"


def test_notebook_01_has_the_live_widget_cell():
    nb = _load(NB_DIR / "01_pentachoron.ipynb")
    cells = [c for c in nb.cells if c.cell_type == "code" and 'Rot4DWidget("5-cell")' in c.source]
    assert cells, "01_pentachoron.ipynb must display Rot4DWidget(\"5-cell\")"
    assert not any(_is_marked(c) for c in cells), "a widget view cannot be compared by nbval"


def test_the_default_test_command_runs_the_notebooks():
    """`python -m pytest` must collect notebooks/ with nbval, or the checks above test nothing."""
    conf = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["pytest"]["ini_options"]
    addopts = conf.get("addopts", "")
    addopts = " ".join(addopts) if isinstance(addopts, list) else addopts
    assert "--nbval-lax" in addopts.split()
    assert "--nbval-current-env" in addopts.split()
    assert "notebooks" in conf.get("testpaths", [])


def test_no_dangling_widget_views(notebook):
    """A widget view saved without its model shows "model not found" until the cell is re-run."""
    path, nb = notebook
    saved_state = "application/vnd.jupyter.widget-state+json" in nb.metadata.get("widgets", {})
    for cell in nb.cells:
        for out in cell.get("outputs", []):
            if WIDGET_MIME in out.get("data", {}):
                assert saved_state, f"{path.name}: widget view without saved widget state"
