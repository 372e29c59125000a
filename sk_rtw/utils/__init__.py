"""Input validation and conversion."""

from ._convert import from_aeon, from_tslearn, to_aeon
from ._validation import (
    DEFAULT_ATOL,
    SeriesCollection,
    check_series,
    check_series_collection,
)

__all__ = [
    "DEFAULT_ATOL",
    "SeriesCollection",
    "check_series",
    "check_series_collection",
    "from_aeon",
    "from_tslearn",
    "to_aeon",
]
