"""The geometry wing of rot4d_widget (see docs/design.md): 4-polytopes and their slices.

==================================  ============================================================
`rot4d_widget.geometry.mesh`        `Polytope` (vertices and combinatorics, from a hull or a
                                    mesh given whole), `Incidence`, `COORDINATE_RANGE`,
                                    `check_scale`, `order_cycle`, `MESH_TOLERANCE`
`rot4d_widget.geometry.meshcheck`   `MeshError` and the checks of a mesh (planar convex faces,
                                    closed convex cells, orientation)
`rot4d_widget.geometry.regular`     the six regular polychora (`pentachoron`, `POLYTOPE_NAMES`,
                                    their aliases and Schläfli symbols, `PHI`)
`rot4d_widget.geometry.catalogue`   `polytope(name)`: the regular six, the ten regular star
                                    ones (`rot4d_widget.geometry.star_regular`) and every
                                    uniform polychoron (`rot4d_widget.geometry.uniform`) by name
`rot4d_widget.geometry.slicing`     the w = c0 cut: `polytope_slice` (`slice_polytope`, the
                                    entry), `single_level`, `many_levels`, `tables` (`Slice`),
                                    `star`, `even_odd_fill`
==================================  ============================================================

`Polytope`, `MeshError`, `pentachoron`, `polytope` and `slice_polytope` are importable from
`rot4d_widget` itself.
"""
