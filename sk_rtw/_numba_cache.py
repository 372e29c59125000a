"""Cached kernels that inline another file's code: dropped when that file is newer.

numba keys a cached kernel on its own source file only (``cache=True``: the index file
``__pycache__/<module>.<function>-<line>.py3x.nbi`` records that file's stamp). The DTW
kernels inline the manifolds' compiled point geometry (another package's files); after
an edit there, numba would keep loading the old machine code. :func:`drop_stale_caches`
removes the index files of a package's cached kernels that are older than any of the
sources they inline, so the next call compiles them afresh. It reads only the package's
own ``__pycache__`` (where numba caches beside a writable source tree, as in a checkout
being edited); an installed release is never edited and keeps its caches.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterable
from pathlib import Path


def drop_stale_caches(package_dir: str | Path, sources: Iterable[str | Path]) -> int:
    """Remove the numba index files under ``package_dir/__pycache__`` that are older than
    the newest of ``sources``; returns how many were removed."""
    cache = Path(package_dir) / "__pycache__"
    if not cache.is_dir():
        return 0
    try:
        newest = max(Path(source).stat().st_mtime for source in sources)
    except (OSError, ValueError):  # a source not on disk (a zip import): nothing to do
        return 0
    removed = 0
    for index in cache.glob("*.nbi"):
        with contextlib.suppress(OSError):  # another process may have removed it
            if index.stat().st_mtime < newest:
                index.unlink()
                removed += 1
    return removed
