"""Run the page's modules under Node from a test: `run_page(script, data)`.

``script`` is the body of an ES module that may ``import { ... } from "page:state.js"`` (any page
module by name, resolved to rot4d_widget/view/page/) and reads its input as ``INPUT`` (``data``
as JSON on stdin); it prints one JSON line last, which `run_page` returns.  Without Node (and no
way to install it) the test is skipped.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import tempfile
from pathlib import Path

import pytest

from rot4d_widget.view.bundle import PAGE_DIR
from test_companion import _apt_install_node

_PAGE_IMPORT = re.compile(r'from\s+"page:([A-Za-z0-9_]+\.js)"')


def node_binary() -> str:
    node = shutil.which("node") or shutil.which("nodejs") or _apt_install_node()
    if node is None:
        pytest.skip("Node.js is not installed (apt-get install nodejs): the page's modules not run")
    return node


def run_page(script: str, data=None, timeout: float = 300.0):
    node = node_binary()
    body = _PAGE_IMPORT.sub(lambda m: f'from "{(PAGE_DIR / m.group(1)).as_uri()}"', script)
    head = ('import { readFileSync } from "node:fs";\n'
            'const INPUT = JSON.parse(readFileSync(0, "utf-8") || "null");\n')
    imports = "\n".join(line for line in body.splitlines() if line.startswith("import "))
    rest = "\n".join(line for line in body.splitlines() if not line.startswith("import "))
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "run.mjs"
        path.write_text(imports + "\n" + head + rest)
        proc = subprocess.run([node, str(path)], input=json.dumps(data), capture_output=True, text=True,
                              timeout=timeout)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])
