"""One thread or two for the compiled star level, with levels back to back and further apart.

The compiled level (``_starcut.c``) can give a level's crossing sections to two threads.  Whether
that pays depends on whether the second processor is awake: levels of a batch (a stack, a
benchmark) come back to back; a held key's steps come tens of milliseconds apart, and a virtual
machine's idle processor may take longer to wake than the half it would fill.  This times
`_cstar.cut` of one polychoron at ``--steps`` random orientations (benchmarks/star_load.py's,
c0 = 0.1), each level after a pause of each ``--gaps`` (ms; the pause is not timed), three ways in
turn: one thread; two threads whatever the gap (``batch_gap`` infinite); and the package's rule
(two only within `_cstar.BATCH_GAP` of the last level).  Medians of ``--rounds`` rounds, ms per level.

    python benchmarks/star_threads.py [--name "great icosahedral 120-cell"] [--gaps 0,1,5,30] [--rounds 6]
"""

from __future__ import annotations

import argparse
import os
import pathlib
import statistics
import sys
import time

from rot4d_widget import polytope
from rot4d_widget.geometry import _cstar, starslice
from rot4d_widget.geometry.slicetables import tables

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from star_load import rotations  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--name", default="great icosahedral 120-cell")
    ap.add_argument("--gaps", default="0,1,5,30")
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--rounds", type=int, default=6)
    args = ap.parse_args()
    if not _cstar.available:
        raise SystemExit("the compiled level is not built here (no C compiler at install)")
    p = polytope(args.name)
    t = tables(p)
    st = starslice.star_tables(p, t)
    mats = rotations(args.steps)
    xs = [t.vertices @ m.T for m in mats]
    ways = {"one thread": (1, None), "two, any gap": (2, float("inf")), f"rule ({1e3 * _cstar.BATCH_GAP:g} ms)": (2, None)}
    print(f"{args.name}: _cstar.cut, ms per level (medians of {args.rounds} rounds of {args.steps}); "
          f"levels that took two threads in brackets; {os.cpu_count()} processors")
    print("| gap (ms) | " + " | ".join(ways) + " |")
    print("|---:|" + "---:|" * len(ways))
    for gap in (float(g) for g in args.gaps.split(",")):
        times = {w: [] for w in ways}
        two = {w: 0 for w in ways}
        for _ in range(args.rounds):
            for w, (threads, batch_gap) in ways.items():
                for x, m in zip(xs, mats):
                    if gap:
                        time.sleep(gap / 1e3)
                    a = time.perf_counter()
                    _cstar.cut(st.c, x, m, 0.1, t.tol, threads=threads, batch_gap=batch_gap)
                    times[w].append(time.perf_counter() - a)
                    two[w] += st.c.threads_used == 2
        n = args.rounds * args.steps
        print(f"| {gap:g} | " + " | ".join(f"{1e3 * statistics.median(times[w]):.3f} ({two[w]}/{n})" for w in ways) + " |")


if __name__ == "__main__":
    main()
