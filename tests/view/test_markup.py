"""Text is never markup (issue 32): one module builds the page's HTML, and it escapes.

Read from the package's source (nothing imported).  The rules:

* Outside ``rot4d_widget/view/markup.py`` no string holds a piece of markup (a tag, ``<b>`` or
  ``<span style=...``, or an entity, ``&middot;``), no HTML widget is made, its ``value`` is not
  set (an ``x.value = ...`` anywhere but `ALLOWED_VALUE_SETS`, ``setattr(x, "value", ...)``,
  ``set_trait("value", ...)``), no ``Markup`` is made and ``markupsafe`` is not imported, and no
  widget's description is allowed to be HTML.
* In ``markup.py`` every string that holds markup is the literal argument of ``Markup(...)``:
  no f-string, ``+``, ``%`` or ``str.format`` builds markup, so every value goes in through
  ``Markup.format`` / ``Markup.join``, which escape.
* The page's JavaScript never parses a string as HTML (``innerHTML``, ``outerHTML``,
  ``insertAdjacentHTML``, ``document.write``, ``createContextualFragment``, ``DOMParser``).

The checker is tested on snippets first: each rule must catch the violation it is for.
"""

from __future__ import annotations

import ast
import pathlib
import re

import pytest

PKG = pathlib.Path(__file__).resolve().parents[2] / "rot4d_widget"
MARKUP = PKG / "view" / "markup.py"

#: A piece of markup in a string: a tag's start (``<b>``, ``</td``, ``<span style=``, ``<br/``) or
#: an entity (``&middot;``, ``&#215;``).  ``"<f4"`` (a dtype) and ``"a < b"`` are not.
MARKUP_RE = re.compile(r"</?[A-Za-z][A-Za-z0-9-]*(?=[\s/>])|&(?:[A-Za-z]+|#[0-9]+|#x[0-9A-Fa-f]+);")

#: ``x.value = ...`` outside markup.py: (file relative to the package, the target's source) and why
ALLOWED_VALUE_SETS = {
    ("view/progress.py", "self.bar.value"): "an IntProgress: a number",
    ("view/progress.py", "self.label.value"): "an ipywidgets Label: text, shown as text",
}

HTML_WIDGETS = {"HTML", "HTMLMath"}
JS_HTML_SINKS = re.compile(r"\b(innerHTML|outerHTML|insertAdjacentHTML|document\.write|createContextualFragment"
                           r"|DOMParser)\b")


def _docstrings(tree) -> set:
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                out.add(id(body[0].value))
    return out


def _string_text(node) -> str | None:
    """The text of a string literal (an f-string's holes as ``\\x00``), else None."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.JoinedStr):
        return "".join(v.value if isinstance(v, ast.Constant) else "\x00" for v in node.values)
    return None


def _call_name(node) -> str | None:
    f = node.func
    return f.attr if isinstance(f, ast.Attribute) else f.id if isinstance(f, ast.Name) else None


def violations(source: str, name: str, in_markup: bool) -> list[str]:
    """The rule breaches of one module's ``source`` (``name`` relative to the package)."""
    tree = ast.parse(source)
    docs = _docstrings(tree)
    out = []
    markup_args = set()  # string literals that are the argument of Markup(...)
    for node in ast.walk(tree):
        if isinstance(node, ast.Call) and _call_name(node) == "Markup" and node.args:
            markup_args.add(id(node.args[0]))
        if isinstance(node, ast.JoinedStr):  # an f-string is checked whole, not its parts again
            docs.update(id(v) for v in node.values)
    for node in ast.walk(tree):
        where = f"{name}:{getattr(node, 'lineno', '?')}"
        text = _string_text(node)
        if text is not None and id(node) not in docs and MARKUP_RE.search(text):
            if not in_markup:
                out.append(f"{where}: markup in a string outside view/markup.py: {text[:60]!r}")
            elif id(node) not in markup_args or isinstance(node, ast.JoinedStr):
                out.append(f"{where}: markup built outside a Markup(...) literal: {text[:60]!r}")
        if in_markup:
            continue
        if isinstance(node, ast.Call):
            call = _call_name(node)
            if call in HTML_WIDGETS:
                out.append(f"{where}: an HTML widget made outside view/markup.py")
            if call == "Markup":
                out.append(f"{where}: Markup made outside view/markup.py")
            if call == "setattr" and len(node.args) > 1 and _string_text(node.args[1]) == "value":
                out.append(f"{where}: setattr(..., 'value', ...) outside view/markup.py")
            if call == "set_trait" and node.args and _string_text(node.args[0]) == "value":
                out.append(f"{where}: set_trait('value', ...) outside view/markup.py")
            for kw in node.keywords:
                if kw.arg is not None and "allow_html" in kw.arg:
                    out.append(f"{where}: {kw.arg} outside view/markup.py")
        if isinstance(node, (ast.Assign, ast.AugAssign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            for t in targets:
                for sub in ast.walk(t):
                    if isinstance(sub, ast.Attribute) and sub.attr == "value":
                        expr = ast.unparse(sub)
                        if (name, expr) not in ALLOWED_VALUE_SETS:
                            out.append(f"{where}: {expr} = ... outside view/markup.py")
                    elif isinstance(sub, ast.Attribute) and "allow_html" in sub.attr:
                        out.append(f"{where}: {ast.unparse(sub)} = ... outside view/markup.py")
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            mods = [a.name for a in node.names] if isinstance(node, ast.Import) else [node.module or ""]
            if any(m.split(".")[0] == "markupsafe" for m in mods):
                out.append(f"{where}: markupsafe imported outside view/markup.py")
    return out


def _package_modules():
    for path in sorted(PKG.rglob("*.py")):
        yield path, path.relative_to(PKG).as_posix()


# ----------------------------------------------------------------------------- the checker itself
@pytest.mark.parametrize("snippet", [
    "w.readout.value = '<b>' + name + '</b>'",
    "w.readout.value = text",
    "self.caption.value = f'<div>{x}</div>'",
    "row = '<span style=\"color:red\">' + name",
    "row = f\"<td>{name}</td>\"",
    "row = 'a &middot; b'",
    "row = '<td>%s</td>' % name",
    "label = widgets.HTML(text)",
    "label = ipywidgets.HTMLMath(value=text)",
    "setattr(w.readout, 'value', text)",
    "w.readout.set_trait('value', text)",
    "b = widgets.Checkbox(description=name, description_allow_html=True)",
    "from markupsafe import Markup",
    "x = Markup(name)",
])
def test_the_checker_catches_markup_built_or_shown_outside_markup_py(snippet):
    assert violations(snippet, "view/painter.py", in_markup=False)


@pytest.mark.parametrize("snippet", [
    "x = f\"<td>{name}</td>\"",
    "x = '<b>' + name",
    "x = '<td>{}</td>'.format(name)",
    "x = '<td>%s</td>' % name",
    "x = Markup(f'<b>{name}</b>')",
    "x = Markup('<b>' + name + '</b>')",
])
def test_the_checker_catches_markup_built_by_hand_in_markup_py(snippet):
    assert violations(snippet, "view/markup.py", in_markup=True)


@pytest.mark.parametrize("snippet", [
    "x = np.zeros(3).astype('<f4')",
    "msg = f'expected 0 < c0 < {hi}'",
    "self.bar.value = count",
    "'''A docstring may say <b>bold</b>.'''",
])
def test_the_checker_lets_text_be(snippet):
    assert not violations(snippet, "view/progress.py", in_markup=False)


def test_markup_py_builds_markup_only_from_literals():
    assert not violations("x = Markup('<td>{}</td>').format(name)\ny = Markup('').join(parts)",
                          "view/markup.py", in_markup=True)


# ----------------------------------------------------------------------------- the package
def test_no_module_but_markup_py_builds_or_shows_html():
    found = []
    for path, name in _package_modules():
        found += violations(path.read_text(), name, in_markup=path == MARKUP)
    assert not found, "\n".join(found)


def test_every_allowed_value_set_still_exists():
    """An allowance that no longer matches code goes (it would hide a new assignment there)."""
    seen = set()
    for path, name in _package_modules():
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Assign):
                for t in node.targets:
                    if isinstance(t, ast.Attribute) and t.attr == "value":
                        seen.add((name, ast.unparse(t)))
    assert set(ALLOWED_VALUE_SETS) <= seen


def test_the_page_never_parses_a_string_as_html():
    found = []
    for path in sorted(PKG.rglob("*.js")):
        for i, line in enumerate(path.read_text().splitlines(), 1):
            if JS_HTML_SINKS.search(line):
                found.append(f"{path.name}:{i}: {line.strip()}")
    assert not found, "\n".join(found)


def test_show_and_html_widget_refuse_plain_text():
    import ipywidgets

    from rot4d_widget.view import markup

    with pytest.raises(TypeError, match="never shown as markup"):
        markup.show(ipywidgets.HTML(), "<img src=x onerror=alert(1)>")
    with pytest.raises(TypeError, match="never shown as markup"):
        markup.html_widget("<b>x</b>")
    w = markup.html_widget(markup.keypad_label_html("<b>x</b>"))
    assert w.value == "<small>&lt;b&gt;x&lt;/b&gt;</small>"
