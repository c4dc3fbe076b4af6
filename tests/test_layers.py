"""The package's imports run one way (issue 20): core <- geometry <- sources <- keep <- view.

Parsed from the source (nothing imported): every ``import`` / ``from ... import`` of a
rot4d_widget module anywhere in a module (at its top or inside a function) is an edge.  The test
fails on an edge from a lower wing to a higher one, on a cycle between modules, on a widget
library imported outside the view, and on a module or class larger than the issue allows.

Imports sit at module tops: one inside a function says why (a comment on its line or the line
above its group), and it names neither a standard-library module nor a module of the package,
except a package module in `HEAVY_MODULES` and the modules in `LAZY_MODULES`.
"""

from __future__ import annotations

import ast
import pathlib
import sys

import pytest

PKG = pathlib.Path(__file__).resolve().parent.parent / "rot4d_widget"
WINGS = ("core", "geometry", "sources", "keep", "view")
WIDGET_LIBRARIES = ("ipywidgets", "pythreejs", "ipyevents", "traitlets", "anywidget", "IPython")
MAX_MODULE_LINES = 700
MAX_CLASS_LINES = 400
#: package modules that may be imported inside a function: what importing them pulls in
HEAVY_MODULES = {
    "rot4d_widget.keep.figures": "matplotlib and Pillow (~0.5 s)",
    "rot4d_widget.keep.drawing": "matplotlib (~0.35 s; keep.volume draws with it, the widget imports keep.volume)",
    "rot4d_widget.sources.fields": "numba and scikit-image (~0.5 s)",
    "rot4d_widget.view.scene": "pythreejs (~0.3 s)",
}
#: modules whose import must stay cheap (tests/test_server_extension.py): anything inside functions
LAZY_MODULES = {
    "rot4d_widget": "resolves every public name on first use; a Jupyter server imports it at start",
    "rot4d_widget._server": "the server extension, loaded by every Jupyter server at start",
}


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


def _edges():
    mods = _modules()
    edges = []  # (importer, imported, line, at top)
    for name, path in mods.items():
        tree = ast.parse(path.read_text(), str(path))
        top = {id(n) for n in tree.body}
        for node in ast.walk(tree):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                for target in _resolve(name, path.name == "__init__.py", node, mods):
                    if target != name:
                        edges.append((name, target, node.lineno, id(node) in top))
    return mods, edges


def _wing(module: str):
    parts = module.split(".")
    return parts[1] if len(parts) > 2 and parts[1] in WINGS else None


def test_imports_run_one_way_between_the_wings():
    mods, edges = _edges()
    assert {_wing(m) for m in mods} >= set(WINGS)
    upward = []
    for a, b, line, _ in edges:
        wa, wb = _wing(a), _wing(b)
        if wa is not None and wb is not None and WINGS.index(wb) > WINGS.index(wa):
            upward.append(f"{a} (line {line}) imports {b}: {wa} may not import {wb}")
    assert not upward, "\n".join(upward)


def test_no_import_cycle_between_modules():
    mods, edges = _edges()
    graph = {m: set() for m in mods}
    for a, b, _, _ in edges:
        if b in graph and not (b.count(".") < a.count(".") and a.startswith(b + ".")):  # a package's own init
            graph[a].add(b)
    # the package's __init__ and the wings' __init__s resolve names lazily: not part of a cycle
    for m in list(graph):
        if m == "rot4d_widget" or (m.count(".") == 1 and m.split(".")[1] in WINGS):
            graph[m] = set()
    seen, stack, cycles = {}, [], []

    def visit(m):
        seen[m] = 1
        stack.append(m)
        for n in sorted(graph[m]):
            if seen.get(n) == 1:
                cycles.append(" -> ".join(stack[stack.index(n):] + [n]))
            elif n not in seen:
                visit(n)
        stack.pop()
        seen[m] = 2

    for m in sorted(graph):
        if m not in seen:
            visit(m)
    assert not cycles, "\n".join(cycles)


def test_only_the_view_imports_widget_libraries():
    mods = _modules()
    bad = []
    for name, path in mods.items():
        if _wing(name) == "view" or name.count(".") == 0:
            continue
        tree = ast.parse(path.read_text(), str(path))
        for node in ast.walk(tree):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import)
                     else [node.module or ""] if isinstance(node, ast.ImportFrom) and not node.level else [])
            for n in names:
                if n.split(".")[0] in WIDGET_LIBRARIES:
                    bad.append(f"{name} (line {node.lineno}) imports {n}")
    assert not bad, "\n".join(bad)


def test_no_module_over_700_lines_and_no_class_over_400():
    big = []
    for name, path in _modules().items():
        text = path.read_text()
        n = text.count("\n")
        if n > MAX_MODULE_LINES:
            big.append(f"{name}: {n} lines")
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.ClassDef):
                size = node.end_lineno - node.lineno + 1
                if size > MAX_CLASS_LINES:
                    big.append(f"{name}.{node.name}: class of {size} lines")
    assert not big, "\n".join(big)


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
    ("    # a reason\n    from ..core.look import number_text\n", "package's rot4d_widget.core.look"),
    ("    import xarray\n", "without a comment"),
    ("    # optional\n    import xarray\n    from pde import grids\n", None),
    ("    # numba\n    from .fields import Field4D\n", None),
])
def test_the_inner_import_check_sees_a_light_or_silent_import(body, problem):
    """The checker itself, on a made-up module of the sources wing."""
    text = f"import math\n\n\ndef f():\n    \"\"\"Doc.\"\"\"\n{body}    return 1\n"
    found = _inner_import_problems("rot4d_widget.sources.protocol", text, _modules())
    if problem is None:
        assert found == []
    else:
        assert any(problem in f for f in found), found


@pytest.mark.parametrize("bad, why", [
    ("from ..view import widget", "imports rot4d_widget.view.widget: core may not import view"),
])
def test_the_layer_check_sees_an_upward_import(tmp_path, bad, why):
    """The checker itself: an upward import written into a core module is reported."""
    tree = ast.parse(bad)
    node = tree.body[0]
    mods = _modules()
    targets = _resolve("rot4d_widget.core.state", False, node, mods)
    assert targets == ["rot4d_widget.view.widget"]
    wa, wb = _wing("rot4d_widget.core.state"), _wing(targets[0])
    assert WINGS.index(wb) > WINGS.index(wa)
