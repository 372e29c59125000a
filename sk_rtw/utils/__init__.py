"""Input validation and conversion."""

from ._validation import (
    DEFAULT_ATOL,
    SeriesCollection,
    check_series,
    check_series_collection,
)

__all__ = ["DEFAULT_ATOL", "SeriesCollection", "check_series", "check_series_collection"]
