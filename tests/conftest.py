"""Shared, seeded fixtures."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
import torch

from sk_rtw.align import tangent_sinc_interpolate
from sk_rtw.manifolds import SPD, Euclidean, Product, Quaternion, Sphere
from sk_rtw.methods import get_method

torch.set_default_dtype(torch.float64)

#: Checked by mypy, not run (``--doctest-modules`` would import it).
collect_ignore = ["typing"]

#: One instance of every kind of space, used by the contract tests.
MANIFOLDS = [
    Euclidean(1),
    Euclidean(3),
    Sphere(1),
    Sphere(2),
    Sphere(5),
    Quaternion(),
    SPD(2),
    SPD(3),
    Product((Euclidean(3), Quaternion())),
]

#: The curved ones (log and exp are not subtraction and addition).
CURVED = [m for m in MANIFOLDS if not m.is_flat]

SHARED = Path(__file__).resolve().parents[1].parent / "shared"
UCR_DIR = SHARED / "ucr"


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)


def manifold_id(m) -> str:
    return repr(m)


#: The settings of :func:`quick`, for the methods that have them.
QUICK = {"n_epochs": 2, "hidden_size": 8}


def quick(name: str = "rtw", **settings):
    """A method object for fast tests: 2 epochs and a width-8 network where the method has
    them; ``settings`` must be the method's own (``set_params`` refuses any other)."""
    method = get_method(name)
    own = method.get_params(deep=False)
    return method.set_params(**{**{k: v for k, v in QUICK.items() if k in own}, **settings})


@dataclass(frozen=True)
class CurvedLookingEuclidean(Euclidean):
    """Euclidean geometry that does not declare itself flat: forces the general path."""

    is_flat = False


def interpolate(manifold, x, warps, window=10, refinements=0):
    data = torch.as_tensor(np.asarray(x))[None]
    w = torch.as_tensor(np.asarray(warps), dtype=torch.float64)[None]
    return tangent_sinc_interpolate(
        manifold, data, torch.tensor([len(x)]), w, window, refinements
    )[0].numpy()


def rlasa_in_own_frames(space: str, every: int):
    """R-LASA demonstrations ``(shapes, 4, T, *point)`` of every ``every``-th shape (every
    25th sample), their shape names, and the same demonstrations each in a world frame
    of its own (the R-LASA benchmark's ``--frames``, seed 0); the test is skipped
    without the shared data."""
    from benchmarks.manifold_classification import in_own_frames, load
    from benchmarks.paper._data import data_dir

    try:
        root = data_dir(None)
    except FileNotFoundError:
        pytest.skip("no shared demonstration data")
    demos, shapes = load(space, root, 25)
    demos, shapes = demos[::every], shapes[::every]
    return demos, shapes, in_own_frames(demos, space, 0)
