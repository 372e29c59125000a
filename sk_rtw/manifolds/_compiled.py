"""The switch between the compiled maps and the torch formulas they compile.

On the CPU in float64 the sphere, quaternion and SPD(2) maps (``log``, ``exp``, ``dist``
and their gradients) and the small symmetric eigen-decompositions of SPD(3..6) run as
compiled kernels; elsewhere (other devices, other dtypes) the torch formulas run, and
those are the reference the kernels are tested against. :func:`compiled_maps` turns the
kernels off (or back on) for a block of code: to compare both paths on the same data,
or to time them (``benchmarks/manifold_maps.py``).
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

_ENABLED = [True]


def compiled_enabled() -> bool:
    """Whether the compiled maps may run (see :func:`compiled_maps`)."""
    return _ENABLED[0]


@contextmanager
def compiled_maps(enabled: bool = True) -> Iterator[None]:
    """Run the block with the compiled manifold maps on (default) or off.

    Parameters
    ----------
    enabled : bool, default=True
        False: every manifold map runs its torch formula, also on the CPU in float64 (the
        results agree to rounding; the kernels are faster).

    Notes
    -----
    The switch is global to the process, not per thread: set it around a whole
    computation, not inside threads that run others.

    Examples
    --------
    >>> import numpy as np
    >>> from sk_rtw.manifolds import Sphere, compiled_maps
    >>> p, x = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
    >>> with compiled_maps(False):
    ...     reference = Sphere(2).dist(p, x)
    >>> bool(np.isclose(reference, Sphere(2).dist(p, x)))
    True
    """
    if not isinstance(enabled, bool):
        raise TypeError(f"compiled_maps: enabled must be True or False, got {enabled!r}")
    previous = _ENABLED[0]
    _ENABLED[0] = enabled
    try:
        yield
    finally:
        _ENABLED[0] = previous
