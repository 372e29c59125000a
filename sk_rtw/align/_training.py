"""The optimisation loop: Adam over the warp parameters, each group's best iterate kept.

The parameters of several independent groups (the classes of an estimator) are trained in
one loop. The loss function returns the total loss (whose gradient drives Adam) and the
loss of every group; because the groups share no parameter and Adam is elementwise, each
group follows exactly the trajectory of a separate fit. Per group the loop keeps

* the lowest loss so far, its epoch and a copy of the group's parameters at that epoch
  (copied *before* the Adam step changes them);
* an early-stopping counter (``n_iter_no_change``, ``tol``, as scikit-learn's
  ``MLPRegressor``): an epoch counts as no improvement unless its loss is below the best
  loss by more than ``tol`` times its size; after ``n_iter_no_change`` such epochs in a
  row the group stops: its best iterate is frozen. The loop ends when every group has
  stopped or after ``n_epochs``;
* a stop that knows the start (``start_patience``): the first epoch's loss is the loss of
  the warps training starts from (RTW's DTW start, composed with a zero readout). A group
  whose lowest loss after ``start_patience`` epochs is still more than
  :data:`NEAR_START` times the start's stops: the start is its best iterate and is kept,
  as the early stop would keep it after ``n_iter_no_change`` epochs. Adam's first step
  from a fine start throws the warps far from it (a median 1.9 times the start's loss on
  UCR class fits, 100-600 times on long smooth demonstrations). Where training can beat
  the start, the loss is back near it within a few epochs (generated warped sets: under
  1.71 times by the 8th epoch, then 2-5 % below the start after 20-50 epochs); where it
  is not back, training has not beaten the start on any recorded history (long
  demonstrations: still 2-100 times after 20 epochs). The study ``start_patience.py``
  (retired: docs/benchmarks/studies.md) replayed recorded histories under other
  patiences and ratios: shorter patiences or a ratio of 2 cut training on the generated
  sets that it would have won.
  A group hovering near its start is left to ``n_iter_no_change``.
  A group still *far* from its start stops sooner: one whose lowest loss after
  :data:`EARLY_PATIENCE` epochs is more than :data:`FAR_FROM_START` times the start's
  (the same replays: no group that went on to beat its start was above 7.2 times it
  after two epochs; long demonstrations were 23-375 times above it).

A caller may pause the loop (``run(pause=...)``) and continue with the running groups
only (:meth:`Trainer.narrow`): best iterates, counters, history and Adam's moments are
carried over, so each group's trajectory is the one it had in the whole batch (the engine
narrows its batch once half of the groups have stopped).

All bookkeeping is tensor operations (``torch.where``), so an epoch needs no host-device
synchronisation on a GPU; on a CPU the stop flags are read every epoch, on CUDA every
``report_every`` epochs.

With ``cuda_graph=True`` on a CUDA device the whole epoch is captured once in a CUDA
graph and replayed (``torch.cuda.CUDAGraph``): a small alignment problem is otherwise bound
by the launch cost of several hundred small kernels per epoch. Capture is tried after a
few eager warm-up epochs; if an operation cannot be captured, the remaining epochs run
eagerly with a warning. Graph capture is opt-in: it has not yet been checked on a GPU
(``benchmarks/check_cuda.py`` does that check).
"""

from __future__ import annotations

import copy
import math
import sys
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import torch

from ._adam import FusedAdam

#: Eager epochs before a CUDA graph is captured (lets lazy allocations settle).
WARMUP_EPOCHS = 3
#: ``start_patience`` stops a group whose lowest loss after the first epoch is still more
#: than this multiple of the start's (measured: docs/benchmarks/align_speed.md).
NEAR_START = 2.5
#: ... and, after :data:`EARLY_PATIENCE` epochs, one whose lowest loss is still more than
#: this multiple of the start's (whatever ``start_patience`` is, where it is set).
FAR_FROM_START = 20.0
EARLY_PATIENCE = 3


def _group_shapes(parameter_groups, parameters, device) -> list[torch.Tensor]:
    """Every parameter's group labels shaped to broadcast over the parameter."""
    return [
        groups.to(device).view(-1, *([1] * max(p.ndim - 1, 0)))
        for groups, p in zip(parameter_groups, parameters, strict=True)
    ]


@dataclass
class GroupProgress:
    """Every group's progress, one entry per group (``history``: one column per group),
    updated in place by every epoch (a CUDA graph replays those updates)."""

    #: The lowest loss so far, and its epoch (-1: none yet).
    best_loss: torch.Tensor
    best_epoch: torch.Tensor
    #: Still training; epochs in a row without a significant improvement.
    active: torch.Tensor
    stalled: torch.Tensor
    #: Epochs trained, and the loss of each (NaN once the group stopped).
    epochs_run: torch.Tensor
    history: torch.Tensor
    #: The first epoch's loss (the start's) and the lowest loss after the first epoch.
    start_loss: torch.Tensor
    low: torch.Tensor
    #: The caller's number of every group (a narrowed trainer's error messages name it).
    ids: np.ndarray

    @classmethod
    def start(cls, n_groups: int, n_epochs: int, dtype, device) -> GroupProgress:
        shape = (max(1, n_epochs), n_groups)
        return cls(
            best_loss=torch.full((n_groups,), math.inf, dtype=dtype, device=device),
            best_epoch=torch.full((n_groups,), -1, dtype=torch.long, device=device),
            active=torch.ones(n_groups, dtype=torch.bool, device=device),
            stalled=torch.zeros(n_groups, dtype=torch.long, device=device),
            epochs_run=torch.zeros(n_groups, dtype=torch.long, device=device),
            history=torch.full(shape, math.nan, dtype=dtype, device=device),
            ids=np.arange(n_groups),
            start_loss=torch.full((n_groups,), math.nan, dtype=dtype, device=device),
            low=torch.full((n_groups,), math.inf, dtype=dtype, device=device),
        )

    def select(self, groups: torch.Tensor) -> GroupProgress:
        """The progress of ``groups`` (indices), copied."""
        return GroupProgress(
            best_loss=self.best_loss[groups].clone(),
            best_epoch=self.best_epoch[groups].clone(),
            active=self.active[groups].clone(),
            stalled=self.stalled[groups].clone(),
            epochs_run=self.epochs_run[groups].clone(),
            history=self.history[:, groups].clone(),
            ids=self.ids[groups.cpu().numpy()],
            start_loss=self.start_loss[groups].clone(),
            low=self.low[groups].clone(),
        )


class Trainer:
    """Adam on ``parameters`` minimising ``loss_fn()``; keeps every group's best parameters.

    Parameters
    ----------
    loss_fn : callable
        Returns the scalar total loss, or a pair ``(total, group_losses)`` with the loss
        of each of ``n_groups`` groups (shape ``(n_groups,)``).
    parameters : list of torch.Tensor
        Trainable parameters (updated in place).
    n_epochs : int
    learning_rate : float
    parameter_groups : list of torch.Tensor, optional
        For every parameter, the group of each index along its leading axis (default:
        everything belongs to group 0).
    n_groups : int, default=1
    n_iter_no_change : int or None, default=None
        Stop a group after this many epochs without an improvement larger than ``tol``
        (None: never stop early).
    tol : float, default=1e-4
        Relative improvement that counts.
    start_patience : int or None, default=None
        Stop a group after this many epochs if its lowest loss since the first epoch is
        still more than :data:`NEAR_START` times the first epoch's, or after
        :data:`EARLY_PATIENCE` epochs if it is more than :data:`FAR_FROM_START` times
        it, keeping the first epoch's parameters (see the module docstring; None: no
        such stop).
    cuda_graph : bool, default=False
        Capture the epoch in a CUDA graph and replay it (CUDA devices only).
    """

    def __init__(
        self,
        loss_fn: Callable[[], torch.Tensor | tuple[torch.Tensor, torch.Tensor]],
        parameters: Sequence[torch.Tensor],
        n_epochs: int,
        learning_rate: float,
        parameter_groups: Sequence[torch.Tensor] | None = None,
        n_groups: int = 1,
        n_iter_no_change: int | None = None,
        tol: float = 1e-4,
        start_patience: int | None = None,
        cuda_graph: bool = False,
    ):
        self.loss_fn = loss_fn
        self.cuda_graph = cuda_graph
        self.parameters = list(parameters)
        self.n_epochs = n_epochs
        self.n_groups = n_groups
        self.n_iter_no_change = n_iter_no_change
        self.tol = float(tol)
        self.start_patience = start_patience
        device = parameters[0].device
        self.device = device
        self.cuda = device.type == "cuda"
        # fused Adam: one kernel for all parameters (CPU and CUDA alike), torch.optim's
        # kernel without its first-call import of torch._dynamo (see _adam.py)
        self.optimiser = FusedAdam(parameters, lr=learning_rate)
        dtype = torch.float64  # the losses' (a float32 warp network's too)
        if parameter_groups is None:
            parameter_groups = [torch.zeros(p.shape[0] if p.ndim else 1, dtype=torch.long)
                                for p in parameters]  # fmt: skip
        self._shapes = _group_shapes(parameter_groups, parameters, device)
        self.whole_groups = n_groups
        self.epochs_done = 0
        self.best = [p.detach().clone() for p in parameters]
        self.progress = GroupProgress.start(n_groups, n_epochs, dtype, device)
        self.epoch = torch.zeros(1, dtype=torch.long, device=device)
        self._limit = n_iter_no_change if n_iter_no_change is not None else max(1, n_epochs) + 1

    def _losses(self) -> tuple[torch.Tensor, torch.Tensor]:
        out = self.loss_fn()
        if isinstance(out, tuple):
            return out
        return out, out.reshape(1)

    def step(self, zero_grad: bool = True) -> None:
        """One epoch (no host-device synchronisation)."""
        if zero_grad:
            self.optimiser.zero_grad(set_to_none=True)
        total, groups = self._losses()
        total.backward()
        with torch.no_grad():
            value = groups.detach()
            progress = self.progress
            active, best_loss = progress.active, progress.best_loss
            better = (value < best_loss) & active  # False for NaN
            threshold = best_loss - self.tol * best_loss.abs()
            significant = (value < threshold) | torch.isinf(best_loss)
            best_loss.copy_(torch.where(better, value, best_loss))
            progress.best_epoch.copy_(torch.where(better, self.epoch, progress.best_epoch))
            # on a CPU reading the flags is free: copy only when a group improved, and
            # plainly when every group did (one group: each improving epoch)
            if self.cuda or bool(better.any()):
                every = not self.cuda and bool(better.all())
                for kept, current, shape in zip(self.best, self.parameters, self._shapes,
                                                strict=True):  # fmt: skip
                    kept.copy_(current if every else torch.where(better[shape], current, kept))
            progress.history.index_copy_(
                0, self.epoch, torch.where(active, value, math.nan).unsqueeze(0)
            )
            progress.epochs_run.add_(active.long())
            progress.stalled.copy_(torch.where(significant, 0, progress.stalled + 1))
            keep = progress.stalled < self._limit
            if self.start_patience is not None:
                keep &= ~self._far_from_start(value, self.start_patience)
            active.copy_(active & keep)
            self.epoch += 1
        self.optimiser.step()

    def _far_from_start(self, value: torch.Tensor, patience: int) -> torch.Tensor:
        """Update the start's bookkeeping with this epoch's losses; True for the groups
        that ``start_patience=patience`` stops now (no host-device synchronisation)."""
        progress = self.progress
        first = self.epoch == 0
        start, low = progress.start_loss, progress.low
        start.copy_(torch.where(first, value, start))
        low.copy_(torch.where(first, low, torch.minimum(low, value)))
        # the lowest loss only falls: a group back within NEAR_START is never stopped here
        done = self.epoch + 1
        near = (done >= patience) & (low > NEAR_START * start)
        return near | ((done >= EARLY_PATIENCE) & (low > FAR_FROM_START * start))

    def run(
        self,
        report: Callable[[int, np.ndarray], None],
        report_every: int,
        pause: Callable[[torch.Tensor], bool] | None = None,
    ) -> np.ndarray | None:
        """All epochs (or until every group stopped); loads each group's best parameters.

        ``report(done, history)`` is called every ``report_every`` epochs and at the end
        with the number of epochs done and the losses so far (``(done, n_groups)``).
        ``pause(active)``, checked after every epoch on a CPU, may interrupt the run while
        groups are still running: it returns None then, and :meth:`narrow` (or another
        ``run``) continues where it stopped.

        Returns
        -------
        best_epoch : ndarray of int, shape (n_groups,), or None when paused

        Raises
        ------
        FloatingPointError
            As soon as a check finds a non-finite loss.
        """
        done, graph = self.epochs_done, None
        if self.cuda and self.cuda_graph:
            done = self._warm_up(report, report_every)
            graph = self._capture() if done < self.n_epochs else None
        # on a CPU reading the flags costs nothing: check every epoch
        check_every = report_every if self.cuda else 1
        active = self.progress.active
        while done < self.n_epochs and bool(active.any()):
            block = min(check_every, self.n_epochs - done)
            for _ in range(block):
                if graph is not None:
                    graph.replay()
                else:
                    self.step()
            done += block
            stopped = not bool(active.any())
            announce = done % report_every == 0 or done == self.n_epochs or stopped
            self._check(done, report if announce else None)
            self.epochs_done = done
            if pause is not None and not stopped and done < self.n_epochs and pause(active):
                return None
        self.epochs_done = done
        with torch.no_grad():
            for current, kept in zip(self.parameters, self.best, strict=True):
                current.copy_(kept)
        return self.progress.best_epoch.cpu().numpy()

    def rows(self, groups: torch.Tensor) -> list[torch.Tensor]:
        """For every parameter, the indices of its leading axis that belong to ``groups``."""
        return [torch.isin(shape.view(-1), groups).nonzero().flatten() for shape in self._shapes]

    def narrow(
        self,
        groups: torch.Tensor,
        loss_fn: Callable[[], torch.Tensor | tuple[torch.Tensor, torch.Tensor]],
        parameters: Sequence[torch.Tensor],
        parameter_groups: Sequence[torch.Tensor],
    ) -> Trainer:
        """A trainer of ``groups`` only (increasing indices) that goes on where this one
        paused: the losses of ``loss_fn`` and the ``parameters`` (with their
        ``parameter_groups``) are those groups' alone, renumbered from 0. Best iterates,
        counters, history and Adam's moments are carried over, so every remaining group
        follows the trajectory it would have followed in the whole batch."""
        groups = groups.to(self.device)
        rows = self.rows(groups)
        other = copy.copy(self)
        other.loss_fn = loss_fn
        other.parameters = list(parameters)
        other.n_groups = len(groups)
        other._shapes = _group_shapes(parameter_groups, other.parameters, self.device)
        other.optimiser = self.optimiser.narrow(other.parameters, rows)
        other.best = [kept[r].clone() for kept, r in zip(self.best, rows, strict=True)]
        other.progress = self.progress.select(groups)
        other.epoch = self.epoch.clone()
        return other

    # ------------------------------------------------------------------ cuda
    def _warm_up(self, report, report_every: int) -> int:
        side = torch.cuda.Stream(device=self.device)
        side.wait_stream(torch.cuda.current_stream(self.device))
        epochs = min(WARMUP_EPOCHS, self.n_epochs)
        with torch.cuda.stream(side):
            for _ in range(epochs):
                self.step()
        torch.cuda.current_stream(self.device).wait_stream(side)
        announce = epochs == self.n_epochs or epochs % report_every == 0
        self._check(epochs, report if announce else None)
        return epochs

    def _capture(self) -> torch.cuda.CUDAGraph | None:
        graph = torch.cuda.CUDAGraph()
        self.optimiser.zero_grad(set_to_none=True)
        try:
            with torch.cuda.graph(graph):
                self.step(zero_grad=False)
        except Exception as exc:  # an operation that cannot be captured: run eagerly
            torch.cuda.synchronize(self.device)
            self.optimiser.zero_grad(set_to_none=True)
            warnings.warn(
                f"CUDA graph capture failed ({type(exc).__name__}: {exc}); the remaining "
                "epochs run without it (slower, same result)",
                RuntimeWarning,
                stacklevel=4,
            )
            return None
        return graph

    # ---------------------------------------------------------------- checks
    def _check(self, done: int, report) -> None:
        """Raise on a non-finite loss among the first ``done``; then ``report`` if given."""
        history = self.progress.history[:done].cpu().numpy()
        epochs_run = self.progress.epochs_run.cpu().numpy()
        for g in range(self.n_groups):
            values = history[: epochs_run[g], g]
            bad = np.flatnonzero(~np.isfinite(values))
            if bad.size:
                where = f" of group {self.progress.ids[g]}" if self.whole_groups > 1 else ""
                raise FloatingPointError(
                    f"the alignment loss{where} became {values[bad[0]]} at epoch {bad[0]}; "
                    "lower learning_rate or check the data scale"
                )
        if report is not None:
            report(done, history)


def progress_printer(method: str, n_epochs: int, verbose: bool | int):
    """The ``report`` callback of :meth:`Trainer.run` and its interval for ``verbose``.

    Epochs are numbered from 0, as ``Alignment.best_epoch`` is.
    """
    every = (
        int(verbose) if not isinstance(verbose, bool) and verbose > 1 else max(1, n_epochs // 10)
    )

    def report(done: int, history: np.ndarray) -> None:
        if not verbose:
            return
        history = np.atleast_2d(history.T).T  # (done, n_groups)
        total = np.nansum(history, axis=1)
        running = int(np.isfinite(history[-1]).sum())
        best = int(np.argmin(total)) if np.isfinite(total).any() else 0
        groups = f", {running}/{history.shape[1]} groups running" if history.shape[1] > 1 else ""
        print(
            f"[{method}] {done:>4}/{n_epochs} epochs, loss {total[-1]:.6g} "
            f"(best {total[best]:.6g} at epoch {best}){groups}",
            file=sys.stderr,
            flush=True,
        )

    return report, every


def stopped_far_from_start(history: np.ndarray) -> bool:
    """Whether the early tier of ``start_patience`` stopped the groups that ran longest in
    ``history`` (epochs x groups, NaN once a group stopped): each one's lowest loss after
    its first epoch still more than :data:`FAR_FROM_START` times the first epoch's."""
    history = np.atleast_2d(np.asarray(history, dtype=float).T).T
    last = history[-1]
    longest = history[:, np.isfinite(last)]
    if len(history) < EARLY_PATIENCE or longest.shape[1] == 0:
        return False
    return bool(np.all(np.nanmin(longest[1:], axis=0) > FAR_FROM_START * longest[0]))


def early_stop_note(
    method: str,
    done: int,
    n_epochs: int,
    best_epoch: np.ndarray,
    n_iter_no_change,
    tol,
    start_patience=None,
    history: np.ndarray | None = None,
) -> str | None:
    """The ``verbose`` line of a run that stopped before ``n_epochs``, or None.

    ``history``: the losses of the ``done`` epochs (epochs x groups), which tell the
    early tier of ``start_patience`` from its main rule."""
    if done >= n_epochs or (n_iter_no_change is None and start_patience is None):
        return None
    kept = (
        f"epoch {int(best_epoch[0])}"
        if len(best_epoch) == 1
        else f"each group's best epoch ({int(best_epoch.min())} to {int(best_epoch.max())})"
    )
    early = start_patience is not None and EARLY_PATIENCE <= done < start_patience
    if early and history is not None and stopped_far_from_start(history[:done]):
        reason = (
            f"after {done} epochs the loss was still more than {FAR_FROM_START:g} times "
            "the start's"
        )
    # the no-change counter cannot stop a group before n_iter_no_change + 1 epochs
    elif n_iter_no_change is None or done <= n_iter_no_change:
        reason = (
            f"within start_patience={start_patience} epochs the loss did not come back "
            f"within {NEAR_START:g} times the start's"
        )
    else:
        reason = f"{n_iter_no_change} epochs without a relative gain of tol={tol}"
    return (
        f"[{method}] stopped early after {done} of {n_epochs} epochs: {reason}; keeping the "
        f"warps of {kept} (best_epoch, numbered from 0)"
    )
