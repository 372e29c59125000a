"""Input validation and conversion."""

from ._convert import from_aeon, from_tslearn, to_aeon
from ._labels import check_classes, check_labels, encode_labels
from ._validation import (
    DEFAULT_ATOL,
    SeriesCollection,
    check_series,
    check_series_collection,
)

__all__ = [
    "DEFAULT_ATOL",
    "SeriesCollection",
    "check_classes",
    "check_labels",
    "check_series",
    "check_series_collection",
    "encode_labels",
    "from_aeon",
    "from_tslearn",
    "to_aeon",
]
