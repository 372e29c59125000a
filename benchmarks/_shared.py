"""What every benchmark script starts with: argument types, output checks, method objects,
smooth test series.

Each script runs on its own (``python benchmarks/ucr/run.py``); its one start line puts
the repository on ``sys.path`` (Python looks only in the script's folder), then
everything the scripts share comes from here. Command-line values are checked by
argparse before any work, output paths before the first result is computed.
"""

from __future__ import annotations

import argparse
import os
import platform
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import torch

from sk_rtw.methods import AveragingMethod, get_method

ROOT = Path(__file__).resolve().parents[1]


def _number(kind, minimum, strict: bool, what: str):
    def parse(text: str):
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not {what}") from None
        if value != value or (value <= minimum if strict else value < minimum):
            raise argparse.ArgumentTypeError(f"{text!r} is not {what}")
        return value

    parse.__name__ = what  # argparse names the type in its messages
    return parse


#: argparse types: checked on the command line, before any work.
positive_int = _number(int, 0, True, "a positive integer")
non_negative_int = _number(int, 0, False, "an integer >= 0")
output_length = _number(int, 2, False, "an integer >= 2")
positive_float = _number(float, 0.0, True, "a positive number")


def job_count(text: str) -> int:
    """argparse type: joblib's n_jobs, a non-zero integer (-1: every core)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if value == 0:
        raise argparse.ArgumentTypeError(
            "0 jobs would run nothing: use 1, N, or -1 for every core"
        )
    return value


def existing_directory(text: str) -> str:
    """argparse type: a folder that exists (data is never downloaded)."""
    if not Path(text).is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} is not an existing folder")
    return text


def published_file(text: str) -> Path:
    """argparse type: a published-results CSV that exists and has a ``dataset`` column."""
    path = Path(text)
    if not path.is_file():
        raise argparse.ArgumentTypeError(f"{text!r} is not an existing file")
    with path.open(newline="") as handle:
        header = handle.readline().strip().split(",")
    if "dataset" not in header:
        raise argparse.ArgumentTypeError(
            f"{text!r} has no 'dataset' column: expected a published_results.csv"
        )
    return path


def check_writable(path: str | Path, *, directory: bool = False) -> Path:
    """``path`` (a file, or a folder with ``directory=True``) can be written: its folder
    exists or can be made, and a file can be created there. Raises ``SystemExit`` with
    the reason, before any work."""
    path = Path(path)
    folder = path if directory else path.parent
    if (directory and path.exists() and not path.is_dir()) or (not directory and path.is_dir()):
        raise SystemExit(f"error: {path} exists and is not a {'folder' if directory else 'file'}")
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=folder, prefix=".write-check-"):
            pass
    except OSError as exc:
        raise SystemExit(f"error: cannot write {path}: {exc.strerror or exc}") from None
    return path


def method_object(name: str, **settings: Any) -> AveragingMethod:
    """The method ``name`` with those of ``settings`` it has (``n_epochs`` means nothing to
    DBA, so a script can pass its engine settings to every method)."""
    method = get_method(name)
    own = method.get_params(deep=False)
    return method.set_params(**{k: v for k, v in settings.items() if k in own})


def machine(device: str = "cpu") -> str:
    """One line describing where the numbers were measured."""
    return (
        f"{platform.machine()}, {os.cpu_count()} cores, torch {torch.__version__}, "
        f"Python {platform.python_version()}, device {device}"
    )


def best_time(call: Callable[[], object], repeats: int, *, warm_up: bool = False) -> float:
    """The least wall time of ``repeats`` calls (after one untimed call if ``warm_up``)."""
    if warm_up:
        call()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return min(times)


def smooth_series(manifold, n_series: int, length: int, seed: int = 0) -> np.ndarray:
    """Series that move smoothly on ``manifold``: a random start walked along random
    tangent steps (``exp`` of a small step at every sample)."""
    rng = np.random.default_rng(seed)
    points = manifold.random_point(n_series, random_state=rng)
    out = np.empty((n_series, length, *manifold.point_shape))
    for t in range(length):
        out[:, t] = points
        step = np.stack([manifold.random_tangent(p, 0.05, random_state=rng) for p in points])
        points = np.asarray(manifold.exp(points, step))
    return out
