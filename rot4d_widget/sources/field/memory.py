"""What of a `Field4D` is in memory, and the background read that puts it there.

A chunked or lazy array is read chunk by chunk, once: into the coarse copy (`FieldMemory.coarse`,
for held keys and the data range) and, when it fits the field's `memory_budget`, whole
(`FieldMemory.resident`: steps then run on it as on data given in memory).  `FieldMemory.prepare`
does it on a daemon thread, counted by a `rot4d_widget.core.progress.Progress`; the work itself
is `rot4d_widget.sources.field.coarse.CoarseCopy`'s.
"""

from __future__ import annotations

import math

import numpy as np

from ...core.validate import int_in_range

__all__ = ["FieldMemory"]


class FieldMemory:
    """What `Field4D` takes from here: the coarse copy, the array read whole, the memory budget, the
    background read and what it found missing (`missing`).  The field provides ``_values``,
    ``_kind``, ``_coarse_copy`` (its `rot4d_widget.sources.field.coarse.CoarseCopy`), ``_stat`` (its
    `rot4d_widget.sources.field.stats.FieldStatistics`) and ``_reader`` (its chunk reader, or None)."""

    @property
    def memory_budget(self) -> int:
        """Bytes a chunked or lazy array may take in memory to be read whole (settable; 0: never)."""
        return self._memory_budget

    @memory_budget.setter
    def memory_budget(self, value) -> None:
        self._memory_budget = int_in_range(value, "memory_budget", 0)

    @property
    def fits_in_memory(self) -> bool:
        """True when the values are in memory, or would take at most `memory_budget` bytes there
        (float32 kept, other types as float64): the background read then reads them whole."""
        if self.resident is not None:
            return True
        if self._kind == "function":
            return False
        itemsize = 4 if np.dtype(self._values.dtype) == np.float32 else 8
        return math.prod(int(n) for n in self._values.shape) * itemsize <= self._memory_budget

    @property
    def resident(self):
        """The values as a numpy array in memory, in the array's own axis order -- given so, or read
        whole in the background (`prepare`) -- else None (steps then read chunks)."""
        return self._values if self._kind == "numpy" else self._coarse_copy.loaded

    def drop_chunk_cache(self) -> None:
        """Forget the chunks kept from earlier steps (`chunk_cache_bytes`): once the array is read
        whole, steps no longer read chunks."""
        if self._reader is not None:
            self._reader.clear_cache()

    def coarse(self):
        """An in-memory copy with at most `COARSE_SAMPLES` nodes per axis over the same box
        (linear resampling onto evenly spaced fractional indices), built once.

        The field itself when it already is that small and in memory, or a function.  A chunked or
        lazy array is read chunk by chunk (each downsampled into the copy and dropped: memory is the
        copy plus a few chunks; one that `fits_in_memory` is kept whole as well, `resident`).  An
        array in memory is resampled in blocks of 16 samples a side: the same numbers.  Blocks until
        the copy is built: when `prepare` started it in the background, waits for that read."""
        return self._coarse_copy.get()

    @property
    def coarse_ready(self) -> bool:
        """True once the coarse copy is built (`coarse`, or the background read of `prepare`)."""
        return self._coarse_copy.ready

    @property
    def coarse_progress(self):
        """(chunks done, chunks in all) of the coarse copy's build, once it started (else None)."""
        return self._coarse_copy.progress

    @property
    def _coarse_error(self):
        """What made the background build of the coarse copy fail (None so far)."""
        return self._coarse_copy.error

    def prepare(self, progress: bool = True):
        """Start the background read on a daemon thread and return at once (the source protocol's
        ``prepare``; a live `Rot4DWidget` calls it when shown): one pass over the array, chunk by chunk,
        building the coarse copy (`coarse`) and, when the field `fits_in_memory`, reading the whole
        array into memory (`resident`; steps then run as on data given in memory).  Memory: the copy
        plus a few chunks, and the array when it is read whole.

        Returns the `rot4d_widget.core.progress.Progress` counting chunks (the one already running when
        the read was started before), or None when there is nothing to read.  ``progress``: a bar
        shown after a second -- in a kernel a widget in this cell's output, on a terminal a line;
        a `Rot4DWidget` passes False and shows the returned progress in its own bar, in the page.
        `coarse_progress` holds (chunks done, chunks in all).  Until `coarse_ready`, held keys
        slice the full data at the coarse resolution (``slice(..., coarse=True)`` says so in its
        readout) and the data range and default level come from the chunks read so far ("first
        cut"); `coarse` waits for the read."""
        return self._coarse_copy.prepare(progress)

    @property
    def missing(self):
        """Where the data are missing, for the readout: "NaN in time 0.0021 … 0.0026 s (8 of 60
        steps), 12.5 % of the samples" -- steps of w holding NaN beyond 1 % of their samples more
        than the step with fewest (a block: a failed write, a gap; `NonFiniteWarning` says it once)
        -- or None.  Counted over an array in memory at first need; a chunked or lazy one's by its
        background read (None until that read ends)."""
        self._stat.count_nonfinite()
        return self._stat.nan_text()
