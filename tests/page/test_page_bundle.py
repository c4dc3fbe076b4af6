"""The page's modules (rot4d_widget/view/page/*.js) and the one module they are joined into.

anywidget loads one ES module; the page's code is ES modules of one job each, which Node runs as
they are and `rot4d_widget.view.bundle` joins.  Checked here: the joiner reads the subset of the
syntax it promises and refuses the rest, naming file and line; the joined module parses and loads
in Node with the entry's exports; every module is used.
"""

from __future__ import annotations

import shutil
import subprocess

import pytest

from rot4d_widget.view import bundle
from test_companion import JS, _apt_install_node


def test_every_page_module_is_joined_and_the_entry_keeps_its_exports():
    mods = bundle.modules()
    assert bundle.ENTRY in mods and len(mods) > 1
    text = bundle.page_module()
    for name in mods:
        assert f"// ---- {name}" in text
    assert "export default { render };" in text
    assert text.count("export ") == text.count("export ", text.index(f"// ---- {bundle.ENTRY}"))  # only the entry's


@pytest.mark.parametrize("line, message", [
    ('import x from "./models.js";', "an import must read"),
    ('import { a } from "../elsewhere.js";', "an import must read"),
    ('import * as m from "./models.js";', "an import must read"),
    ("export default 3;", "only companion.js has an `export default`"),
    ("export * from './models.js';", "an export must be"),
    ("export var x = 1;", "an export must be"),
])
def test_the_joiner_refuses_what_it_cannot_join(line, message):
    with pytest.raises(bundle.BundleError, match=message):
        bundle._parse("some.js", line)


def test_imports_are_checked_against_the_exports():
    found = {"companion.js": ({"models.js": [("nope", "nope")]}, [], []), "models.js": ({}, ["modelId"], [])}
    with pytest.raises(bundle.BundleError, match="imports nope from ./models.js, which does not export it"):
        bundle._checked(found)
    with pytest.raises(bundle.BundleError, match="imports ./gone.js, which is not a page module"):
        bundle._checked({"companion.js": ({"gone.js": [("a", "a")]}, [], [])})


def test_an_import_cycle_and_an_unused_module_are_refused():
    cyc = {"companion.js": ({"a.js": []}, [], []), "a.js": ({"companion.js": []}, [], [])}
    with pytest.raises(bundle.BundleError, match="import cycle: companion.js -> a.js -> companion.js"):
        bundle._order(cyc)
    lone = {"companion.js": ({}, [], []), "a.js": ({}, [], [])}
    with pytest.raises(bundle.BundleError, match="a.js not imported"):
        bundle._order(lone)


def test_the_joined_module_parses_and_loads_in_node():
    node = shutil.which("node") or shutil.which("nodejs") or _apt_install_node()
    if node is None:
        pytest.skip("Node.js is not installed (apt-get install nodejs)")
    assert subprocess.run([node, "--check", str(JS)], capture_output=True, text=True).returncode == 0
    code = f"import({str(JS)!r}).then(m => console.log(typeof m.default.render, Object.keys(m).sort().join(',')))"
    out = subprocess.run([node, "--input-type=module", "-e", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split()[0] == "function"
