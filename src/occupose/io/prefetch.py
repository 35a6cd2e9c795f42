"""Reading ahead: the items of an iterable made on a thread of their own (frames read and
decoded while the tracker works on the ones before).

::

    with Prefetch(recording.frames(), size=4) as frames:
        for frame in frames:
            ...

A bounded queue keeps at most ``size`` items waiting. An exception the iterable raises
is raised again, the same exception object with its message and traceback, in the thread
that takes the items, at the place where that item would have come. Leaving the ``with``
block (at the end, on an error, or on Ctrl-C) stops the reader and waits for it: it stops
after the item it is reading.
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Iterable, Iterator

#: Items read ahead by default: a few frames cover the jitter of PNG decoding.
SIZE = 4
_END = object()  # the reader's last item
_POLL_S = 0.05  # how often a reader waiting for room checks whether it should stop


class Prefetch:
    """Iterate ``items`` on a reader thread, ``size`` (>= 1) items ahead; see the module
    docstring. Iterate it once, inside ``with`` (or call :meth:`close` when done)."""

    def __init__(self, items: Iterable, size: int = SIZE):
        if not (isinstance(size, int) and size >= 1):
            raise ValueError(f"size must be an int >= 1 (items read ahead), got {size!r}")
        self._items = items
        self._queue: queue.Queue = queue.Queue(maxsize=size)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._read, name="occupose-reader", daemon=True)
        self._thread.start()

    def _put(self, item) -> bool:
        """Queue ``item``, waiting for room; False when told to stop meanwhile."""
        while not self._stop.is_set():
            try:
                self._queue.put(item, timeout=_POLL_S)
                return True
            except queue.Full:
                continue
        return False

    def _read(self) -> None:
        try:
            for item in self._items:
                if not self._put((item, None)):
                    return
        except BaseException as error:  # raised again where the items are taken
            self._put((None, error))
            return
        self._put((_END, None))

    def __iter__(self) -> Iterator:
        while True:
            item, error = self._queue.get()
            if error is not None:
                raise error
            if item is _END:
                return
            yield item

    def close(self) -> None:
        """Stop the reader after the item it is reading, and wait for it."""
        self._stop.set()
        self._thread.join()

    def __enter__(self) -> Prefetch:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
