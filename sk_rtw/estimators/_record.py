"""One record per centroid fit: everything the fit resolved, for whoever reads it later.

:class:`RTWAverager` (and the classifiers built on it) resolve their parameters once --
method and configuration, band, centroids, representation, the groups every training
series is averaged in, their classes and one seed per centroid -- into a frozen
:class:`CentroidFitRecord`, fit from it, and keep it as the private fitted attribute
``_fit_record``. Whoever refits part of it later (the out-of-fold distances of
:class:`RTWPrototypeClassifier`) asks the record (:meth:`CentroidFitRecord.refit`)
instead of rebuilding the fit from the estimator's parameters: the same method,
configuration, band and seeds, whatever ``random_state`` was.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..methods import AveragingMethod, FitContext
from ..utils import SeriesCollection
from ._core import fit_centroids
from ._selection import Selection


def _frozen(values: Any, dtype: Any = None) -> np.ndarray:
    array = np.array(values, dtype=dtype)
    array.setflags(write=False)
    return array


@dataclass(frozen=True, eq=False)
class CentroidFitRecord:
    """What one centroid fit resolved (frozen; read by the estimator and its readers).

    Attributes
    ----------
    method : AveragingMethod
        The checked method object.
    config
        ``method.configure(context)``: its settings resolved once, with the band.
    context : FitContext
        Preset, band, device, threads and verbosity of the fit.
    representation : str
        What was averaged (``"raw"`` or ``"velocity"``).
    dtw_window : float or None
        The band of the fit and of prediction.
    n_centroids : int or float
        Centroids of every class (a count or a fraction).
    classes : ndarray of shape (n_classes,)
    codes : ndarray of int, shape (n_series,)
        Class index of every training series.
    groups : ndarray of int, shape (n_series,)
        Centroid every training series is averaged into.
    owners : ndarray of int, shape (n_centroids,)
        Class index of every centroid.
    seeds : tuple of int
        One seed per centroid, drawn once from ``random_state``.
    names : tuple
        A name per centroid (its class, or ``class/rank``) for the ``verbose`` lines.
    kind : str
        ``"class"`` (one centroid per class) or ``"centroid"``.
    selection : Selection or None
        The choice behind ``"auto"`` values (None when nothing was chosen).
    owner : str
        The estimator's name, for the ``verbose`` lines.
    """

    method: AveragingMethod
    config: Any
    context: FitContext
    representation: str
    dtw_window: float | None
    n_centroids: int | float
    classes: np.ndarray
    codes: np.ndarray
    groups: np.ndarray
    owners: np.ndarray
    seeds: tuple[int, ...]
    names: tuple[Any, ...]
    kind: str
    selection: Selection | None
    owner: str

    @classmethod
    def create(
        cls, *, classes, codes, groups, owners, seeds, names, **fields
    ) -> CentroidFitRecord:
        """A record with read-only arrays and tuples (its fields are never written)."""
        return cls(
            classes=_frozen(classes), codes=_frozen(codes, np.int64),
            groups=_frozen(groups, np.int64), owners=_frozen(owners, np.int64),
            seeds=tuple(int(s) for s in seeds), names=tuple(names), **fields,
        )  # fmt: skip

    def fit(self, collection: SeriesCollection) -> list[Any]:
        """Every centroid of the record, fitted on ``collection`` (the training series in
        the record's representation)."""
        return fit_centroids(self.method, self.config, collection, self.groups,
                             list(self.seeds), self.context, names=list(self.names),
                             kind=self.kind, owner=self.owner)  # fmt: skip

    def refit(
        self,
        collection: SeriesCollection,
        rows: np.ndarray,
        centroids: np.ndarray,
        *,
        verbose: int | None = None,
        owner: str | None = None,
    ) -> list[Any]:
        """Centroids of the record refitted on some of their series: same method,
        configuration, band and seeds.

        Parameters
        ----------
        collection : SeriesCollection
            The training series of the fit (in the record's representation).
        rows : ndarray of int
            The series to average, each into its recorded centroid.
        centroids : ndarray of int
            The centroids refitted, increasing; every one of them owns some of ``rows``,
            and every row belongs to one of them.
        verbose : int, optional
            The refits' verbosity (default: the fit's).
        owner : str, optional
            The name in the ``verbose`` lines (default: the fit's estimator).

        Returns
        -------
        list
            One result per entry of ``centroids``, in their order.
        """
        centroids = np.asarray(centroids, dtype=np.int64)
        rows = np.asarray(rows, dtype=np.int64)
        context = self.context if verbose is None else replace(self.context, verbose=verbose)
        return fit_centroids(
            self.method, self.config, collection.subset(rows),
            np.searchsorted(centroids, self.groups[rows]),
            [self.seeds[m] for m in centroids], context, kind="centroid",
            owner=self.owner if owner is None else owner,
        )  # fmt: skip
