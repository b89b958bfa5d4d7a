"""The cyclic garbage collector paused while a block creates many objects.

Shapely's geometries are tracked by Python's cyclic garbage collector, so a call that
builds a layer's geometries (20,000 footprints, a million parcels) triggers a
collection every 700 of them, and every tenth of those a larger one: measured on
20,000 footprints, about a tenth of :func:`curvesmith.geo.smooth`. None of these objects
is part of a reference cycle, so the collector finds nothing; pausing it for the build
and resuming it after (when it was running) leaves one collection, at the next
allocation, instead of dozens.
"""

from __future__ import annotations

import gc
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def paused_gc() -> Iterator[None]:
    """Pause the cyclic garbage collector inside the block, if it is running.

    It is resumed on leaving the block, also on an exception. A collector that was off
    stays off. (The switch is the interpreter's: a thread that turns the collector on
    or off meanwhile finds it as this block leaves it.)

    Examples
    --------
    >>> import gc
    >>> with paused_gc():
    ...     gc.isenabled()
    False
    >>> gc.isenabled()
    True
    """
    running = gc.isenabled()
    if running:
        gc.disable()
    try:
        yield
    finally:
        if running:
            gc.enable()
