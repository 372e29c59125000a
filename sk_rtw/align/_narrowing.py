"""Adam over the warp parameters of a batch of groups, the batch narrowed to the running
groups as they stop.

:class:`~._training.Trainer` runs the batch. On a CPU, once half of its groups have
stopped (:func:`half_stopped`), the stopped groups' best iterates are written back to the
whole model and the problem, the model and the trainer go on with the running groups
only: a stopped group's epochs would be wasted work, and at most ``log2(groups)``
narrowings are paid. Every group follows the trajectory it had in the whole batch.

Group identity: the whole problem numbers its groups ``0 .. G - 1`` (its layout's codes);
a narrowed stage numbers its own from 0, and :attr:`BatchOptimisation.running` holds the
whole problem's number of each: the one translation between the two.
"""

from __future__ import annotations

import sys
from functools import partial

import numpy as np
import torch

from ._problem import Problem
from ._training import Trainer, early_stop_note, progress_printer
from ._warps import WarpModel


def half_stopped(active: torch.Tensor) -> bool:
    """Narrow the batch once half of its groups have stopped."""
    return 2 * int(active.sum()) <= active.numel()


def stage_loss(problem: Problem, model: WarpModel):
    """The trainer's loss: total and per-group losses of ``model`` on ``problem``."""
    return problem.forward(model)[:2]


class BatchOptimisation:
    """Adam over ``model``'s parameters on ``problem``, every group to its own stop.

    Parameters
    ----------
    problem : Problem
        The whole problem (all groups).
    model : WarpModel
        The whole model; :meth:`run` leaves every group's best iterate in it.
    verbose : bool or int
        Loss reports (see :func:`sk_rtw.align`).
    """

    def __init__(self, problem: Problem, model: WarpModel, verbose: bool | int) -> None:
        config = problem.config
        n_groups = problem.layout.n_groups
        self.config, self.model, self.verbose = config, model, verbose
        self.trainer = Trainer(
            partial(stage_loss, problem, model),
            list(model.parameters()),
            config.n_epochs,
            config.learning_rate,
            parameter_groups=model.parameter_groups(),
            n_groups=n_groups,
            n_iter_no_change=config.n_iter_no_change,
            tol=config.tol,
            start_patience=config.start_patience,
            cuda_graph=config.cuda_graph,
        )
        #: The whole problem's number of each of the trainer's groups.
        self.running = torch.arange(n_groups)
        self.stage_problem, self.stage_model = problem, model
        self.narrowing = self.trainer.device.type == "cpu" and n_groups > 1
        self.losses = np.full((max(1, config.n_epochs), n_groups), np.nan)
        self.best_epoch = np.full(n_groups, -1)
        self.epochs_run = np.zeros(n_groups, dtype=int)

    def run(self, history: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Train to the end; write every group's loss per epoch into ``history`` (its
        epochs after a group stopped stay NaN) and return the best epoch and the number
        of epochs run of every group."""
        show, every = progress_printer(self.config.method, self.config.n_epochs, self.verbose)

        def report(done: int, part: np.ndarray) -> None:
            self.losses[:done, self.running.numpy()] = part
            show(done, self.losses[:done])

        while not self._run_stage(report, every):
            self._narrow()
        done = self.trainer.epochs_done
        config = self.config
        note = early_stop_note(config.method, done, config.n_epochs, self.best_epoch,
                               config.n_iter_no_change, config.tol,
                               config.start_patience, self.losses[:done])  # fmt: skip
        if self.verbose and note:
            print(note, file=sys.stderr, flush=True)
        history[:done] = self.losses[:done]
        return self.best_epoch, self.epochs_run

    def _run_stage(self, report, every: int) -> bool:
        """Run the trainer until it finishes (True: the whole model then holds every
        group's best iterate) or pauses to narrow (False)."""
        trainer = self.trainer
        best = trainer.run(report, every, pause=half_stopped if self.narrowing else None)
        ids = self.running.numpy()
        self.losses[:, ids] = trainer.progress.history.cpu().numpy()
        self.best_epoch[ids] = trainer.progress.best_epoch.cpu().numpy()
        self.epochs_run[ids] = trainer.progress.epochs_run.cpu().numpy()
        if best is None:
            return False
        if self.stage_model is not self.model:
            self._write_back(self.running, list(self.stage_model.parameters()))
        return True

    def _narrow(self) -> None:
        """The stopped groups' best iterates back to the whole model; the problem, the
        model and the trainer of the running groups only."""
        trainer = self.trainer
        stopped = torch.nonzero(~trainer.progress.active.cpu()).flatten()
        self._write_back(self.running[stopped], trainer.best, trainer.rows(stopped))
        keep = torch.nonzero(trainer.progress.active.cpu()).flatten()
        problem = self.stage_problem.subset(keep.to(self.stage_problem.layout.codes.device))
        model = self.stage_model.subset(keep.to(trainer.device))
        loss = partial(stage_loss, problem, model)
        parameters, owners = list(model.parameters()), model.parameter_groups()
        self.trainer = trainer.narrow(keep, loss, parameters, owners)
        self.stage_problem, self.stage_model = problem, model
        self.running = self.running[keep]

    def _write_back(
        self,
        groups: torch.Tensor,
        values: list[torch.Tensor],
        rows: list[torch.Tensor] | None = None,
    ) -> None:
        """Copy a narrowed model's parameter ``values`` (or their ``rows``) for ``groups``
        (the whole problem's numbering) into the whole model's parameters."""
        whole = self.model
        groups = groups.to(next(whole.parameters()).device)
        picks: list[torch.Tensor | None] = list(rows) if rows is not None else [None] * len(values)
        with torch.no_grad():
            for target, owner, value, picked in zip(whole.parameters(), whole.parameter_groups(),
                                                    values, picks, strict=True):  # fmt: skip
                target[torch.isin(owner, groups)] = value if picked is None else value[picked]
