"""A module-level field function that the state files in tests/fixtures name ("saved_fields:ball")."""


def ball(x, y, z, w):
    """A ball whose radius shrinks along w: 4 - |x|^2 - w/2."""
    return 4.0 - (x * x + y * y + z * z) - 0.5 * w
