"""Slicing a 4-polytope by the hyperplane w = c0: the one place the slicers live, one module each.

* `polytope_slice` -- `slice_polytope` (the entry: it chooses a slicer, one level or many) and
  `TOLERANCE`, with the explicit case table of what becomes what on the hyperplane;
* `single_level` -- one level, the on-H cases handled on purpose;
* `many_levels` -- many parallel levels in one pass (trimesh's ``mesh_multiplane``);
* `tables` -- the per-polytope tables, the `Slice` result and the steps both slicers share;
* `star` -- polytopes with star faces or non-convex cells, level by level;
* `even_odd_fill` -- the star slicer's fill of a section whose cycles cross.

Before issue 38 these were `geometry.slicing`, `geometry.section`, `geometry.multislice`,
`geometry.slicetables`, `geometry.starslice` and `geometry.starfill`.  This ``__init__`` holds no
code and re-exports nothing: it is imported before any of its modules, and the server extension's
check that ``import rot4d_widget`` stays free of numpy resolves nested module paths through it.
`slice_polytope` is importable from `rot4d_widget` itself.
"""
