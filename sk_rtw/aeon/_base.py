"""What the aeon classifiers share: aeon's layouts as sk_rtw series, and a classifier
that delegates to an sk_rtw estimator."""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np
from aeon.classification.base import BaseClassifier
from aeon.utils.validation import check_n_jobs

from .._numba import check_n_jobs as check_n_jobs_value
from ..manifolds import SPD, Euclidean
from ..utils import from_aeon


def _is_named(manifold: Any, name: str) -> bool:
    return isinstance(manifold, str) and manifold.lower() == name


def time_major(X: np.ndarray | list[np.ndarray], manifold: Any) -> np.ndarray | list:
    """aeon's channels-first cases as sk_rtw series of ``manifold``'s points.

    Every channel is a coordinate of the point: ``(n, c, T)`` becomes ``(n, T)`` for one
    channel, ``(n, T, c)`` otherwise; for SPD(k) the ``c = k * k`` channels are the
    matrix's entries, row by row, and become ``(n, T, k, k)``.
    """
    series = from_aeon(X)
    if not (_is_named(manifold, "spd") or isinstance(manifold, SPD)):
        return series
    shapes = {np.shape(s)[1:] for s in series}
    n_channels = 1 if shapes == {()} else next(iter(shapes))[0]
    k = math.isqrt(n_channels)
    if k * k != n_channels or (isinstance(manifold, SPD) and manifold.dim != k):
        expected = f"{manifold.dim ** 2}" if isinstance(manifold, SPD) else "a square number of"
        raise ValueError(
            f"SPD points in aeon's layout are the k x k matrix's entries as channels, row "
            f"by row: expected {expected} channels, got {n_channels}"
        )
    if isinstance(series, np.ndarray):
        return series.reshape(*series.shape[:2], k, k)
    return [np.reshape(s, (len(s), k, k)) for s in series]



class DelegatingClassifier(BaseClassifier):
    """An aeon classifier whose fit and predictions are those of an sk_rtw classifier
    (``_wrapped``) with the same parameters, on aeon's layouts.

    Subclasses write their ``__init__`` (the wrapped class's parameters, ``n_jobs=1`` by
    aeon's convention) and their tags.
    """

    _wrapped: ClassVar[type]
    #: Set by the subclasses' ``__init__`` (the wrapped class's parameters).
    manifold: Any
    n_jobs: int | None

    def _manifold_for(self, X: np.ndarray | list[np.ndarray]) -> Any:
        """The manifold handed on: ``"euclidean"`` becomes ``Euclidean(n_channels)``.

        The layout is known here, so the time-major check against aeon's layout (a
        by-name Euclidean array with fewer time points than channels is refused) must
        not refuse short multichannel cases; the resolved manifold is the same.
        """
        n_channels = X.shape[1] if isinstance(X, np.ndarray) else X[0].shape[0]
        if _is_named(self.manifold, "euclidean") and n_channels > 1:
            return Euclidean(n_channels)
        return self.manifold

    def _fit(self, X: np.ndarray | list[np.ndarray], y: np.ndarray) -> DelegatingClassifier:
        check_n_jobs_value(self.n_jobs)  # 0 refused, as the wrapped estimator refuses it
        self._n_jobs = check_n_jobs(self.n_jobs if self.n_jobs is not None else 1)
        names = self._wrapped._declaration.names  # type: ignore[attr-defined]
        params = {name: getattr(self, name) for name in names if name != "n_jobs"}
        params["manifold"] = self._manifold_for(X)
        self.estimator_ = self._wrapped(n_jobs=self._n_jobs, **params)
        self.estimator_.fit(time_major(X, self.manifold), y)
        return self

    def _predict(self, X: np.ndarray | list[np.ndarray]) -> np.ndarray:
        return self.estimator_.predict(time_major(X, self.manifold))

    def _predict_proba(self, X: np.ndarray | list[np.ndarray]) -> np.ndarray:
        return self.estimator_.predict_proba(time_major(X, self.manifold))
