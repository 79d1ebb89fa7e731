"""The tightenings a controller keeps, newest last, to serve by id (MID 0064 -> 0065).

A controller keeps its results whether or not an integrator is connected, so
an integrator that was away can fetch what it missed. The store is bounded:
``results_kept`` tightenings (``[rig.openprotocol]``, default 1000, each with
its curves: about 40 kB a run of 2 s, 40 MB at the default), the oldest
forgotten first; a request for a forgotten id is answered as for an id that
never was (0004, error 15 "tightening id requested not found").
"""

from __future__ import annotations

from collections import OrderedDict

from services.rig.openprotocol.tightening import Tightening


class ResultStore:
    """The newest ``capacity`` tightenings by tightening id."""

    def __init__(self, capacity: int) -> None:
        if capacity < 1:
            raise ValueError(f"capacity must be at least 1 (got {capacity})")
        self.capacity = capacity
        self._by_id: OrderedDict[int, Tightening] = OrderedDict()
        #: tightenings forgotten to keep the bound
        self.forgotten = 0

    def __len__(self) -> int:
        return len(self._by_id)

    def add(self, tightening: Tightening) -> None:
        self._by_id[tightening.tightening_id] = tightening
        self._by_id.move_to_end(tightening.tightening_id)
        while len(self._by_id) > self.capacity:
            self._by_id.popitem(last=False)
            self.forgotten += 1

    def newest(self) -> Tightening | None:
        if not self._by_id:
            return None
        return next(reversed(self._by_id.values()))

    def find(self, tightening_id: int) -> Tightening | None:
        """The tightening ``tightening_id``; 0: the newest (as MID 0064 asks); None: not kept."""
        if tightening_id == 0:
            return self.newest()
        return self._by_id.get(tightening_id)
