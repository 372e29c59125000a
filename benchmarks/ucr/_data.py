"""Loading UCR datasets through aeon and converting them to sk_rtw's time-major layout.

aeon returns channels-first data: an array ``(n_cases, n_channels, n_timepoints)`` or, for
unequal-length datasets, a list of ``(n_channels, T_i)`` arrays. :func:`sk_rtw.utils.from_aeon`
turns it into ``(n_cases, T)`` for univariate data, ``(n_cases, T, n_channels)`` otherwise,
or a list of ``(T_i,)`` / ``(T_i, n_channels)`` series.

Nothing is downloaded: a dataset is available when it is in the data directory (aeon's
local layout) or bundled with aeon; :func:`check_available` says which are not.

Missing values (NaN) are filled by linear interpolation along time, the ends by the
nearest observed value; a series with no observed value is dropped (and reported).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from sk_rtw.utils import from_aeon

#: Datasets that aeon ships inside its package (usable with no data directory).
AEON_BUNDLED = ("ArrowHead", "GunPoint", "ItalyPowerDemand")
ENV_DATA_DIR = "SK_RTW_UCR_DIR"


@dataclass
class Split:
    X: np.ndarray | list[np.ndarray]
    y: np.ndarray
    lengths: np.ndarray
    notes: list[str] = field(default_factory=list)


def default_data_dir() -> str | None:
    """``$SK_RTW_UCR_DIR`` if set, else None (aeon's own location and bundled data)."""
    return os.environ.get(ENV_DATA_DIR) or None


def available_datasets(data_dir: str | None) -> list[str]:
    """Datasets in aeon's local layout ``DIR/<name>/<name>_TRAIN.ts`` plus aeon's own."""
    names = set(AEON_BUNDLED)
    if data_dir and Path(data_dir).is_dir():
        names.update(
            p.name for p in Path(data_dir).iterdir() if (p / f"{p.name}_TRAIN.ts").is_file()
        )
    return sorted(names)


class DatasetUnavailable(LookupError):
    """A dataset that is neither in the data directory nor bundled with aeon."""


def aeon_shipped(name: str) -> bool:
    """Whether aeon's package holds the classification dataset ``name`` (any of its own)."""
    try:
        import aeon.datasets
    except ImportError:
        return False
    folder = Path(aeon.datasets.__file__).parent / "data" / name
    return (folder / f"{name}_TRAIN.ts").is_file()


def check_available(name: str, data_dir: str | None) -> None:
    """Raise :class:`DatasetUnavailable` (with what to do) unless ``name`` can be loaded."""
    if name in AEON_BUNDLED or aeon_shipped(name):
        return
    if data_dir and (Path(data_dir) / name / f"{name}_TRAIN.ts").is_file():
        return
    where = f"in {data_dir}" if data_dir else f"(no --data-dir given, ${ENV_DATA_DIR} unset)"
    raise DatasetUnavailable(
        f"dataset {name!r} is not available offline {where}: put it there in aeon's local "
        f"layout ({name}/{name}_TRAIN.ts and _TEST.ts) or choose from "
        f"{', '.join(available_datasets(data_dir))}; nothing is downloaded"
    )


def _fill_missing(series: np.ndarray) -> np.ndarray | None:
    """Interpolate NaNs along time (axis 0); None if a channel has no observed value."""
    series = np.array(series, dtype=np.float64)
    flat = series.reshape(len(series), -1)
    t = np.arange(len(series))
    for c in range(flat.shape[1]):
        observed = np.isfinite(flat[:, c])
        if not observed.any():
            return None
        if not observed.all():
            flat[:, c] = np.interp(t, t[observed], flat[observed, c])
    return flat.reshape(series.shape)


def load_split(name: str, split: str, data_dir: str | None) -> Split:
    from aeon.datasets import load_classification

    check_available(name, data_dir)
    path = data_dir if data_dir and (Path(data_dir) / name).is_dir() else None
    X, y = load_classification(name, split=split, extract_path=path)
    series, labels, notes = [], [], []
    n_filled = 0
    for i, s in enumerate(from_aeon(list(X))):  # (T,) or (T, channels) each
        if np.isnan(s).any():
            s = _fill_missing(s)
            if s is None:
                notes.append(f"{split} series {i} has no observed value and was dropped")
                continue
            n_filled += 1
        series.append(s)
        labels.append(y[i])
    if n_filled:
        notes.append(
            f"{n_filled} {split} series had missing values, filled by linear "
            "interpolation along time"
        )
    lengths = np.array([len(s) for s in series])
    X_out = np.stack(series) if len(set(lengths.tolist())) == 1 else series
    return Split(X=X_out, y=np.asarray(labels), lengths=lengths, notes=notes)


def subsample_per_class(split: Split, max_per_class: int | None, seed: int) -> np.ndarray:
    """Indices of at most ``max_per_class`` series per class (seeded, sorted)."""
    index = np.arange(len(split.y))
    if not max_per_class:
        return index
    rng = np.random.default_rng(seed)
    keep = []
    for label in np.unique(split.y):
        members = index[split.y == label]
        if len(members) > max_per_class:
            members = rng.choice(members, max_per_class, replace=False)
        keep.extend(members.tolist())
    return np.sort(np.array(keep))


def take(split: Split, index: np.ndarray) -> Split:
    X = split.X[index] if isinstance(split.X, np.ndarray) else [split.X[i] for i in index]
    return Split(X=X, y=split.y[index], lengths=split.lengths[index], notes=split.notes)


def resample_split(train: Split, test: Split, resample: int) -> tuple[Split, Split]:
    """The archive's split (``resample`` 0) or its stratified resample ``resample``.

    aeon's and tsml-eval's resampling (``stratified_resample_data``, seeded by the
    resample number): train and test pooled, every class's cases shuffled, and the first
    as many as the class has in the archive's training split go to training, so class
    counts stay those of the archive. Works on the loaded splits (after missing values
    were filled), with aeon's own index function, so that a resample here is the same
    cases as resample ``resample`` of a tsml-eval experiment.
    """
    if resample == 0:
        return train, test
    from aeon.benchmarking.resampling import stratified_resample_data_indices

    train_index, test_index = stratified_resample_data_indices(
        train.y, test.y, random_state=resample
    )
    pooled = _pool(train, test)
    return take(pooled, train_index), take(pooled, test_index)


def _pool(train: Split, test: Split) -> Split:
    if (
        isinstance(train.X, np.ndarray)
        and isinstance(test.X, np.ndarray)
        and (train.X.shape[1:] == test.X.shape[1:])
    ):
        X = np.concatenate([train.X, test.X])
    else:
        X = [*train.X, *test.X]
    return Split(
        X=X,
        y=np.concatenate([train.y, test.y]),
        lengths=np.concatenate([train.lengths, test.lengths]),
        notes=train.notes + test.notes,
    )
