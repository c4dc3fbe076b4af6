"""`service(w, now)`: what a widget's ticker thread does once (its update pump's ``service``).

The one place the widget tests reach into a widget for time (with a fake clock
and ``_autotick=False``).
"""


def service(w, now=None):
    """Run the widget's due ticks and flow control once; returns when it wants to run next."""
    return w._pump.service(now)
