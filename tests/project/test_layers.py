"""The package's import rules (issue 38): contracts for import-linter, and what it cannot see.

The rules live in ``pyproject.toml`` (``[tool.importlinter]``) and `test_the_import_contracts_hold`
runs ``lint-imports`` on them:

``wings``
    core <- geometry <- sources <- keep <- view: a lower wing never imports a higher one;
``widget-libraries``
    only the view imports ipywidgets, pythreejs, ipyevents, traitlets, anywidget or IPython;
``no-root``
    no module of the package imports the root package: its ``__init__`` is the table of public
    names (and, in a kernel, registers the view's progress bar), so importing it from a wing is
    a way round the wings;
``no-cycles``
    no import cycle between the modules (or subpackages) of one package.

Each contract is seen failing here on a copy of the package with a violation written into it
(`test_each_contract_fails_on_a_violation`).  Sizes are not checked: modules and classes are as
large as what they hold.

What import-linter cannot see is checked by hand below:

* imports inside functions: one says why (a comment on its line or the line above its group), and
  names neither a standard-library module nor a module of the package, except a package module in
  `HEAVY_MODULES` and the modules in `LAZY_MODULES`;
* modules loaded by name (``importlib.import_module``, ``__import__``): only where `LOADS_BY_NAME`
  says why, since an edge made from a string is invisible to the contracts.
"""

from __future__ import annotations

import ast
import os
import pathlib
import shutil
import subprocess
import sys

import pytest

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    import tomli as tomllib

ROOT = pathlib.Path(__file__).resolve().parents[2]
PKG = ROOT / "rot4d_widget"
WINGS = ("core", "geometry", "sources", "keep", "view")
#: package modules that may be imported inside a function: what importing them pulls in
HEAVY_MODULES = {
    "rot4d_widget.keep.pictures.state_picture": "matplotlib and Pillow (~0.5 s: it draws with every other picture module)",
    "rot4d_widget.keep.pictures.canvas": "matplotlib's Figure and Text (the animation's reused figure)",
    "rot4d_widget.keep.pictures.framing": "matplotlib, through keep.pictures.slice_drawing",
    "rot4d_widget.keep.pictures.slice_drawing": "matplotlib (~0.35 s; keep.pictures.ray_caster draws with it, the widget imports keep.pictures.ray_caster)",
    "rot4d_widget.sources.field.container": "numba and scikit-image (~0.5 s)",
    "rot4d_widget.sources.field.surface": "scikit-image (marching cubes)",
    "rot4d_widget.view.scene": "pythreejs (~0.3 s)",
}
#: modules whose import must stay cheap (tests/project/test_server_extension.py): anything inside functions
LAZY_MODULES = {
    "rot4d_widget": "resolves every public name on first use; a Jupyter server imports it at start",
    "rot4d_widget._server": "the server extension, loaded by every Jupyter server at start",
}
#: the modules that load modules by name, and what they load
LOADS_BY_NAME = {
    "rot4d_widget": "its public names (the table `_LAZY`) and, in a kernel, view.progress: the root is above "
                    "every wing, and no package module imports it (contract no-root)",
    "rot4d_widget.keep.rebuild": "the function a state file names (``module:qualname``), only when the caller "
                                 "allows code: a user's module, not an edge of the package",
}
#: the contracts pyproject.toml must declare (a contract taken out is noticed)
CONTRACTS = {"wings", "widget-libraries", "no-root", "no-cycles"}


def _modules():
    """{dotted name: path} of every module of the package (``rot4d_widget.core.state`` ...)."""
    out = {}
    for path in sorted(PKG.rglob("*.py")):
        rel = path.relative_to(PKG.parent).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def _resolve(module: str, is_package: bool, node: ast.ImportFrom | ast.Import, known) -> list:
    """The rot4d_widget modules an import statement of ``module`` names."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names if a.name.split(".")[0] == "rot4d_widget"]
    base = module.split(".") if is_package else module.split(".")[:-1]
    if node.level:
        base = base[: len(base) - (node.level - 1)]
        target = ".".join(base + ([node.module] if node.module else []))
    else:
        target = node.module or ""
    if target.split(".")[0] != "rot4d_widget":
        return []
    out = []
    for alias in node.names:  # `from .pkg import module` names a module
        sub = f"{target}.{alias.name}"
        out.append(sub if sub in known else target)
    return out


def _lint_imports(root: pathlib.Path, config: pathlib.Path) -> subprocess.CompletedProcess:
    """``lint-imports`` on the package under ``root`` (first on its path), with the contracts of ``config``."""
    code = ("import importlib.util, pathlib, sys; "
            "origin = pathlib.Path(importlib.util.find_spec('rot4d_widget').origin); "
            f"assert origin.is_relative_to({str(root)!r}), origin; "
            "from importlinter.cli import lint_imports_command; sys.exit(lint_imports_command())")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(root), os.environ.get("PYTHONPATH", "")]))
    return subprocess.run([sys.executable, "-c", code, "--no-cache", "--no-logo", str(config)], cwd=root, env=env,
                          capture_output=True, text=True, timeout=300)


def test_pyproject_declares_the_contracts():
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]
    contracts = {c["id"]: c for c in config["contracts"]}
    assert set(contracts) == CONTRACTS
    assert config["root_package"] == "rot4d_widget"
    assert contracts["wings"]["layers"] == list(reversed(WINGS))
    assert {m.split(".")[1] for m in contracts["widget-libraries"]["source_modules"]} >= set(WINGS) - {"view"}


def test_the_import_contracts_hold():
    out = _lint_imports(ROOT, ROOT / "pyproject.toml")
    assert out.returncode == 0, out.stdout + out.stderr
    assert f"Contracts: {len(CONTRACTS)} kept, 0 broken." in out.stdout, out.stdout


@pytest.mark.parametrize("module, line, contract", [
    ("core/state.py", "from ..view import widget", "The wings import one way"),
    ("keep/meshes.py", "import ipywidgets", "Only the view imports a widget library"),
    ("keep/statefile.py", "from .. import __version__", "No module of the package imports the root package"),
    ("view/markup.py", "import rot4d_widget", "No module of the package imports the root package"),
    ("core/rotation.py", "from . import state", "No import cycle"),
])
def test_each_contract_fails_on_a_violation(tmp_path, module, line, contract):
    """A copy of the package with ``line`` added to ``module``: ``lint-imports`` names the contract broken."""
    shutil.copytree(PKG, tmp_path / "rot4d_widget", ignore=lambda d, names: [
        n for n in names if not (n.endswith(".py") or (pathlib.Path(d) / n).is_dir()) or n == "__pycache__"])
    target = tmp_path / "rot4d_widget" / module
    target.write_text(target.read_text() + f"\n{line}  # a violation, on purpose\n")
    out = _lint_imports(tmp_path, ROOT / "pyproject.toml")
    assert out.returncode == 1, out.stdout + out.stderr
    broken = out.stdout.split("Broken contracts", 1)[-1]
    assert contract in broken, out.stdout  # (an upward import between wings is a cycle of wings too)


def _inner_imports(tree):
    """The import statements inside function bodies (at any depth)."""
    out = []

    def visit(node, inside):
        for child in ast.iter_child_nodes(node):
            if inside and isinstance(child, (ast.Import, ast.ImportFrom)):
                out.append(child)
            visit(child, inside or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)))

    visit(tree, False)
    return out


def _says_why(lines, node) -> bool:
    """A comment on the import's line, on an import line of its group above it, or on the line
    above the group."""
    i = node.lineno - 1
    while i >= 0:
        line = lines[i].strip()
        if "#" in line:
            return True
        if i != node.lineno - 1 and not line.startswith(("import ", "from ")):
            return False
        i -= 1
    return False


def _inner_import_problems(name: str, text: str, known) -> list:
    """What is wrong with the imports inside the functions of module ``name`` (source ``text``)."""
    lines = text.splitlines()
    problems = []
    for node in _inner_imports(ast.parse(text)):
        where = f"{name} (line {node.lineno}) `{ast.unparse(node)}`"
        if not _says_why(lines, node):
            problems.append(f"{where}: inside a function without a comment saying why")
        if name in LAZY_MODULES:
            continue
        is_package = name in known and known[name].name == "__init__.py"
        for target in _resolve(name, is_package, node, known):
            if target not in HEAVY_MODULES:
                problems.append(f"{where}: imports the package's {target}, which belongs at the module top")
        stdlib = ([a.name for a in node.names] if isinstance(node, ast.Import)
                  else [node.module or ""] if not node.level else [])
        for n in stdlib:
            if n.split(".")[0] in sys.stdlib_module_names:
                problems.append(f"{where}: imports the standard library's {n}, which belongs at the module top")
    return problems


def test_imports_inside_functions_say_why_and_are_not_light():
    mods = _modules()
    problems = []
    for name, path in mods.items():
        problems += _inner_import_problems(name, path.read_text(), mods)
    assert not problems, "\n".join(problems)


@pytest.mark.parametrize("body, problem", [
    ("    import os\n", "without a comment"),
    ("    import os  # why not\n", "standard library's os"),
    ("    # a reason\n    from ..core.text import number_text\n", "package's rot4d_widget.core.text"),
    ("    import xarray\n", "without a comment"),
    ("    # optional\n    import xarray\n    from pde import grids\n", None),
    ("    # numba\n    from .field.container import Field4D\n", None),
])
def test_the_inner_import_check_sees_a_light_or_silent_import(body, problem):
    """The checker itself, on a made-up module of the sources wing."""
    text = f"import math\n\n\ndef f():\n    \"\"\"Doc.\"\"\"\n{body}    return 1\n"
    found = _inner_import_problems("rot4d_widget.sources.protocol", text, _modules())
    if problem is None:
        assert found == []
    else:
        assert any(problem in f for f in found), found


def _loads_by_name(tree) -> list:
    """The calls ``importlib.import_module(...)``, ``import_module(...)`` and ``__import__(...)``."""
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            f = node.func
            name = f.attr if isinstance(f, ast.Attribute) else f.id if isinstance(f, ast.Name) else None
            if name in ("import_module", "__import__"):
                out.append(node)
    return out


def _by_name_problems(name: str, text: str) -> list:
    if name in LOADS_BY_NAME:
        return []
    return [f"{name} (line {node.lineno}) `{ast.unparse(node)}`: loads a module by name, an import the contracts "
            "cannot see; import it at the top (or say in LOADS_BY_NAME why it must be loaded by name)"
            for node in _loads_by_name(ast.parse(text))]


def test_modules_are_loaded_by_name_only_where_it_is_said_why():
    mods = _modules()
    problems = []
    for name, path in mods.items():
        problems += _by_name_problems(name, path.read_text())
    assert not problems, "\n".join(problems)
    for name in LOADS_BY_NAME:  # each entry still loads something (a stale entry is noticed)
        assert _loads_by_name(ast.parse(mods[name].read_text())), f"{name} loads nothing by name any more"


@pytest.mark.parametrize("body", [
    "importlib.import_module('rot4d_widget.view.widget')",
    "import_module('..view.widget', __package__)",
    "__import__('rot4d_widget.view.widget')",
])
def test_the_by_name_check_sees_a_load(body):
    """The checker itself, on a made-up module of the core."""
    found = _by_name_problems("rot4d_widget.core.state", f"import importlib\n\n\ndef f():\n    return {body}\n")
    assert len(found) == 1 and "loads a module by name" in found[0], found
