"""The page's JavaScript: ES modules of one job each, joined into the one module anywidget loads.

anywidget loads a single ES module and the package has no build step.  The page's code lives in
``rot4d_widget/view/page/*.js``, each file an ES module that Node runs as it is (the unit tests in
``tests/js``); `page_module` joins them into one: each module's body runs in a function scope of
its own (so names private to two modules never clash) whose exports it returns as an object, its
imports become destructurings of the modules it names, in dependency order, and the entry module
(``companion.js``) stays a module: its exports (``export default``, and names the tests import)
are the joined module's.  Joined once per process.

The files keep to a subset of the syntax, checked here (`BundleError` names the file and line):

* imports at the top, relative and named: ``import { a, b as c } from "./name.js";``
* exports on declarations -- ``export function f``, ``export async function f``,
  ``export const x``, ``export class C`` -- or ``export { a, b };``
* ``export default`` only in the entry module.
"""

from __future__ import annotations

import functools
import pathlib
import re

__all__ = ["page_module", "PAGE_DIR", "ENTRY", "BundleError", "modules"]

#: Where the page's modules are.
PAGE_DIR = pathlib.Path(__file__).with_name("page")
#: The module anywidget runs (its ``export default`` is the widget's ``render``).
ENTRY = "companion.js"

_IMPORT = re.compile(r'^import\s*\{([^}]*)\}\s*from\s*"\./([A-Za-z0-9_]+\.js)";\s*$')
_EXPORT_DECL = re.compile(r"^export\s+(?:async\s+)?(function\*?|const|let|class)\s+([A-Za-z_$][\w$]*)")
_EXPORT_LIST = re.compile(r"^export\s*\{([^}]*)\};?\s*$")
_NAME = re.compile(r"^[A-Za-z_$][\w$]*$")


class BundleError(ValueError):
    """A page module outside the subset `page_module` joins."""


def _names(text: str, where: str) -> list[tuple[str, str]]:
    """``a, b as c`` -> [("a", "a"), ("b", "c")] (exported name, local name)."""
    out = []
    for part in (p.strip() for p in text.split(",")):
        if not part:
            continue
        bits = part.split()
        if len(bits) == 1 and _NAME.match(bits[0]):
            out.append((bits[0], bits[0]))
        elif len(bits) == 3 and bits[1] == "as" and _NAME.match(bits[0]) and _NAME.match(bits[2]):
            out.append((bits[0], bits[2]))
        else:
            raise BundleError(f"{where}: cannot read the name {part!r}")
    return out


def _parse(name: str, text: str):
    """(imports {module: [(exported, local)]}, exports [names], body lines) of one module."""
    imports: dict = {}
    exports: list = []
    body = []
    for i, line in enumerate(text.splitlines(), 1):
        where = f"{name}:{i}"
        if line.startswith("import"):
            m = _IMPORT.match(line)
            if not m:
                raise BundleError(f'{where}: an import must read `import {{ a, b }} from "./module.js";`')
            imports.setdefault(m.group(2), []).extend(_names(m.group(1), where))
            continue
        if line.startswith("export default"):
            if name != ENTRY:
                raise BundleError(f"{where}: only {ENTRY} has an `export default`")
            body.append(line)
            continue
        if line.startswith("export"):
            m = _EXPORT_DECL.match(line)
            if m:  # the entry stays a module with its exports; the others return theirs
                exports.append(m.group(2))
                body.append(line if name == ENTRY else line[len("export"):].lstrip())
                continue
            m = _EXPORT_LIST.match(line)
            if m:
                exports.extend(local for _, local in _names(m.group(1), where))
                if name == ENTRY:
                    body.append(line)
                continue
            raise BundleError(f"{where}: an export must be `export function|const|let|class NAME` "
                              "or `export { ... };`")
        body.append(line)
    return imports, exports, body


@functools.lru_cache(maxsize=None)
def modules() -> dict:
    """``{file name: (imports, exports, body lines)}`` of every page module."""
    found = {p.name: _parse(p.name, p.read_text(encoding="utf-8")) for p in sorted(PAGE_DIR.glob("*.js"))}
    return _checked(found)


def _checked(found: dict) -> dict:
    """``found`` if every module's imports name a page module and what it exports, else BundleError."""
    if ENTRY not in found:
        raise BundleError(f"no {ENTRY} in {PAGE_DIR}")
    for name, (imports, _, _) in found.items():
        for target, names in imports.items():
            if target not in found:
                raise BundleError(f"{name} imports ./{target}, which is not a page module")
            missing = [e for e, _ in names if e not in found[target][1]]
            if missing:
                raise BundleError(f"{name} imports {', '.join(missing)} from ./{target}, which does not export it")
    return found


def _order(found: dict) -> list[str]:
    """The modules an entry needs, each after those it imports (a cycle is an error)."""
    out, state = [], {}

    def visit(name, path):
        if state.get(name) == "done":
            return
        if state.get(name) == "open":
            raise BundleError(f"import cycle: {' -> '.join(path + [name])}")
        state[name] = "open"
        for target in found[name][0]:
            visit(target, path + [name])
        state[name] = "done"
        out.append(name)

    visit(ENTRY, [])
    unused = sorted(set(found) - set(out))
    if unused:
        raise BundleError(f"page module(s) {', '.join(unused)} not imported by {ENTRY} or a module it imports")
    return out


def _var(name: str) -> str:
    return "__page_" + name[:-3]


@functools.lru_cache(maxsize=None)
def page_module() -> str:
    """The joined ES module (the companion's ``_esm``)."""
    found = modules()
    parts = ["// rot4d_widget's page code, joined from rot4d_widget/view/page/*.js (rot4d_widget.view.bundle)"]
    for name in _order(found):
        imports, exports, body = found[name]
        lines = [f"const {{ {', '.join(e if e == loc else f'{e}: {loc}' for e, loc in names)} }} = {_var(target)};"
                 for target, names in imports.items()]
        lines += body
        if name == ENTRY:
            parts.append(f"// ---- {name}\n" + "\n".join(lines))
        else:
            parts.append(f"// ---- {name}\nconst {_var(name)} = (() => {{\n" + "\n".join(lines)
                         + f"\nreturn {{ {', '.join(exports)} }};\n}})();")
    return "\n".join(parts) + "\n"
