"""Bridge between numpy and torch for the geometry.

Every geometric operation is written once, in torch, so that it is differentiable. Public
methods accept numpy arrays as well: they are converted to float64 tensors on the way in
and back to numpy on the way out ("numpy in, numpy out; torch in, torch out").
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

import numpy as np
import torch


def to_tensor(x: Any, like: torch.Tensor | None = None) -> torch.Tensor:
    """Convert ``x`` to a floating tensor (float64 unless ``x`` already is a float tensor)."""
    if isinstance(x, torch.Tensor):
        if not x.is_floating_point():
            x = x.to(torch.float64)
        if like is not None and (x.dtype != like.dtype or x.device != like.device):
            x = x.to(dtype=like.dtype, device=like.device)
        return x
    arr = np.ascontiguousarray(x)
    if arr.dtype.kind not in "f":
        arr = arr.astype(np.float64)
    if not arr.flags.writeable:  # torch shares memory only with writable arrays
        arr = arr.copy()
    t = torch.from_numpy(arr)
    if like is not None:
        t = t.to(dtype=like.dtype, device=like.device)
    return t


def numpy_compatible(method: Callable) -> Callable:
    """Decorate a torch method so that numpy (or list) inputs give numpy outputs.

    All positional array arguments are converted; if any of them is a tensor, the
    computation stays in torch and the result is returned as a tensor.
    """

    @functools.wraps(method)
    def wrapper(self, *arrays, **kwargs):
        any_tensor = any(isinstance(a, torch.Tensor) for a in arrays)
        ref = next((a for a in arrays if isinstance(a, torch.Tensor)), None)
        if ref is not None and not ref.is_floating_point():
            ref = None
        converted = [a if a is None else to_tensor(a, like=ref) for a in arrays]
        if not any_tensor:
            converted = [a if a is None else a.to(torch.float64) for a in converted]
        out = method(self, *converted, **kwargs)
        if any_tensor:
            return out
        return _to_numpy(out)

    return wrapper


def _to_numpy(out: Any) -> Any:
    if isinstance(out, torch.Tensor):
        return out.detach().cpu().numpy()
    if isinstance(out, tuple):
        return tuple(_to_numpy(o) for o in out)
    return out


def sum_last(x: torch.Tensor, n_axes: int = 1, keepdim: bool = False) -> torch.Tensor:
    """Sum over the last ``n_axes`` axes, as a matrix-vector product with ones.

    Same value as ``x.sum(dim=(-n_axes, ..., -1))``, but torch's CPU reductions over a
    short last axis (the 2 to 16 coordinates of a point) are 5 to 15 times slower than a
    product with a ones vector, and the geometry does them on every sample of every epoch.
    """
    if n_axes > 1:
        x = x.reshape(*x.shape[: x.ndim - n_axes], -1)
    out = x @ torch.ones(x.shape[-1], dtype=x.dtype, device=x.device)
    return out.unsqueeze(-1) if keepdim else out


def inner(a: torch.Tensor, b: torch.Tensor, keepdim: bool = False) -> torch.Tensor:
    """Inner product over the last axis, broadcast over the others."""
    return sum_last(a * b, keepdim=keepdim)


def safe_norm(v: torch.Tensor, dim: int | tuple[int, ...] = -1) -> torch.Tensor:
    """Euclidean norm whose gradient at zero is zero instead of NaN (NaN stays NaN)."""
    if dim == -1 and v.shape[-1] == 1:
        return v.abs().squeeze(-1)  # exact at any magnitude
    if dim == -1:
        sq = sum_last(v * v)
    elif dim == (-2, -1):
        sq = sum_last(v * v, n_axes=2)
    else:
        sq = (v * v).sum(dim=dim)
    return safe_sqrt(sq)


def safe_sqrt(sq: torch.Tensor) -> torch.Tensor:
    """Square root of non-negative ``sq`` whose gradient at zero is zero instead of
    infinite (NaN stays NaN)."""
    positive = sq > 0
    root = torch.sqrt(torch.where(positive, sq, torch.ones_like(sq)))
    return torch.where(positive, root, sq * 0.0)  # 0 at 0, NaN for NaN
