"""Feedback on long work, on stderr: progress bars drawn by tqdm on a terminal (a plain line
every few seconds elsewhere) and one line when numba starts compiling.

The library reports progress through a plain ``progress(done, total)`` callable and prints
nothing; :class:`Bar` is such a callable that draws a bar. Anything that takes one can be
given ``Bar("what it does", unit="what it counts")``: it draws from its first call and closes
when ``done`` reaches ``total`` (or at :meth:`Bar.close`, or when the command ends: see
:func:`close_bars`). An optional third argument, a short text, is shown after the bar.

Whether a bar is drawn is decided when it is drawn (:func:`feedback_on`): on a terminal
(stderr is a TTY) yes. Elsewhere (a CI log, a pipe) a bar that is still running after
:data:`LINE_EVERY_S` says where it is in a plain line, one every :data:`LINE_EVERY_S`, and
one more when it ends (:func:`lines_on`): a log holds them, and work of a few seconds
writes nothing but its results. The environment variable ``QUADCRUISE_PROGRESS``
overrides both: ``1`` draws the bar anywhere (the tests capture it so), ``0`` shows nothing.

Examples
--------
>>> import os
>>> os.environ["QUADCRUISE_PROGRESS"] = "0"
>>> bar = Bar("flying", unit="flight")
>>> for done in range(4):
...     bar(done, 3)                      # draws nothing: the feedback is off
>>> bar.closed
True
>>> del os.environ["QUADCRUISE_PROGRESS"]
"""

from __future__ import annotations

import contextlib
import os
import sys
import time
import weakref
from collections.abc import Iterator

from tqdm import tqdm

__all__ = ["COMPILE_LINE", "ENV", "LINE_EVERY_S", "Bar", "close_bars", "compile_notice", "feedback_on", "lines_on"]

ENV = "QUADCRUISE_PROGRESS"
"""The environment variable that turns the feedback on (``1``) or off (``0``) anywhere."""

COMPILE_LINE = "compiling the engine and controllers for this machine, once (numba caches them on disk): about 5-15 s"
"""What :func:`compile_notice` says. Measured with an empty ``NUMBA_CACHE_DIR``, less the warm
run, on two shared cores: ``fly hover`` 6-8 s, ``analyze`` 7 s, ``montecarlo`` 10 s, ``compare``
(four controllers) 11-13 s."""

LINE_EVERY_S = 10.0
"""Off a terminal: seconds between two progress lines (the first after as long)."""

_OPEN: weakref.WeakSet = weakref.WeakSet()  # the bars drawn and not closed yet


def feedback_on() -> bool:
    """Whether feedback is shown: ``QUADCRUISE_PROGRESS`` if set (``1``/``0``), else whether stderr is a terminal."""
    value = os.environ.get(ENV, "").strip().lower()
    if value in ("1", "true", "yes", "on"):
        return True
    if value in ("0", "false", "no", "off"):
        return False
    try:
        return bool(sys.stderr.isatty())
    except (AttributeError, ValueError):  # no stderr, or a closed one
        return False


def lines_on() -> bool:
    """Whether progress is said in plain lines: stderr is not a terminal and
    ``QUADCRUISE_PROGRESS`` is not set."""
    if os.environ.get(ENV, "").strip():
        return False
    try:
        return sys.stderr is not None and not sys.stderr.isatty()
    except (AttributeError, ValueError):  # a closed stderr
        return False


def _duration(seconds: float) -> str:
    """``42 s``, ``3 min 05 s``."""
    seconds = max(0, round(seconds))
    return f"{seconds} s" if seconds < 60 else f"{seconds // 60} min {seconds % 60:02d} s"


def _size() -> dict:
    """tqdm's size keywords: the terminal's, followed as it is resized; a terminal that
    reports no size (0 x 0, as a bare pseudo-terminal) gets 80 x 24, on which tqdm draws."""
    try:
        columns, lines = os.get_terminal_size(sys.stderr.fileno())
    except (AttributeError, OSError, ValueError):  # not a terminal: tqdm's defaults
        return {}
    return {"dynamic_ncols": True} if columns and lines else {"ncols": 80, "nrows": 24}


class _Tqdm(tqdm):
    """tqdm without its monitor thread (the bars here are updated often enough)."""

    monitor_interval = 0


class Bar:
    """A ``progress(done, total)`` callable that draws a bar on stderr (tqdm), when
    :func:`feedback_on`, or says it in a plain line every :data:`LINE_EVERY_S` when
    :func:`lines_on`, e.g. ``flying: 2,500 of 10,000 flights (25 %) after 40 s, about 2 min
    00 s left``.

    Examples
    --------
    >>> with Bar("drawing", unit="frame") as bar:
    ...     bar(0, 2); bar(1, 2, "t = 0.5 s")
    """

    def __init__(self, label: str, unit: str = "step") -> None:
        self.label = label
        self.unit = unit
        self._bar: tqdm | None = None
        self.closed = False
        self._lines: bool | None = None  # off a terminal: plain lines (decided at the first call)
        self._start = self._said = 0.0
        self._last: tuple[int, int] = (0, 0)
        self._note: str | None = None  # the last note (a tuner's best cost), said after the line
        self._lines_said = 0

    def _line(self, done: int, total: int, end: bool = False) -> None:
        """One plain line on stderr: where the work is, how long it has taken and (not at the end) is left."""
        now = time.monotonic()
        elapsed = now - self._start
        units = self.unit if total == 1 else self.unit + "s"
        share = f" ({100 * done / total:.0f} %)" if total > 0 else ""
        text = f"{self.label}: {done:,} of {total:,} {units}{share} "
        if end:
            text += f"in {_duration(elapsed)}"
        else:
            text += f"after {_duration(elapsed)}"
            if 0 < done < total:
                text += f", about {_duration(elapsed * (total - done) / done)} left"
        if self._note:
            text += f"; {self._note}"
        try:
            sys.stderr.write(text + "\n")
            sys.stderr.flush()
        except (AttributeError, OSError, ValueError):  # stderr gone: the work goes on
            self._lines = False
        self._said = now
        self._lines_said += 1

    def __call__(self, done: int, total: int, text: str | None = None) -> None:
        """Show ``done`` of ``total``."""
        if self.closed:
            return
        if self._lines is None:
            self._lines = lines_on()
            self._start = self._said = time.monotonic()
        if self._lines:
            self._last = (done, total)
            self._note = text if text is not None else self._note
            _OPEN.add(self)
            if done >= total:
                self.close()
            elif done > 0 and time.monotonic() - self._said >= LINE_EVERY_S:
                self._line(done, total)
            return
        if self._bar is None:
            self._bar = _Tqdm(
                total=total,
                initial=done,
                desc=self.label,
                unit=self.unit,
                file=sys.stderr,
                leave=False,
                disable=not feedback_on(),
                **_size(),
            )
            _OPEN.add(self)
        bar = self._bar
        if bar.disable:
            if done >= total:
                self.close()
            return
        bar.total = total
        if done >= total:
            self.close()
            return
        bar.update(done - bar.n)  # drawn at most every 0.1 s
        if text is not None:
            bar.set_postfix_str(text)  # drawn now

    def close(self) -> None:
        """Remove the bar (nothing happens if it is closed already); off a terminal, a last
        line if any was said, with the time it all took."""
        if self._lines and not self.closed and self._lines_said:
            done, total = self._last
            self._line(done, total, end=done >= total)
        self.closed = True
        _OPEN.discard(self)
        if self._bar is not None:
            self._bar.close()

    def __enter__(self) -> Bar:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def close_bars() -> None:
    """Close every bar still open, e.g. before an error message."""
    for bar in list(_OPEN):
        bar.close()


@contextlib.contextmanager
def compile_notice() -> Iterator[None]:
    """Within it, say :data:`COMPILE_LINE` once on stderr when numba starts compiling."""
    # numba announces each compilation that misses its cache (its numba:compile event), which is
    # exactly when the wait comes; a later run loads the machine code from disk and says nothing.
    if not feedback_on():
        yield
        return
    from numba.core import event

    said: list[bool] = []

    class Notice(event.Listener):
        def on_start(self, ev) -> None:
            if not said:
                said.append(True)
                tqdm.write(COMPILE_LINE, file=sys.stderr)  # above any bar being drawn

        def on_end(self, ev) -> None:
            pass

    listener = Notice()
    event.register("numba:compile", listener)
    try:
        yield
    finally:
        event.unregister("numba:compile", listener)
