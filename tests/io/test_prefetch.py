"""The reader thread: items in order, the reader's errors raised where they would have come,
and a reader that stops when the items are no longer taken."""

import threading
import time

import pytest

from occupose.io.prefetch import Prefetch


def test_items_come_in_order_and_all_of_them():
    with Prefetch(iter(range(100)), size=3) as items:
        assert list(items) == list(range(100))
    with Prefetch([]) as items:
        assert list(items) == []


def test_the_reader_stays_at_most_size_items_ahead():
    read = []

    def items():
        for i in range(50):
            read.append(i)
            yield i

    with Prefetch(items(), size=4) as prefetched:
        taken = iter(prefetched)
        assert next(taken) == 0
        for _ in range(1000):  # until the queue is full (a loaded machine may take a while)
            if prefetched._queue.full():
                break
            time.sleep(0.01)
        time.sleep(0.05)
        assert 5 <= len(read) <= 6  # 1 taken, 4 waiting, perhaps 1 more read and blocked
        assert list(taken) == list(range(1, 50))


def test_an_error_of_the_reader_is_raised_where_its_item_would_come():
    def items():
        yield 0
        yield 1
        raise FileNotFoundError("frame 2: cam0/depth/000002.png is missing")

    taken = []
    with Prefetch(items()) as prefetched:
        with pytest.raises(FileNotFoundError, match="frame 2: cam0/depth/000002.png is missing"):
            for item in prefetched:
                taken.append(item)
    assert taken == [0, 1]


def test_leaving_early_stops_the_reader():
    def endless():
        i = 0
        while True:
            yield i
            i += 1

    before = threading.active_count()
    with pytest.raises(KeyboardInterrupt):
        with Prefetch(endless(), size=2) as prefetched:
            for item in prefetched:
                if item == 5:
                    raise KeyboardInterrupt  # as Ctrl-C in the loop
    assert threading.active_count() == before
    assert not prefetched._thread.is_alive()


def test_bad_size():
    with pytest.raises(ValueError, match="size must be an int >= 1"):
        Prefetch([], size=0)
