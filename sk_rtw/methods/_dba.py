"""DBA as a method object: DTW barycenter averaging with Fréchet means, group by group."""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from typing import Any

import numpy as np
from joblib import Parallel, delayed

from .._settings import resolve_knobs
from ..baselines import dba_average
from ..utils import SeriesCollection
from ..utils._params import drop_auto
from ._base import AveragingMethod, FitContext, method_class


@dataclass(frozen=True)
class DBAConfig:
    """The resolved settings of one DBA fit."""

    method: str
    preset: str
    max_iter: int
    tol: float
    window: float | None

    def to_dict(self) -> dict[str, Any]:
        return dataclasses.asdict(self)


def _fit_one(collection: SeriesCollection, config: DBAConfig, init: Any = "medoid"):
    start = time.perf_counter()
    result = dba_average(collection, window=config.window, max_iter=config.max_iter,
                         tol=config.tol, init=init)  # fmt: skip
    return dataclasses.replace(result, config=config, fit_time=time.perf_counter() - start)


@method_class(
    "dba",
    "DTW barycenter averaging with Fréchet means (Petitjean et al., 2011), any manifold.\n\n"
    "    Each iteration aligns every series of a group to the current average by manifold\n"
    "    DTW (squared geodesic costs) and replaces each sample of the average by the\n"
    "    Fréchet mean of the points matched to it (:func:`sk_rtw.baselines.dba_average`);\n"
    "    the average starts at the group's DTW medoid (in k-means rounds: at the cluster's\n"
    "    current centroid, as in Petitjean et al.'s k-means) and keeps its length. The DTW\n"
    "    band is the estimator's ``dtw_window``.",
)
class DBA(AveragingMethod):
    def __init__(
        self,
        *,
        tol: float | str = "auto",
        max_iter: int | str = "auto",
    ) -> None:
        self.tol = tol
        self.max_iter = max_iter

    def configure(self, context: FitContext) -> DBAConfig:
        """Every setting checked and resolved (preset, then method, then the values given),
        the band the estimator's (``context``).

        Parameters
        ----------
        context : FitContext

        Returns
        -------
        DBAConfig
        """
        given = drop_auto(super().configure(context))
        values = resolve_knobs(self.name, context.preset, given)
        return DBAConfig(self.name, context.preset, values["max_iter"], values["tol"],
                         context.dtw_window)  # fmt: skip

    def keeps_single_series(self, config: DBAConfig) -> bool:
        """True: the average starts at the group's medoid, the series, and stays there."""
        return True

    def fit_groups(
        self,
        collection: SeriesCollection,
        codes: np.ndarray,
        seeds: list[int],
        config: DBAConfig,
        context: FitContext,
        starts: list[np.ndarray] | None = None,
    ) -> list[Any]:
        codes = np.asarray(codes, dtype=np.int64)
        members = [np.flatnonzero(codes == g) for g in range(int(codes.max()) + 1)]
        inits = ["medoid"] * len(members) if starts is None else list(starts)
        jobs = [
            delayed(_fit_one)(collection.subset(idx), config, init)
            for idx, init in zip(members, inits, strict=True)
        ]
        if context.n_jobs in (None, 1) or len(members) == 1:
            return [fn(*args, **kwargs) for fn, args, kwargs in jobs]
        return list(Parallel(n_jobs=context.n_jobs)(jobs))
