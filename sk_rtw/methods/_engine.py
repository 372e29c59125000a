"""RTW, TTW and NTW: the alignment engine's three configurations as method objects."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from ..align import Alignment, AlignmentConfig, align_collection, resolve_config, size_config
from ..utils import SeriesCollection
from ..utils._params import drop_auto
from ._base import AveragingMethod, FitContext, method_class


class EngineMethod(AveragingMethod):
    """A configuration of :func:`sk_rtw.align`'s engine; every group in one optimisation
    per distinct output length."""

    def configure(self, context: FitContext) -> AlignmentConfig:
        """Every setting checked and resolved (preset, then method, then the values given):
        the engine's configuration, its output length left to the preset's rule
        (``None``) unless given, the DTW start's band the estimator's (``context``).

        Parameters
        ----------
        context : FitContext

        Returns
        -------
        AlignmentConfig
        """
        given = drop_auto(super().configure(context))
        return resolve_config(self.name, context.preset, given, device=context.device,
                              dtw_window=context.dtw_window)  # fmt: skip

    def fit_groups(
        self,
        collection: SeriesCollection,
        codes: np.ndarray,
        seeds: list[int],
        config: AlignmentConfig,
        context: FitContext,
        starts: list[np.ndarray] | None = None,
    ) -> list[Any]:
        codes = np.asarray(codes, dtype=np.int64)
        n_groups = int(codes.max()) + 1
        lengths = collection.lengths
        z = np.array(
            [size_config(config, lengths[codes == g]).output_length for g in range(n_groups)]
        )
        fitted: list[Alignment | None] = [None] * n_groups
        for length in np.unique(z):
            groups = np.flatnonzero(z == length)
            members = np.flatnonzero(np.isin(codes, groups))
            batch = size_config(dataclasses.replace(config, output_length=int(length)),
                                lengths[members])  # fmt: skip
            results = align_collection(
                collection.subset(members), np.searchsorted(groups, codes[members]),
                [seeds[g] for g in groups], batch, n_jobs=context.n_jobs,
                verbose=context.verbose >= 2,
            )  # fmt: skip
            for g, result in zip(groups, results, strict=True):
                fitted[g] = result
        return fitted

    def keeps_single_series(self, config: AlignmentConfig) -> bool:
        """True unless an output length is given: every preset's rule gives one series its
        own length, and its warp is the identity."""
        return config.output_length is None

    def describe(self, result: Any) -> str:
        return f"best epoch {result.best_epoch + 1} of {result.n_iter} run"


@method_class("rtw", "Riemannian Time Warping: neural warps, windowed sinc, Gaussian window loss.")
class RTW(EngineMethod):
    def __init__(
        self,
        *,
        output_length: int | str = "auto",
        n_epochs: int | str = "auto",
        learning_rate: float | str = "auto",
        sinc_window: int | str | None = "auto",
        loss_window: int | str = "auto",
        loss_step: int | str = "auto",
        penalty: float | str = "auto",
        warp_start: str = "auto",
        init: str = "auto",
        hidden_size: int | str = "auto",
        warp_knots: int | str | None = "auto",
        warp_dtype: str = "auto",
        tangent_refinements: int | str = "auto",
        mean_iterations: int | str = "auto",
        mean_start: str = "auto",
        mean_weights: str = "auto",
        dtw_rounds: int | str = "auto",
        smoothing: float | str = "auto",
        start_axis: str = "auto",
        n_iter_no_change: int | str | None = "auto",
        tol: float | str = "auto",
        start_patience: int | str | None = "auto",
        cuda_graph: bool | str = "auto",
        refine_steps: int | str = "auto",
    ) -> None:
        self.output_length = output_length
        self.n_epochs = n_epochs
        self.learning_rate = learning_rate
        self.sinc_window = sinc_window
        self.loss_window = loss_window
        self.loss_step = loss_step
        self.penalty = penalty
        self.warp_start = warp_start
        self.init = init
        self.hidden_size = hidden_size
        self.warp_knots = warp_knots
        self.warp_dtype = warp_dtype
        self.tangent_refinements = tangent_refinements
        self.mean_iterations = mean_iterations
        self.mean_start = mean_start
        self.mean_weights = mean_weights
        self.dtw_rounds = dtw_rounds
        self.smoothing = smoothing
        self.start_axis = start_axis
        self.n_iter_no_change = n_iter_no_change
        self.tol = tol
        self.start_patience = start_patience
        self.cuda_graph = cuda_graph
        self.refine_steps = refine_steps


@method_class("ttw", "Riemannian Trainable Time Warping: sine-series warps, pointwise loss.")
class TTW(EngineMethod):
    def __init__(
        self,
        *,
        output_length: int | str = "auto",
        n_epochs: int | str = "auto",
        learning_rate: float | str = "auto",
        sinc_window: int | str | None = "auto",
        loss_window: int | str = "auto",
        loss_step: int | str = "auto",
        penalty: float | str = "auto",
        warp_start: str = "auto",
        n_components: int | str = "auto",
        tangent_refinements: int | str = "auto",
        mean_iterations: int | str = "auto",
        mean_start: str = "auto",
        mean_weights: str = "auto",
        dtw_rounds: int | str = "auto",
        smoothing: float | str = "auto",
        start_axis: str = "auto",
        n_iter_no_change: int | str | None = "auto",
        tol: float | str = "auto",
        start_patience: int | str | None = "auto",
        cuda_graph: bool | str = "auto",
        refine_steps: int | str = "auto",
    ) -> None:
        self.output_length = output_length
        self.n_epochs = n_epochs
        self.learning_rate = learning_rate
        self.sinc_window = sinc_window
        self.loss_window = loss_window
        self.loss_step = loss_step
        self.penalty = penalty
        self.warp_start = warp_start
        self.n_components = n_components
        self.tangent_refinements = tangent_refinements
        self.mean_iterations = mean_iterations
        self.mean_start = mean_start
        self.mean_weights = mean_weights
        self.dtw_rounds = dtw_rounds
        self.smoothing = smoothing
        self.start_axis = start_axis
        self.n_iter_no_change = n_iter_no_change
        self.tol = tol
        self.start_patience = start_patience
        self.cuda_graph = cuda_graph
        self.refine_steps = refine_steps


@method_class("ntw", "Riemannian Neural Time Warping: zero-initialised network, full sinc.")
class NTW(EngineMethod):
    def __init__(
        self,
        *,
        output_length: int | str = "auto",
        n_epochs: int | str = "auto",
        learning_rate: float | str = "auto",
        sinc_window: int | str | None = "auto",
        loss_window: int | str = "auto",
        loss_step: int | str = "auto",
        penalty: float | str = "auto",
        warp_start: str = "auto",
        init: str = "auto",
        hidden_size: int | str = "auto",
        warp_knots: int | str | None = "auto",
        warp_dtype: str = "auto",
        tangent_refinements: int | str = "auto",
        mean_iterations: int | str = "auto",
        mean_start: str = "auto",
        mean_weights: str = "auto",
        dtw_rounds: int | str = "auto",
        smoothing: float | str = "auto",
        start_axis: str = "auto",
        n_iter_no_change: int | str | None = "auto",
        tol: float | str = "auto",
        start_patience: int | str | None = "auto",
        cuda_graph: bool | str = "auto",
        refine_steps: int | str = "auto",
    ) -> None:
        self.output_length = output_length
        self.n_epochs = n_epochs
        self.learning_rate = learning_rate
        self.sinc_window = sinc_window
        self.loss_window = loss_window
        self.loss_step = loss_step
        self.penalty = penalty
        self.warp_start = warp_start
        self.init = init
        self.hidden_size = hidden_size
        self.warp_knots = warp_knots
        self.warp_dtype = warp_dtype
        self.tangent_refinements = tangent_refinements
        self.mean_iterations = mean_iterations
        self.mean_start = mean_start
        self.mean_weights = mean_weights
        self.dtw_rounds = dtw_rounds
        self.smoothing = smoothing
        self.start_axis = start_axis
        self.n_iter_no_change = n_iter_no_change
        self.tol = tol
        self.start_patience = start_patience
        self.cuda_graph = cuda_graph
        self.refine_steps = refine_steps
