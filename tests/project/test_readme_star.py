"""The README's "Star polychora, any polytope, and the whole object beside its slice" block runs as
written: the great grand stellated 120-cell with its projection, and another viewer's 4OFF file
(the great grand 120-cell written with 3 digits, tests/data/off_library/polytopeviewer) read with
the looser tolerance the README gives."""

from __future__ import annotations

import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parents[2]
OFF = ROOT / "tests" / "data" / "off_library" / "polytopeviewer" / "Gaghi.off"


def _block() -> str:
    readme = (ROOT / "README.md").read_text()
    section = readme.split("## Star polychora, any polytope", 1)[1]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def test_the_readme_star_block_runs(monkeypatch):
    code = _block()
    assert 'Polytope.from_off("Gaghi.off", tolerance=1e-4)' in code
    monkeypatch.chdir(OFF.parent)
    ns: dict = {}
    exec(compile(code, "README.md", "exec"), ns)
    w, p = ns["w"], ns["p"]
    try:
        assert w.projection is True and w.source.polytope.counts == (600, 1200, 720, 120)
        assert "self-intersecting" in w.readout.value
        assert p.counts == (120, 1200, 720, 120) and not p.convex and p.self_intersecting  # {5,5/2,3}
    finally:
        w.close()
