"""The one check of a number read from a file (a model, a machine's
controller): a real number, not a bool, finite, and > 0 when it must be."""
import math


def finite(v, positive=False):
    """True when v is an int or float (not a bool), finite, and > 0 if positive."""
    return (not isinstance(v, bool) and isinstance(v, (int, float)) and math.isfinite(v)
            and (not positive or v > 0))
