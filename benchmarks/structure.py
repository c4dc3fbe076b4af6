"""How the package's units reach into each other, counted from the source (nothing imported).

    python benchmarks/structure.py [--root DIR] [--list]

Counted over every module of ``rot4d_widget`` (``--root``: another checkout's package folder):

* private imports -- ``from .x import _name`` / ``import ... as _x`` of a name that starts with
  one underscore, across modules (a module reaching into another's private part);
* reach-throughs -- ``obj._attr`` where ``obj`` is neither ``self`` nor ``cls`` (a unit reading or
  writing another object's private state; ``super()._x`` and dunder names are left out);
* getattr probes -- ``getattr(obj, "name", default)`` with a literal name: asking an object
  whether it has an optional member instead of a contract that says so;
* modules, and lines of the largest module and class.

``--list`` prints every finding with its file and line.
"""

from __future__ import annotations

import argparse
import ast
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1] / "rot4d_widget"


def _private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def scan(root: pathlib.Path) -> dict:
    found = {"private imports": [], "reach-throughs": [], "getattr probes": []}
    modules, biggest_module, biggest_class = 0, (0, ""), (0, "")
    for path in sorted(root.rglob("*.py")):
        rel = path.relative_to(root.parent).as_posix()
        text = path.read_text(encoding="utf-8")
        tree = ast.parse(text)
        modules += 1
        n = len(text.splitlines())
        biggest_module = max(biggest_module, (n, rel))
        for node in ast.walk(tree):
            where = f"{rel}:{getattr(node, 'lineno', 0)}"
            if isinstance(node, ast.ClassDef):
                size = node.end_lineno - node.lineno + 1
                biggest_class = max(biggest_class, (size, f"{rel}:{node.name}"))
            elif isinstance(node, ast.ImportFrom) and (node.level or (node.module or "").startswith("rot4d_widget")):
                for a in node.names:
                    if _private(a.name):
                        found["private imports"].append(f"{where}: {a.name} from {'.' * node.level}{node.module or ''}")
            elif isinstance(node, ast.Attribute) and _private(node.attr):
                base = node.value
                if isinstance(base, ast.Name) and base.id in ("self", "cls"):
                    continue
                if isinstance(base, ast.Call) and isinstance(base.func, ast.Name) and base.func.id == "super":
                    continue
                found["reach-throughs"].append(f"{where}: {ast.unparse(node)}")
            elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "getattr"
                  and len(node.args) == 3 and isinstance(node.args[1], ast.Constant)):
                found["getattr probes"].append(f"{where}: {ast.unparse(node)}")
    return {"found": found, "modules": modules, "biggest module": biggest_module, "biggest class": biggest_class}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--root", default=str(ROOT), help="the package folder to scan (default: this checkout's)")
    ap.add_argument("--list", action="store_true", help="print every finding")
    args = ap.parse_args(argv)
    r = scan(pathlib.Path(args.root))
    print(f"{'modules':<18} {r['modules']:>6}")
    for name, items in r["found"].items():
        print(f"{name:<18} {len(items):>6}")
    print(f"{'largest module':<18} {r['biggest module'][0]:>6}  {r['biggest module'][1]}")
    print(f"{'largest class':<18} {r['biggest class'][0]:>6}  {r['biggest class'][1]}")
    if args.list:
        for name, items in r["found"].items():
            print(f"\n{name}:")
            for item in items:
                print("  " + item)
    return 0


if __name__ == "__main__":
    sys.exit(main())
