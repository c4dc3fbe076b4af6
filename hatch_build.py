"""Build hook: compile the general slicer's C level (rot4d_widget/geometry/_starcut.c) into the wheel.

A plain C shared library, no Python API (loaded with ctypes by rot4d_widget.geometry._cstar), so
one build serves every Python 3: the wheel is tagged py3-none-<platform>.  Where no C compiler
works, the build goes on without it (a pure wheel) and the package slices star polytopes with its
numpy slicer: the same slices, slower (docs/meshes.md has both speeds).  An editable install
compiles it beside the source, where the package finds it.
"""

from __future__ import annotations

import hashlib
import os
import shlex
import subprocess
import sys
import sysconfig
from pathlib import Path

from hatchling.builders.hooks.plugin.interface import BuildHookInterface

SOURCE = "rot4d_widget/geometry/_starcut.c"
LIBRARY = "rot4d_widget/geometry/_starcut.so"


def _compilers():
    seen = []
    for cmd in (os.environ.get("CC"), sysconfig.get_config_var("CC"), "cc", "gcc", "clang"):
        if cmd and shlex.split(cmd) not in seen:
            seen.append(shlex.split(cmd))
    return seen


class CompiledLevel(BuildHookInterface):
    PLUGIN_NAME = "custom"

    def initialize(self, version: str, build_data: dict) -> None:
        if self.target_name != "wheel" or os.environ.get("ROT4D_NO_C"):
            return
        src, out = Path(self.root) / SOURCE, Path(self.root) / LIBRARY
        sha = hashlib.sha256(src.read_bytes()).hexdigest()  # the library names its source: a stale one is not used
        tried = []
        for cc in _compilers():  # $CC, Python's own, then the usual names (a conda Python's may be absent)
            # no fused multiply-adds: the points are numpy's to the bit on every platform
            cmd = [*cc, "-O3", "-ffp-contract=off", "-shared", "-fPIC", "-pthread", f'-DSTARCUT_SOURCE="{sha}"', "-o",
                   str(out), str(src), "-lm"]
            try:
                subprocess.run(cmd, check=True, capture_output=True, text=True, timeout=300)
                break
            except (OSError, subprocess.SubprocessError) as err:
                detail = getattr(err, "stderr", "") or str(err)
                tried.append(f"{' '.join(cc)}: {detail.strip()[:300]}")
        else:
            print("rot4d_widget: no compiled star slicer (" + "; ".join(tried) + "); the numpy slicer does every level",
                  file=sys.stderr)
            return
        if version != "editable":
            build_data["force_include"][str(out)] = LIBRARY
        build_data["pure_python"] = False
        build_data["tag"] = "py3-none-" + sysconfig.get_platform().replace("-", "_").replace(".", "_")
