"""A progress line for long runs: items done, the rate and the time left, on a stream.

:class:`ProgressBar` is the ``progress(done, total)`` callback that ``quadcruise
montecarlo`` hands to :func:`quadcruise.montecarlo.montecarlo`.
"""

from __future__ import annotations

import math
import sys
import time

__all__ = ["ProgressBar"]


class ProgressBar:
    """``progress(done, total)`` that prints flights done, the rate and the time left.

    On a terminal it rewrites one line; otherwise it prints a line at most every
    ``log_interval`` seconds (and the last one). The rate counts the flights flown since
    the first call (flights resumed from disk are done but not flown).

    Parameters
    ----------
    stream : file-like, optional
        Where to write; ``sys.stderr`` by default. A stream whose ``isatty()`` is true is
        a terminal.
    label : str
        What is counted, e.g. ``"flights"``.
    min_interval : float
        Shortest time between two updates on a terminal [s].
    log_interval : float
        Shortest time between two lines elsewhere [s].

    Examples
    --------
    >>> import io
    >>> buf = io.StringIO()
    >>> bar = ProgressBar(buf)
    >>> bar(0, 10); bar(10, 10); bar.close()
    >>> buf.getvalue().splitlines()[-1].split(",")[0]
    '10/10 flights (100.0 %)'
    """

    def __init__(self, stream=None, *, label: str = "flights", min_interval: float = 0.25,
                 log_interval: float = 10.0) -> None:
        self.stream = sys.stderr if stream is None else stream
        self.label = label
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.interval = min_interval if self.tty else log_interval
        self.t0: float | None = None
        self.done0 = 0
        self.last = -math.inf
        self.width = 0

    def __call__(self, done: int, total: int) -> None:
        now = time.monotonic()
        if self.t0 is None:
            self.t0, self.done0 = now, done
        final = done >= total
        if not final and now - self.last < self.interval:
            return
        self.last = now
        elapsed = now - self.t0
        rate = (done - self.done0) / elapsed if elapsed > 0 and done > self.done0 else 0.0
        eta = "-" if not rate else _clock((total - done) / rate)
        text = (f"{done:,}/{total:,} {self.label} ({100.0 * done / max(total, 1):.1f} %), "
                f"{rate:,.0f} {self.label}/s, ETA {eta}")
        if self.tty:
            self.stream.write("\r" + text.ljust(self.width))
            self.width = len(text)
        else:
            self.stream.write(text + "\n")
        self.stream.flush()

    def close(self) -> None:
        """End the line (on a terminal)."""
        if self.tty and self.width:
            self.stream.write("\n")
            self.stream.flush()
            self.width = 0


def _clock(seconds: float) -> str:
    seconds = int(round(seconds))
    h, rest = divmod(seconds, 3600)
    return f"{h}:{rest // 60:02d}:{rest % 60:02d}" if h else f"{rest // 60}:{rest % 60:02d}"
