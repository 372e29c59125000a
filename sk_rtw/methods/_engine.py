"""RTW, TTW and NTW: the alignment engine's three configurations as method objects."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..align._config import resolve_config
from ..align._engine import Alignment, align_collection
from ..align._presets import PRESETS
from ..utils import SeriesCollection
from ._base import AveragingMethod, FitContext, method_class


class EngineMethod(AveragingMethod):
    """A configuration of :func:`sk_rtw.align`'s engine; every group in one optimisation
    per distinct output length."""

    def fit_groups(
        self,
        collection: SeriesCollection,
        codes: np.ndarray,
        seeds: list[int],
        context: FitContext,
        starts: list[np.ndarray] | None = None,
    ) -> list[Any]:
        explicit = self.settings()
        codes = np.asarray(codes, dtype=np.int64)
        n_groups = int(codes.max()) + 1
        lengths = collection.lengths
        rule = PRESETS[context.preset].output_length
        z = np.array(
            [explicit.get("output_length") or rule(lengths[codes == g]) for g in range(n_groups)]
        )
        fitted: list[Alignment | None] = [None] * n_groups
        for length in np.unique(z):
            groups = np.flatnonzero(z == length)
            members = np.flatnonzero(np.isin(codes, groups))
            config = resolve_config(
                self.name, context.preset, {**explicit, "output_length": int(length)},
                lengths[members], device=context.device, dtw_window=context.dtw_window,
            )  # fmt: skip
            results = align_collection(
                collection.subset(members), np.searchsorted(groups, codes[members]),
                [seeds[g] for g in groups], config, n_jobs=context.n_jobs,
                verbose=context.verbose >= 2,
            )  # fmt: skip
            for g, result in zip(groups, results, strict=True):
                fitted[g] = result
        return fitted

    def describe(self, result: Any) -> str:
        return f"best epoch {result.best_epoch + 1} of {result.n_iter} run"


@method_class("rtw", "Riemannian Time Warping: neural warps, windowed sinc, Gaussian window loss.")
class RTW(EngineMethod):
    pass


@method_class("ttw", "Riemannian Trainable Time Warping: sine-series warps, pointwise loss.")
class TTW(EngineMethod):
    pass


@method_class("ntw", "Riemannian Neural Time Warping: zero-initialised network, full sinc.")
class NTW(EngineMethod):
    pass
