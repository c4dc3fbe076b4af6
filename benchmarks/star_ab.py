"""Two builds of the compiled star level against each other, in one process, interleaved.

For a change to ``rot4d_widget/geometry/_starcut.c`` whose effect is a few percent (less than this
machine's drift between runs): builds the file as it is at ``--rev`` (default HEAD) or in
``--base-file``, and as it is in the working tree (or ``--flags`` against ``--base-flags`` for one
source), each into a temporary folder with the package's flags (hatch_build.py's, unless given),
loads both, and cuts one polychoron at ``--steps`` random orientations (benchmarks/star_load.py's,
c0 = 0.1) with each in turn, ``--rounds`` times; prints each one's median ms per level and their
ratio. Only the C call and its copy-out are timed (`_cstar.cut`), not `slice_polytope`'s Python
around it. Both builds must have the interface the working tree's `_cstar.py` loads. Two builds of
one source differ by a few percent from run to run on this machine (the noise to beat).

    python benchmarks/star_ab.py [--rev HEAD] [--name "great icosahedral 120-cell"] [--rounds 40]
    python benchmarks/star_ab.py --base-flags "-O2" --flags "-O3"       # the working tree's, two ways
    python benchmarks/star_ab.py --base-file /tmp/_starcut.c               # a saved copy against the working tree
"""

from __future__ import annotations

import argparse
import hashlib
import pathlib
import shlex
import statistics
import subprocess
import sys
import sysconfig
import tempfile
import time

from rot4d_widget import polytope
from rot4d_widget.geometry import _cstar, starslice
from rot4d_widget.geometry.slicetables import tables

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from star_load import rotations  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]
SOURCE = "rot4d_widget/geometry/_starcut.c"
FLAGS = "-O3 -ffp-contract=off -pthread"  # hatch_build.py's (besides -shared -fPIC)


def build(source: bytes, folder: pathlib.Path, flags: str):
    """``source`` compiled with ``flags`` into ``folder``, loaded (None if it does not load)."""
    folder.mkdir()
    (folder / "_starcut.c").write_bytes(source)
    sha = hashlib.sha256(source).hexdigest()
    cc = shlex.split(sysconfig.get_config_var("CC") or "cc")
    subprocess.run([*cc, *shlex.split(flags), "-shared", "-fPIC", f'-DSTARCUT_SOURCE="{sha}"', "-o",
                    str(folder / _cstar.LIBRARY), str(folder / "_starcut.c"), "-lm"], check=True)
    return _cstar._load(folder)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rev", default="HEAD", help="the git revision of the first build's source")
    ap.add_argument("--base-file", default=None, help="the first build's source: this file instead of --rev's")
    ap.add_argument("--base-flags", default=None, help="compile the working tree's source twice: these flags first")
    ap.add_argument("--flags", default=FLAGS)
    ap.add_argument("--name", default="great icosahedral 120-cell")
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--rounds", type=int, default=40)
    args = ap.parse_args()
    work = (ROOT / SOURCE).read_bytes()
    if args.base_file is not None:
        base = pathlib.Path(args.base_file).read_bytes()
        sides = [(args.base_file, base, args.flags), ("working tree", work, args.flags)]
    elif args.base_flags is None:
        old = subprocess.run(["git", "-C", str(ROOT), "show", f"{args.rev}:{SOURCE}"], check=True,
                             capture_output=True).stdout
        sides = [(f"{args.rev}", old, args.flags), ("working tree", work, args.flags)]
    else:
        sides = [(args.base_flags, work, args.base_flags), (args.flags, work, args.flags)]
    p = polytope(args.name)
    t = tables(p)
    st = starslice.star_tables(p, t)
    mats = rotations(args.steps)
    xs = [t.vertices @ m.T for m in mats]
    loaded = []
    with tempfile.TemporaryDirectory() as tmp:
        for i, (label, src, flags) in enumerate(sides):
            lib = build(src, pathlib.Path(tmp) / str(i), flags)
            if lib is None:
                raise SystemExit(f"{label}: the build does not load")
            keep, _cstar._lib = _cstar._lib, lib
            try:
                ct = _cstar.CTables(p, t, st)  # its own pool (the two builds' pools may differ)
                _cstar.cut(ct, xs[0], mats[0], 0.1, t.tol)  # warm
            finally:
                _cstar._lib = keep
            loaded.append((label, lib, ct))
        times: dict = {label: [] for label, _, _ in loaded}
        for _ in range(args.rounds):
            for label, lib, ct in loaded:
                keep, _cstar._lib = _cstar._lib, lib
                try:
                    a = time.perf_counter()
                    for x, m in zip(xs, mats):
                        _cstar.cut(ct, x, m, 0.1, t.tol)
                    times[label].append((time.perf_counter() - a) / len(mats))
                finally:
                    _cstar._lib = keep
    print(f"{args.name}: ms per level (the C call and copy-out), medians of {args.rounds} interleaved rounds "
          f"of {args.steps} orientations, up to {_cstar.THREADS} thread(s)")
    med = {label: statistics.median(v) for label, v in times.items()}
    for label, v in med.items():
        print(f"| {label} | {1e3 * v:.3f} |")
    first, second = (label for label, _, _ in loaded)
    print(f"ratio (second / first): {med[second] / med[first]:.3f}")


if __name__ == "__main__":
    main()
