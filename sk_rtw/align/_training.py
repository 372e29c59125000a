"""The optimisation loop: Adam over the warp parameters, best iterate kept.

One epoch is: forward pass to the loss, backward pass, bookkeeping (loss history; the
parameters of the lowest loss so far are copied aside *before* the Adam step changes
them), Adam step. On a GPU everything after the forward pass stays on the device: the
bookkeeping uses ``torch.where`` rather than Python decisions on the loss value, so an
epoch needs no host-device synchronisation. On a CPU reading the loss is free, and the
parameters are copied only when the loss improves.

With ``cuda_graph=True`` on a CUDA device the whole epoch is captured once in a CUDA
graph and replayed (``torch.cuda.CUDAGraph``): a small alignment problem is otherwise bound
by the launch cost of several hundred small kernels per epoch. Capture is tried after a
few eager warm-up epochs; if an operation cannot be captured (some devices' eigensolvers
synchronise), the remaining epochs run eagerly with a warning. On CUDA, losses are read
back every ``report_every`` epochs (progress, non-finite check), not every epoch.
Graph capture is opt-in: it has not yet been checked on a GPU
(``benchmarks/check_cuda.py`` does that check).
"""

from __future__ import annotations

import math
import sys
import warnings
from collections.abc import Callable

import numpy as np
import torch

#: Eager epochs before a CUDA graph is captured (lets lazy allocations settle).
WARMUP_EPOCHS = 3


class Trainer:
    """Adam on ``parameters`` minimising ``loss_fn()``; keeps the best parameters.

    Parameters
    ----------
    loss_fn : callable
        Returns the scalar loss tensor of the current parameters.
    parameters : list of torch.Tensor
        Trainable parameters (updated in place).
    n_epochs : int
    learning_rate : float
    cuda_graph : bool, default=False
        Capture the epoch in a CUDA graph and replay it (CUDA devices only).
    """

    def __init__(
        self,
        loss_fn: Callable[[], torch.Tensor],
        parameters: list[torch.Tensor],
        n_epochs: int,
        learning_rate: float,
        cuda_graph: bool = False,
    ):
        self.loss_fn = loss_fn
        self.cuda_graph = cuda_graph
        self.parameters = parameters
        self.n_epochs = n_epochs
        device = parameters[0].device
        self.device = device
        self.cuda = device.type == "cuda"
        # fused Adam: one kernel for all parameters (CPU and CUDA alike)
        self.optimiser = torch.optim.Adam(
            parameters, lr=learning_rate, fused=True, capturable=self.cuda
        )
        dtype = parameters[0].dtype
        self.best = [p.detach().clone() for p in parameters]
        self.best_loss = torch.full((), math.inf, dtype=dtype, device=device)
        self.best_epoch = torch.full((), -1, dtype=torch.long, device=device)
        self.history = torch.full((max(1, n_epochs),), math.nan, dtype=dtype, device=device)
        self.epoch = torch.zeros(1, dtype=torch.long, device=device)

    def step(self, zero_grad: bool = True) -> None:
        """One epoch (on CUDA with no host-device synchronisation)."""
        if zero_grad:
            self.optimiser.zero_grad(set_to_none=True)
        loss = self.loss_fn()
        loss.backward()
        with torch.no_grad():
            value = loss.detach()
            if self.cuda:
                better = value < self.best_loss  # False for NaN
                self.best_loss.copy_(torch.where(better, value, self.best_loss))
                self.best_epoch.copy_(torch.where(better, self.epoch[0], self.best_epoch))
                for kept, current in zip(self.best, self.parameters, strict=True):
                    kept.copy_(torch.where(better, current, kept))
            elif value < self.best_loss:  # host memory: reading the loss is free
                self.best_loss.copy_(value)
                self.best_epoch.copy_(self.epoch[0])
                torch._foreach_copy_(self.best, self.parameters)
            self.history.index_copy_(0, self.epoch, value.reshape(1))
            self.epoch += 1
        self.optimiser.step()

    def run(self, report: Callable[[int, np.ndarray], None], report_every: int) -> int:
        """All epochs; loads the best parameters and returns the best epoch.

        ``report(done, history)`` is called every ``report_every`` epochs and at the end
        with the number of epochs done and the losses so far.

        Raises
        ------
        FloatingPointError
            As soon as a report finds a non-finite loss.
        """
        done, graph = 0, None
        if self.cuda and self.cuda_graph:
            done = self._warm_up(report, report_every)
            graph = self._capture() if done < self.n_epochs else None
        # on a CPU reading the loss costs nothing: check every epoch
        check_every = report_every if self.cuda else 1
        while done < self.n_epochs:
            block = min(check_every, self.n_epochs - done)
            for _ in range(block):
                if graph is not None:
                    graph.replay()
                else:
                    self.step()
            done += block
            announce = done % report_every == 0 or done == self.n_epochs
            self._check(done, report if announce else None)
        with torch.no_grad():
            for current, kept in zip(self.parameters, self.best, strict=True):
                current.copy_(kept)
        return int(self.best_epoch)

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
        history = self.history[:done].cpu().numpy()
        bad = np.flatnonzero(~np.isfinite(history))
        if bad.size:
            raise FloatingPointError(
                f"the alignment loss became {history[bad[0]]} at epoch {bad[0]}; lower "
                "learning_rate or check the data scale"
            )
        if report is not None:
            report(done, history)


def progress_printer(method: str, n_epochs: int, verbose: bool | int):
    """The ``report`` callback of :meth:`Trainer.run` and its interval for ``verbose``."""
    every = (
        int(verbose) if not isinstance(verbose, bool) and verbose > 1 else max(1, n_epochs // 10)
    )

    def report(done: int, history: np.ndarray) -> None:
        if not verbose:
            return
        best = int(np.argmin(history))
        print(
            f"[{method}] epoch {done:>4}/{n_epochs} loss {history[-1]:.6g} "
            f"(best {history[best]:.6g} at {best + 1})",
            file=sys.stderr,
            flush=True,
        )

    return report, every
