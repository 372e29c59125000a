"""Adam for the engine: torch's fused Adam kernel, called without ``torch.optim``.

``torch.optim.Adam(parameters, lr=..., fused=True)`` runs one fused kernel per device and
dtype; its ``Optimizer`` wrappers import ``torch._dynamo`` on their first call, which took
1.6 s of a fresh process's first :func:`sk_rtw.align` (of 2.0 s for 8 series of 50
samples) and again in every worker of a parallel grid search. :class:`FusedAdam` calls
the same kernel with the same state (first and second moments, a float32 step counter on
the parameters' device), so the updates are bit for bit those of ``torch.optim.Adam``
(tested), at no import cost.

The kernel runs on the CPU from torch 2.4 on (CUDA since 2.0), the floor that
``pyproject.toml`` declares; an older torch is refused at import with that message
rather than with the dispatcher's error at the first epoch.
"""

from __future__ import annotations

from collections.abc import Sequence

import torch

#: The oldest torch whose fused Adam kernel has a CPU implementation.
MIN_TORCH = (2, 4)


def _release(version: str) -> tuple[int, int]:
    """``(major, minor)`` of a torch version string (``"2.13.0+cpu"`` -> ``(2, 13)``)."""
    major, minor = version.split("+")[0].split(".")[:2]
    return int(major), int("".join(c for c in minor if c.isdigit()) or 0)


if _release(torch.__version__) < MIN_TORCH:
    raise ImportError(
        f"sk_rtw needs torch>={MIN_TORCH[0]}.{MIN_TORCH[1]} (its fused Adam kernel on the "
        f"CPU); this is torch {torch.__version__}: pip install 'torch>=2.4'"
    )


class FusedAdam:
    """Adam (Kingma and Ba, 2015) over ``parameters``: torch's fused update, lazily
    initialised state, ``zero_grad`` setting gradients to None.

    Parameters
    ----------
    parameters : sequence of Tensor
        Leaf tensors with ``requires_grad``; one without a gradient at a step is skipped.
    lr : float
        Step size.
    betas : tuple of float, default=(0.9, 0.999)
        Decay rates of the first and second moment estimates.
    eps : float, default=1e-8
        Added to the denominator.
    """

    def __init__(
        self,
        parameters: Sequence[torch.Tensor],
        lr: float,
        betas: tuple[float, float] = (0.9, 0.999),
        eps: float = 1e-8,
    ) -> None:
        self.parameters = list(parameters)
        self.lr = float(lr)
        self.betas = (float(betas[0]), float(betas[1]))
        self.eps = float(eps)
        self._state: dict[int, tuple[torch.Tensor, torch.Tensor, torch.Tensor]] = {}

    def narrow(
        self, parameters: Sequence[torch.Tensor], rows: Sequence[torch.Tensor]
    ) -> FusedAdam:
        """Adam over ``parameters``, the ``rows`` of this one's parameters (indices along
        their leading axis, in order), with those rows' moments and the same step count."""
        other = FusedAdam(parameters, self.lr, self.betas, self.eps)
        for index, (average, square, steps) in self._state.items():
            picked = rows[index]
            other._state[index] = (average[picked].clone(), square[picked].clone(), steps.clone())
        return other

    def zero_grad(self, set_to_none: bool = True) -> None:
        """Forget the gradients (set to None, as ``torch.optim``'s default)."""
        for parameter in self.parameters:
            if set_to_none:
                parameter.grad = None
            elif parameter.grad is not None:
                parameter.grad.zero_()

    @torch.no_grad()
    def step(self) -> None:
        """One Adam update of every parameter that has a gradient."""
        groups: dict[tuple[torch.device, torch.dtype], list[tuple[torch.Tensor, ...]]] = {}
        for index, parameter in enumerate(self.parameters):
            if parameter.grad is None:
                continue
            state = self._state.get(index)
            if state is None:
                state = (
                    torch.zeros_like(parameter, memory_format=torch.preserve_format),
                    torch.zeros_like(parameter, memory_format=torch.preserve_format),
                    torch.zeros((), dtype=torch.float32, device=parameter.device),
                )
                self._state[index] = state
            key = (parameter.device, parameter.dtype)
            groups.setdefault(key, []).append((parameter, parameter.grad, *state))
        beta1, beta2 = self.betas
        for members in groups.values():
            params, grads, averages, squares, steps = (list(t) for t in zip(*members, strict=True))
            torch._foreach_add_(steps, 1)
            torch._fused_adam_(
                params, grads, averages, squares, [], steps, amsgrad=False, lr=self.lr,
                beta1=beta1, beta2=beta2, weight_decay=0.0, eps=self.eps, maximize=False,
                grad_scale=None, found_inf=None,
            )  # fmt: skip
