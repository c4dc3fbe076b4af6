"""4-D scalar fields as sources: the `Field4D` and the units it is made of, one module each.

* `container` -- `Field4D` (a field's data, frame and settings) and `slice_field`;
* `inputs` -- how values come in: arrays checked, xarray DataArrays mapped to x, y, z, w, files opened;
* `checks` -- what a field checks (numbers, levels, resolutions, extent, axes) and its warnings;
* `slicing` -- the geometry of one step: the cut of the data's box and the samples on the slice;
* `kernels` -- the resampling kernels, compiled by numba;
* `surface` -- the isosurfaces of one slice (marching cubes) and `FieldSlice` / `FieldSliceData`;
* `grid` -- the cut on a regular 3-D grid (`sample_field`, `FieldGrid`) for ray-cast pictures;
* `levels` -- the iso levels and the side and caps of the surfaces (`FieldLevels`);
* `stats` -- the data range and what a field knows of its values (`FieldStatistics`);
* `memory` -- what is in memory and the background read that puts it there (`FieldMemory`);
* `chunks` -- chunked and lazy arrays read chunk by chunk; `coarse` -- the coarse copy;
* `readout` -- what a field says about itself: readout rows, axis order, its description.

Before issue 38 these were `sources.fields` and the flat `sources.field_*`, `sources.chunks` and
`sources.coarse` modules. `sources.field_labels` stays beside the protocol, which uses it for
every source's coordinates (inside this package it would make the field and the protocol import
each other). Import each name from the module that defines it; this package re-exports nothing.
"""
