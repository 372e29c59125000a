"""One alignment problem on its device: the series, their interpolator, the loss weights,
and the forward pass every epoch runs (warps, aligned series, mean, loss)."""

from __future__ import annotations

import copy

import torch

from ..manifolds._mean import frechet_mean
from ..utils import SeriesCollection
from ._config import AlignmentConfig
from ._density import density_representatives
from ._layout import GroupLayout
from ._loss import window_weights
from ._sinc import SincInterpolator
from ._warps import WarpModel, compose_warps, unit_time


class Problem:
    """Everything one forward pass needs, on the right device."""

    def __init__(self, collection: SeriesCollection, layout: GroupLayout, config: AlignmentConfig):
        device = torch.device(config.device)
        self.manifold = collection.manifold
        self.config = config
        self.layout = layout.to(device)
        self.data = torch.as_tensor(collection.data, dtype=torch.float64, device=device)
        self.lengths = torch.as_tensor(collection.lengths, device=device)
        z = output_length(config)
        self.zhat = unit_time(z, device=device)
        self.loss_weights = window_weights(z, config.loss_window, config.loss_step, device=device)
        sizes = self.layout.sizes.to(torch.float64)
        #: 1 / (N_g Z) for every series: each group's loss is the paper's mean over its series
        self.series_weight = 1.0 / (self.layout.expand(sizes) * z)
        self.interpolate = SincInterpolator(
            self.manifold,
            self.data,
            self.lengths,
            config.sinc_window,
            config.tangent_refinements,
        )
        #: Starting warps (N, Z) that the learned warps are composed with, or None.
        self.start: torch.Tensor | None = None
        #: The previous epoch's means (``mean_start="previous"``): the next Gauss–Newton start.
        self.warm: torch.Tensor | None = None

    def subset(self, groups: torch.Tensor) -> Problem:
        """The problem of ``groups`` only (increasing indices): their series, starting
        warps and warm-started means; each computed exactly as in the whole problem."""
        layout, rows = self.layout.subset(groups)
        other = copy.copy(self)
        other.layout = layout
        other.interpolate = self.interpolate.subset(rows)
        # one copy of the series, shared with the interpolator as in the whole problem
        other.data, other.lengths = other.interpolate.data, other.interpolate.lengths
        other.series_weight = self.series_weight[rows]
        other.start = None if self.start is None else self.start[rows]
        other.warm = None if self.warm is None else self.warm[groups].clone()
        return other

    def points_and_weights(self, warps: torch.Tensor, aligned: torch.Tensor):
        """What enters the mean: the aligned points with equal weights, or the stretch
        representatives with their sample counts (``mean_weights="density"``)."""
        if self.config.mean_weights == "density":
            return density_representatives(self.manifold, self.data, self.lengths, warps,
                                           aligned)  # fmt: skip
        return aligned, None

    def average(self, warps: torch.Tensor, aligned: torch.Tensor) -> torch.Tensor:
        """The engine's mean of every group's aligned series (loss and returned mean)."""
        config = self.config
        points, weights = self.points_and_weights(warps, aligned)
        codes, sizes = self.layout.codes, self.layout.sizes
        if self.manifold.is_flat:  # exact in one step, from any start
            return frechet_mean(self.manifold, points, weights, codes, sizes=sizes)
        if config.mean_start == "first":
            return frechet_mean(self.manifold, points, weights, codes, sizes=sizes,
                                max_iter=config.mean_iterations, tol=0.0)  # fmt: skip
        if self.warm is None or self.warm.shape[1] != points.shape[1]:
            return frechet_mean(self.manifold, points, weights, codes, sizes=sizes,
                                differentiate="none")  # fmt: skip
        mean = frechet_mean(self.manifold, points, weights, codes, sizes=sizes, start=self.warm,
                            max_iter=config.mean_iterations, tol=0.0,
                            differentiate="last")  # fmt: skip
        self.warm.copy_(mean.detach())
        return mean

    def converged_mean(self, warps: torch.Tensor, start: torch.Tensor | None = None):
        """The converged mean along ``warps`` (no gradient): DTW start and returned mean."""
        with torch.no_grad():
            aligned = self.interpolate(warps)
            points, weights = self.points_and_weights(warps, aligned)
            return frechet_mean(self.manifold, points, weights, self.layout.codes,
                                start=start, differentiate="none",
                                sizes=self.layout.sizes)  # fmt: skip

    def initial_warps(self) -> torch.Tensor:
        identity = self.zhat.expand(self.layout.n_series, -1)
        return identity if self.start is None else compose_warps(self.start, identity)

    def prepare_mean(self) -> None:
        """The Gauss–Newton start of the first epoch: the converged mean at the start."""
        if self.config.mean_start == "previous" and not self.manifold.is_flat:
            self.warm = self.converged_mean(self.initial_warps()).clone()

    def forward(self, model: WarpModel):
        raw = model(self.zhat)
        warps = model.finalise(raw)
        if self.start is not None:
            warps = compose_warps(self.start, warps)
        aligned = self.interpolate(warps)
        mean = self.average(warps, aligned)
        distances = self.manifold._dist(aligned, self.layout.expand(mean))
        per_series = (distances @ self.loss_weights) * self.series_weight
        if self.config.penalty > 0:
            decrease = torch.relu(raw[:, :-1] - raw[:, 1:]).sum(1)
            per_series = per_series + self.config.penalty * decrease
        group_loss = self.layout.sum(per_series)
        return group_loss.sum(), group_loss, warps, aligned, mean


def output_length(config: AlignmentConfig) -> int:
    """``config.output_length``, which the engine needs sized (:func:`size_config`)."""
    if config.output_length is None:
        raise ValueError("the configuration has no output length yet: size it with size_config")
    return config.output_length


def check_finite(values: torch.Tensor, collection: SeriesCollection, what: str) -> torch.Tensor:
    """``values``, or a ``ValueError`` when float64 could not follow the geometry."""
    if not bool(torch.isfinite(values).all()):
        note = collection.manifold.spread_note(collection.data)
        raise ValueError(
            f"aligning these series on {collection.manifold!r} left float64 arithmetic "
            f"(non-finite values in {what})" + (f": {note}" if note else "") + "; the "
            "geodesics between such points overflow: rescale or regularise the data"
        )
    return values
