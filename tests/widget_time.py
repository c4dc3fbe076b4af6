"""`service(w, now)`: what a widget's ticker thread does once (its update pump's ``service``).

The one place the widget tests reach into a widget for time (with a fake clock
and ``_autotick=False``).
"""


def service(w, now=None):
    """Run the widget's due ticks and flow control once; returns when it wants to run next."""
    return w._pump.service(now)


def sent(w, timeout=60.0):
    """Wait (real time) until a ticking widget's latest state has left: not dirty, no send being
    computed.  A widget with its own ticker thread computes a send's slice outside the lock, so
    one ``service`` call may find that send under way and return before the buffers change."""
    import time

    end = time.monotonic() + timeout
    while True:
        service(w, w._pump.clock() + 1.0)  # no view: past the acknowledgement timeout
        with w._pump.lock:
            if not w._pump.dirty and not w._pump._sending:
                return
        if time.monotonic() > end:
            raise AssertionError(f"the widget's update did not leave within {timeout} s")
        time.sleep(0.01)
