"""Several independent alignment problems in one batch: which series belongs to which.

An estimator averages every class separately; the engine solves all of them in one
optimisation. The series of all groups are stacked along one axis (any order); a
:class:`GroupLayout` records the group of every series and its position inside the
group, and sums or broadcasts per-series values over the groups. One call of
:func:`sk_rtw.align` is the one-group case.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch


@dataclass(frozen=True, eq=False)
class GroupLayout:
    """Group of every series of a stacked collection.

    Attributes
    ----------
    codes : torch.Tensor of int64, shape (N,)
        Group of each series, in ``0..n_groups - 1``; every group has a series.
    positions : torch.Tensor of int64, shape (N,)
        Index of each series inside its group, in stacking order.
    sizes : torch.Tensor of int64, shape (n_groups,)
        Number of series of each group.
    """

    codes: torch.Tensor
    positions: torch.Tensor
    sizes: torch.Tensor

    @classmethod
    def from_codes(cls, codes, device: str | torch.device = "cpu") -> GroupLayout:
        """Layout of ``codes`` (N,) ints; the groups are ``0..max(codes)``, none empty."""
        codes = np.asarray(codes, dtype=np.int64).ravel()
        if codes.size == 0 or codes.min() < 0:
            raise ValueError("group codes must be non-negative integers, one per series")
        sizes = np.bincount(codes)
        if np.any(sizes == 0):
            raise ValueError(f"groups {np.flatnonzero(sizes == 0).tolist()} have no series")
        order = np.argsort(codes, kind="stable")
        positions = np.empty_like(codes)
        starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
        positions[order] = np.arange(codes.size) - np.repeat(starts, sizes)
        return cls(
            codes=torch.as_tensor(codes, device=device),
            positions=torch.as_tensor(positions, device=device),
            sizes=torch.as_tensor(sizes, device=device),
        )

    @classmethod
    def single(cls, n_series: int, device: str | torch.device = "cpu") -> GroupLayout:
        """All ``n_series`` series in one group."""
        return cls.from_codes(np.zeros(n_series, dtype=np.int64), device)

    @property
    def n_series(self) -> int:
        return int(self.codes.numel())

    @property
    def n_groups(self) -> int:
        return int(self.sizes.numel())

    @property
    def max_size(self) -> int:
        return int(self.sizes.max())

    def members(self, group: int) -> np.ndarray:
        """Indices (into the stacked series) of the series of ``group``, in order."""
        codes = self.codes.cpu().numpy()
        return np.flatnonzero(codes == group)

    def sum(self, values: torch.Tensor) -> torch.Tensor:
        """Per-group sums of per-series ``values`` (N, ...) -> (n_groups, ...).

        One accumulation order whatever the number of groups (series in stacking order),
        so a group gets bitwise the same sums alone as in a batch.
        """
        out = values.new_zeros(self.n_groups, *values.shape[1:])
        return out.index_add(0, self.codes, values)

    def expand(self, values: torch.Tensor) -> torch.Tensor:
        """Per-group ``values`` (n_groups, ...) broadcast to their series -> (N, ...)."""
        if self.n_groups == 1:
            return values.expand(self.n_series, *values.shape[1:])
        return values.index_select(0, self.codes)

    def subset(self, groups: torch.Tensor) -> tuple[GroupLayout, torch.Tensor]:
        """The layout of ``groups`` only (increasing indices), renumbered from 0, and the
        rows of their series in the stacked collection (stacking order kept)."""
        renumber = torch.full((self.n_groups,), -1, dtype=torch.long, device=self.codes.device)
        renumber[groups] = torch.arange(len(groups), device=self.codes.device)
        codes = renumber[self.codes]
        rows = torch.nonzero(codes >= 0).flatten()
        layout = GroupLayout(codes=codes[rows], positions=self.positions[rows],
                             sizes=self.sizes[groups])  # fmt: skip
        return layout, rows

    def to(self, device: str | torch.device) -> GroupLayout:
        return GroupLayout(
            codes=self.codes.to(device), positions=self.positions.to(device),
            sizes=self.sizes.to(device),
        )  # fmt: skip
