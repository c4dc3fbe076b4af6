"""The package's unit rules (issue 38), checked on its source: units own their state.

* **No private access across modules.**  A module never imports another module's private name
  (``from .x import _name``), and ``obj._x`` appears only where ``obj`` is ``self``, ``cls``,
  ``super()`` or an object of a class defined in the same module -- read here as: ``_x`` is a
  member that a class of this module defines (a method, a class attribute or ``self._x = ...``).
  A third-party object's private member is allowed only where `THIRD_PARTY_PRIVATE` says why.
* **No view unit is handed the widget.**  In ``view/widget.py`` the widget passes itself to a
  unit only as the unit's ``traits`` (its settings, which are the widget's traits), and every
  view unit uses its ``traits`` only for trait names and the traitlets API (`TRAITS_API`): a
  unit that reached the widget's children or other units through it would fail here.  Every
  other collaborator is handed over by name (the constructor, or ``connect`` for a loop).

* **Sources are read through the protocol.**  No module but ``sources/protocol.py`` asks an
  object whether it has one of the source protocol's optional members (``getattr(source,
  "levels", None)``, ``hasattr(source, "sample")``): `SourceBase` gives every source each of them
  with its default, and a user's object is read only by the `UserSource` wrapping it.  An object
  that is not a source but has a member of the same name is allowed where `NOT_A_SOURCE` says so.

Each rule is seen failing on a snippet that breaks it (the ``..._sees_...`` tests).  Counts of
what was reached into before these rules: ``python benchmarks/structure.py``.
"""

from __future__ import annotations

import ast
import builtins
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
PKG = ROOT / "rot4d_widget"
#: ``(module path, member)``: a private member of a third-party object the package uses, and why.
THIRD_PARTY_PRIVATE = {
    ("keep/pictures/canvas.py", "_set_transform"):
        "matplotlib's FT2Font has no public way to render a glyph at a sub-pixel origin with the "
        "slant/extend transform; the glyph cache repeats backend_agg's own text drawing (matplotlib "
        "3.11), which calls these same two, so that its pixels are matplotlib's",
    ("keep/pictures/canvas.py", "_render_glyph"): "the same: backend_agg renders each glyph with it",
}
#: What a unit may do with the widget it holds as its ``traits``, besides reading and setting traits.
TRAITS_API = frozenset({"observe", "unobserve", "set_trait", "has_trait", "hold_trait_notifications", "trait_names"})


def _private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def _own_members(tree: ast.Module) -> set:
    """Private members the classes of a module define: methods, class attributes, ``self._x = ...``."""
    own = set()
    for node in ast.walk(tree):
        if not isinstance(node, ast.ClassDef):
            continue
        for item in node.body:
            if isinstance(item, (ast.FunctionDef, ast.AsyncFunctionDef)):
                own.add(item.name)
            elif isinstance(item, ast.Assign):
                own.update(t.id for t in item.targets if isinstance(t, ast.Name))
            elif isinstance(item, ast.AnnAssign) and isinstance(item.target, ast.Name):
                own.add(item.target.id)
        for sub in ast.walk(node):
            if (isinstance(sub, ast.Attribute) and isinstance(sub.ctx, ast.Store)
                    and isinstance(sub.value, ast.Name) and sub.value.id in ("self", "cls")):
                own.add(sub.attr)
    return own


def private_access_problems(rel: str, text: str) -> list:
    """``line: what`` for every private import of a package module and every ``obj._x`` not of this
    module's own classes in the module ``rel`` (a path under the package's folder)."""
    tree = ast.parse(text)
    own = _own_members(tree)
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.level or (node.module or "").startswith("rot4d_widget")):
            out += [f"{node.lineno}: imports {a.name} from {'.' * node.level}{node.module or ''}"
                    for a in node.names if _private(a.name)]
        elif isinstance(node, ast.Attribute) and _private(node.attr):
            base = node.value
            if isinstance(base, ast.Name) and base.id in ("self", "cls"):
                continue
            if isinstance(base, ast.Call) and isinstance(base.func, ast.Name) and base.func.id == "super":
                continue
            if node.attr in own or (rel, node.attr) in THIRD_PARTY_PRIVATE:
                continue
            out.append(f"{node.lineno}: reaches into {ast.unparse(node)}")
    return out


def _modules():
    for path in sorted(PKG.rglob("*.py")):
        yield path.relative_to(PKG).as_posix(), path.read_text(encoding="utf-8")


def test_no_module_reaches_into_another_modules_private_parts():
    problems = [f"{rel}:{p}" for rel, text in _modules() for p in private_access_problems(rel, text)]
    assert not problems, "private access across modules:\n" + "\n".join(problems)


def test_every_third_party_exception_is_still_used():
    texts = dict(_modules())
    stale = [k for k in THIRD_PARTY_PRIVATE if k[0] not in texts or f".{k[1]}" not in texts[k[0]]]
    assert not stale


@pytest.mark.parametrize("body, problem", [
    ("from .pump import _lower_median\n", "imports _lower_median"),
    ("from rot4d_widget.core.state import _check\n", "imports _check"),
    ("def f(w):\n    return w._pump\n", "reaches into w._pump"),
    ("class A:\n    def f(self, other):\n        return other._b\n", "reaches into other._b"),
    ("def f(w):\n    w._x = 1\n", "reaches into w._x"),
])
def test_the_private_access_check_sees_a_reach(body, problem):
    got = private_access_problems("view/example.py", body)
    assert any(problem in p for p in got), got


@pytest.mark.parametrize("body", [
    "class A:\n    def __init__(self):\n        self._b = 1\n    def same(self, other):\n        return other._b\n",
    "class A:\n    def _f(self):\n        pass\n\ndef g(a):\n    return a._f()\n",
    "class A(B):\n    def f(self):\n        return super()._f()\n",
    "from .pump import lower_median\nx = y.__dict__\n",
])
def test_the_private_access_check_lets_own_members_be(body):
    assert private_access_problems("view/example.py", body) == []


# -- the widget hands its units what they use ---------------------------------------------------
def _widget_class(tree: ast.Module) -> ast.ClassDef:
    return next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "Rot4DWidget")


def _trait_names(cls: ast.ClassDef) -> set:
    """The traits the widget class declares (``name = <trait>(...)`` in its body)."""
    return {t.id for n in cls.body if isinstance(n, ast.Assign) and isinstance(n.value, ast.Call)
            for t in n.targets if isinstance(t, ast.Name)}


def _init_params(tree: ast.Module) -> dict:
    """``{class name: [its __init__'s parameter names, self left out]}`` of a module's classes."""
    out = {}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            for item in node.body:
                if isinstance(item, ast.FunctionDef) and item.name == "__init__":
                    out[node.name] = [a.arg for a in item.args.args[1:]] + [a.arg for a in item.args.kwonlyargs]
    return out


def handed_widget_problems(widget_text: str, units: dict) -> list:
    """Where ``view/widget.py`` (``widget_text``) hands ``self`` to a unit other than as its
    ``traits``; ``units``: ``{class name: its __init__'s parameter names}`` of the view's classes."""
    cls = _widget_class(ast.parse(widget_text))
    out = []
    for node in ast.walk(cls):
        if not isinstance(node, ast.Call):
            continue
        callee = node.func.id if isinstance(node.func, ast.Name) else None
        if callee is not None and hasattr(builtins, callee):
            continue  # getattr(self, ...), id(self): the widget asking of itself
        for i, arg in enumerate(node.args):
            if isinstance(arg, ast.Name) and arg.id == "self":
                params = units.get(callee, [])
                if i >= len(params) or params[i] != "traits":
                    out.append(f"{node.lineno}: {callee or ast.unparse(node.func)} is handed the widget")
        for kw in node.keywords:
            if isinstance(kw.value, ast.Name) and kw.value.id == "self" and kw.arg != "traits":
                out.append(f"{node.lineno}: {callee} is handed the widget as {kw.arg}")
    return out


def traits_use_problems(text: str, traits: set) -> list:
    """Every ``self.traits.<name>`` in a module that is neither a trait of the widget nor `TRAITS_API`."""
    out = []
    for node in ast.walk(ast.parse(text)):
        if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Attribute)
                and node.value.attr == "traits" and isinstance(node.value.value, ast.Name)
                and node.value.value.id == "self" and node.attr not in traits and node.attr not in TRAITS_API):
            out.append(f"{node.lineno}: self.traits.{node.attr} is not a trait")
    return out


def _view_units() -> dict:
    units = {}
    for path in sorted((PKG / "view").glob("*.py")):
        units.update(_init_params(ast.parse(path.read_text(encoding="utf-8"))))
    return units


def test_no_view_unit_is_handed_the_widget():
    text = (PKG / "view" / "widget.py").read_text(encoding="utf-8")
    problems = handed_widget_problems(text, _view_units())
    assert not problems, "\n".join(problems)


def test_view_units_use_the_widget_only_for_its_traits():
    traits = _trait_names(_widget_class(ast.parse((PKG / "view" / "widget.py").read_text(encoding="utf-8"))))
    assert {"rendering", "clim", "projection", "levels"} <= traits
    problems = [f"view/{p.name}:{q}" for p in sorted((PKG / "view").glob("*.py"))
                for q in traits_use_problems(p.read_text(encoding="utf-8"), traits)]
    assert not problems, "\n".join(problems)


_WIDGET = '''
class Rot4DWidget(HBox):
    rendering = t.Rendering("surface")
    def __init__(self):
        self._painter = Painter(self, 1)
        self._keys = KeyPath({})
'''


@pytest.mark.parametrize("line, problem", [
    ("        self._keys = KeyPath(self)", "KeyPath is handed the widget"),
    ("        self._keys = KeyPath(1, self)", "KeyPath is handed the widget"),
    ("        self._keys = KeyPath(owner=self)", "KeyPath is handed the widget as owner"),
])
def test_the_handed_widget_check_sees_a_unit_handed_the_widget(line, problem):
    text = _WIDGET.replace("        self._keys = KeyPath({})", line)
    got = handed_widget_problems(text, {"Painter": ["traits", "n"], "KeyPath": ["table"]})
    assert any(problem in p for p in got), got
    assert handed_widget_problems(_WIDGET, {"Painter": ["traits", "n"], "KeyPath": ["table"]}) == []


@pytest.mark.parametrize("use", ["self.traits._pump.flush()", "self.traits.scene.show()", "self.traits.refresh()"])
def test_the_traits_check_sees_a_reach_through_the_widget(use):
    body = f"class P:\n    def f(self):\n        x = self.traits.rendering\n        {use}\n"
    got = traits_use_problems(body, {"rendering"})
    assert len(got) == 1, got


# ------------------------------------------------------------------ sources read through the protocol
#: ``(module path, member)``: a ``getattr`` / ``hasattr`` with an optional protocol member's name
#: on an object that is not a source, and what the object is.
NOT_A_SOURCE = {
    ("geometry/offfile.py", "name"): "a file handle's name (an OFF file read from an open file)",
    ("keep/recorder.py", "name"): "a source action's name (any object in a source's `actions`)",
    ("sources/field/inputs.py", "dims"): "an xarray DataArray's or Dataset's dims (telling one by its members)",
}


def optional_member_probes(rel: str, text: str) -> list:
    """``getattr(x, "levels", ...)`` or ``hasattr(x, "levels")`` with one of the protocol's optional
    members (`OPTIONAL_MEMBERS`) as a literal: asking a source whether it has a member that
    `SourceBase` gives every source (with its default) -- outside sources/protocol.py, whose
    `UserSource` alone reads a user's object."""
    from rot4d_widget.sources.protocol import OPTIONAL_MEMBERS

    out = []
    for node in ast.walk(ast.parse(text)):
        if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                and node.func.id in ("getattr", "hasattr") and len(node.args) >= 2
                and isinstance(node.args[1], ast.Constant) and node.args[1].value in OPTIONAL_MEMBERS
                and (node.func.id == "hasattr" or len(node.args) == 3)
                and (rel, node.args[1].value) not in NOT_A_SOURCE):
            out.append(f"{rel}:{node.lineno}: {ast.unparse(node)}")
    return out


def test_sources_are_read_through_the_protocol_not_probed():
    problems = [p for rel, text in _modules() if rel != "sources/protocol.py"
                for p in optional_member_probes(rel, text)]
    assert problems == []


def test_every_not_a_source_exception_is_still_used():
    from rot4d_widget.sources.protocol import OPTIONAL_MEMBERS

    texts = dict(_modules())
    for rel, member in NOT_A_SOURCE:
        assert member in OPTIONAL_MEMBERS and f'"{member}"' in texts[rel], (rel, member)


@pytest.mark.parametrize("body", [
    'def f(source):\n    return getattr(source, "levels", None)\n',
    'def f(source):\n    return getattr(inner_source(source), "w_units", "")\n',
    'def f(source):\n    return hasattr(source, "sample")\n',
])
def test_the_protocol_check_sees_a_probe(body):
    assert len(optional_member_probes("view/x.py", body)) == 1


def test_the_protocol_check_lets_plain_reads_and_other_objects_be():
    body = ('def f(source, da):\n    return source.levels, getattr(da, "encoding", None), '
            'getattr(source, "levels")\n')
    assert optional_member_probes("view/x.py", body) == []
