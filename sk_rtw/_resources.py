"""Machine resources: memory available now."""

from __future__ import annotations

import os


def available_memory() -> int:
    """Physical memory currently available, in bytes (8 GiB where it cannot be read)."""
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):  # pragma: no cover - non-POSIX
        return 8 * 2**30


def format_bytes(n_bytes: float) -> str:
    """``n_bytes`` in GiB (or MiB below one GiB), for messages."""
    if n_bytes >= 2**30:
        return f"{n_bytes / 2**30:.3g} GiB"
    return f"{n_bytes / 2**20:.3g} MiB"
