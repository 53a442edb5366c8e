"""How much slower renders run now than the calibration measured them: the machine's load.

The cost model is fitted once, at start-up (``workers.calibration``). Load that arrives
later (another process on the same cores) slows every render alike, and predictions
from the calibration then admit work that misses its deadline: a review measured a
render predicted at 9.9 s (the deadline 10 s) that took 15.2 s while a test suite ran
beside the server. So each finished render's time over the model's estimate of it moves
an average, and predictions are scaled by that average where it is above 1; never below
the calibration's, so an idle machine's predictions are what they were. A render moves
the average in proportion to its estimated time, up to ``WINDOW_S``: the many small
renders, whose fixed costs the model fits least well, do not outweigh the long ones
that meet the deadline or miss it.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field

WEIGHT = 0.25  # a render of WINDOW_S or more moves the average a quarter of the way
WINDOW_S = 1.0
MAX_PACE = 8.0  # one render stalled by a stop (SIGSTOP, a swap storm) counts as this at most


@dataclass
class Pace:
    value: float = 1.0
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False)

    def observe(self, estimate_s: float, seconds: float) -> None:
        """A render the model estimated at ``estimate_s`` (no safety factor) took ``seconds``."""
        if not estimate_s > 0.0 or not seconds >= 0.0:
            return
        ratio = min(seconds / estimate_s, MAX_PACE)
        weight = WEIGHT * min(1.0, estimate_s / WINDOW_S)
        with self._lock:
            self.value += weight * (ratio - self.value)

    def factor(self) -> float:
        """What predictions are multiplied by: the average, where it is above 1."""
        with self._lock:
            return max(1.0, self.value)
