"""What a recorded signal can resolve: the smallest step between two of its values.

A controller writes its torque to a fixed resolution (the CS351 runs at hand
to 0.001 Nm; other tools to 0.01 Nm). A signal whose noise is below one step
is mostly flat at that resolution: most of its second differences are 0, so
their running median, the noise floor of :mod:`.second_difference`, sinks far
under a step, and a flicker of a step or three passes as a slip. So a drop
must span more than ``RESOLUTION_STEPS`` steps as well
(:func:`~.extremum_tracker.slip_floor_nm`): three steps, as it must exceed
three median |d2| (``NOISE_FACTOR``), and half a step more, so that a drop of
exactly three steps read in floating point (0.030000000000000027) stays
under it. The resolution is the run's own (``PredictorSettings.
torque_resolution_nm``, from :func:`signal_resolution` of its torque values:
``boltwatch import``); 0 where it is not known (live, ``predict``): no floor.

Why the resolution and not the tool's nominal torque: a share of the nominal
torque that refuses a drop of 0.03 Nm on a 12 Nm tool (0.25 %) also refuses
9 of the 74 events of the ten real CS351 runs (drops of 0.012-0.015 Nm on
their 6 Nm tool, 0.2-0.25 %), each above its run's own noise floor and
12-15 steps of its 0.001 Nm resolution.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable


def signal_resolution(values: Iterable[float]) -> float:
    """The smallest step between two distinct finite ``values``; 0.0 with fewer than two.

    One value off the grid (a step of 1e-9 between two readings) makes it tiny:
    the floor it sets is then none, as without it.
    """
    distinct = sorted({value for value in values if math.isfinite(value)})
    return min((b - a for a, b in itertools.pairwise(distinct)), default=0.0)
