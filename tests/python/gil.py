"""A check the binding tests share: whether a call releases the GIL while it works."""

import threading
import time


def ticks_during(call):
    """Runs call() while another Python thread counts; returns (seconds the call took, ticks the
    other thread made meanwhile). A call that keeps the GIL lets the other thread make none."""
    ticks = 0
    stop = False

    def count():
        nonlocal ticks
        while not stop:
            ticks += 1
            time.sleep(0.0005)

    t = threading.Thread(target=count)
    t.start()
    try:
        time.sleep(0.05)
        before = ticks
        start = time.perf_counter()
        call()
        elapsed = time.perf_counter() - start
        during = ticks - before
    finally:
        stop = True
        t.join()
    return elapsed, during
