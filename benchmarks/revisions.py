"""Run a benchmark's measurement on the code of a git revision beside the working tree, in one run.

    with Revisions(["HEAD~3", None]) as revs:      # None: the working tree
        for rev in revs:
            env = rev.env(NUMBA_CACHE_DIR=...)        # PYTHONPATH puts that revision's package first
            subprocess.run([sys.executable, "-c", CHILD], env=env, ...)

A revision is a clean ``git archive`` of ``rot4d_widget/`` (nothing uncommitted, no build
products: the compiled star slicer is absent there, which no field benchmark uses) in a temporary
folder, first on the child's ``PYTHONPATH``; the working tree is the checkout this file lives in.
Each child reports which package it imported (`Revision.check`), so a row never says "before"
over the working tree's code.  The same pattern as ``benchmarks/browser_latency.py --rev``.
"""

from __future__ import annotations

import os
import pathlib
import subprocess
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]


def _git(*args) -> str:
    return subprocess.run(["git", "-C", str(ROOT), *args], check=True, capture_output=True, text=True).stdout.strip()


class Revision:
    """One version of the package: ``label`` ("b6e1f2a" or "working tree at b6e1f2a (+ changes)"),
    ``path`` (the folder holding its ``rot4d_widget``)."""

    def __init__(self, label: str, path: pathlib.Path):
        self.label = label
        self.path = path

    def env(self, **extra) -> dict:
        """The environment of a child that imports this revision's package."""
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join([str(self.path)] + [p for p in env.get("PYTHONPATH", "").split(os.pathsep)
                                                                 if p])
        env.update({k: str(v) for k, v in extra.items()})
        return env

    def check(self, module_file: str) -> None:
        """ValueError unless ``module_file`` (a child's ``rot4d_widget.__file__``) is this revision's."""
        want = (self.path / "rot4d_widget" / "__init__.py").resolve()
        if pathlib.Path(module_file).resolve() != want:
            raise ValueError(f"{self.label}: the child imported {module_file}, not {want}")


class Revisions:
    """The revisions to compare (a git revision, or None for the working tree), each exported once."""

    def __init__(self, revs):
        self._revs = list(revs)
        self._tmp = None
        self.items: list[Revision] = []

    def __enter__(self) -> list:
        self._tmp = tempfile.TemporaryDirectory(prefix="rot4d-revs-")
        for i, rev in enumerate(self._revs):
            if rev is None:
                sha = _git("rev-parse", "--short", "HEAD")
                dirty = _git("status", "--porcelain", "--", "rot4d_widget")
                self.items.append(Revision(f"working tree at {sha}" + (" + changes" if dirty else ""), ROOT))
                continue
            dest = pathlib.Path(self._tmp.name) / f"rev{i}"
            dest.mkdir()
            archive = subprocess.run(["git", "-C", str(ROOT), "archive", rev, "rot4d_widget"], check=True,
                                     capture_output=True).stdout
            subprocess.run(["tar", "-x", "-C", str(dest)], input=archive, check=True)
            self.items.append(Revision(_git("rev-parse", "--short", rev), dest))
        return self.items

    def __exit__(self, *exc) -> None:
        self._tmp.cleanup()
