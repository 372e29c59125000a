"""Shared, seeded fixtures."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import torch

from sk_rtw.manifolds import SPD, Euclidean, Product, Quaternion, Sphere

torch.set_default_dtype(torch.float64)

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


def quick(name: str = "rtw", **settings):
    """A method object for fast tests: 2 epochs, a width-8 network where there is one."""
    from benchmarks._shared import method_object

    return method_object(name, **{"n_epochs": 2, "hidden_size": 8, **settings})
