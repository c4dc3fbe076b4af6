"""The package's imports run one way (issue 20): core <- geometry <- sources <- keep <- view.

Parsed from the source (nothing imported): every ``import`` / ``from ... import`` of a
rot4d_widget module anywhere in a module (at its top or inside a function) is an edge.  The test
fails on an edge from a lower wing to a higher one, on a cycle between modules, on a widget
library imported outside the view, and on a module or class larger than the issue allows.
"""

from __future__ import annotations

import ast
import pathlib

import pytest

PKG = pathlib.Path(__file__).resolve().parent.parent / "rot4d_widget"
WINGS = ("core", "geometry", "sources", "keep", "view")
WIDGET_LIBRARIES = ("ipywidgets", "pythreejs", "ipyevents", "traitlets", "anywidget", "IPython")
MAX_MODULE_LINES = 700
MAX_CLASS_LINES = 400


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
