"""Conversion of every accepted input form to one canonical form, with clear errors.

Accepted collections of series (time-major, see the input-shapes table in the docs):

* ``(n_series, n_timepoints)`` -- univariate, treated as ``(n, T, 1)``;
* ``(n, T, *point_shape)`` -- e.g. ``(n, T, d)``, ``(n, T, 4)`` quaternions,
  ``(n, T, k, k)`` SPD matrices, ``(n, T, 7)`` poses;
* a list of ``(T_i,)`` or ``(T_i, *point_shape)`` arrays of unequal lengths.

The canonical form is a :class:`SeriesCollection`: a float64 array padded to the longest
series by repeating each series' last sample (so padding stays on the manifold), the true
lengths, and the manifold resolved against the data.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from types import GeneratorType
from typing import Any

import numpy as np
from scipy.sparse import issparse
from sklearn.utils import check_array

from ..manifolds import Manifold, get_manifold
from ..manifolds._check import check_on_data

#: Relative tolerance used to decide whether data lie on the manifold.
DEFAULT_ATOL = 1e-6


@dataclass(frozen=True, eq=False)
class SeriesCollection:
    """Validated series: ``data`` (n, T_max, *point_shape), ``lengths`` (n,), ``manifold``."""

    data: np.ndarray
    lengths: np.ndarray
    manifold: Manifold

    @property
    def n_series(self) -> int:
        return self.data.shape[0]

    @property
    def max_length(self) -> int:
        return self.data.shape[1]

    @property
    def equal_length(self) -> bool:
        return bool(np.all(self.lengths == self.max_length))

    def series(self, i: int) -> np.ndarray:
        """The ``i``-th series without padding.

        Parameters
        ----------
        i : int

        Returns
        -------
        series : ndarray of shape (T_i, *point_shape)
        """
        return self.data[i, : self.lengths[i]]

    def subset(self, index: Any) -> SeriesCollection:
        """The series ``index`` (int array or mask), padding cut to their longest.

        Parameters
        ----------
        index : array-like of int or bool

        Returns
        -------
        SeriesCollection
        """
        index = np.flatnonzero(index) if np.asarray(index).dtype == bool else np.asarray(index)
        lengths = self.lengths[index]
        return SeriesCollection(
            data=self.data[index, : int(lengths.max())], lengths=lengths, manifold=self.manifold
        )


def _expected_layout(n_lead: int, point_shape: tuple[int, ...]) -> str:
    lead = "(n_series, n_timepoints" if n_lead == 2 else "(n_timepoints"
    body = ", ".join(str(s) for s in point_shape)
    text = f"{lead}, {body})"
    if point_shape == (1,):
        text += f" or {lead})"
    return text


def _is_tensor(x: Any) -> bool:
    return hasattr(x, "detach") and hasattr(x, "cpu")


def _to_float_array(x: Any, name: str) -> np.ndarray:
    if _is_tensor(x):
        x = x.detach().cpu().numpy()
    try:
        arr = np.asarray(x)
    except ValueError as exc:  # ragged nested lists
        raise ValueError(
            f"{name} could not be read as an array ({exc}); pass unequal-length series as a "
            "list of arrays"
        ) from None
    if arr.dtype == object:
        raise TypeError(f"{name} must contain numbers, got an object array")
    if arr.dtype.kind not in "biuf":
        raise TypeError(f"{name} must be numeric, got dtype {arr.dtype}")
    return arr.astype(np.float64, copy=False)


def check_series(
    x: Any,
    manifold: str | Manifold = "euclidean",
    *,
    name: str = "x",
    min_length: int = 2,
    atol: float = DEFAULT_ATOL,
) -> tuple[np.ndarray, Manifold]:
    """Validate one series ``(T,)`` or ``(T, *point_shape)``.

    Parameters
    ----------
    x : array-like of shape (T,) or (T, *point_shape)
    manifold : str or Manifold, default="euclidean"
        Name (dimension inferred from the data) or manifold object.
    name : str, default="x"
        Name used in error messages.
    min_length : int, default=2
        Shortest series accepted.
    atol : float, default=1e-6
        Tolerance for the manifold constraint.

    Returns
    -------
    series : ndarray of shape (T, *point_shape), float64
    manifold : Manifold resolved against the data
    """
    arr = _to_float_array(x, name)
    if arr.ndim == 0:
        raise ValueError(f"{name} must be a series, got a scalar")
    manifold_obj = _resolve(manifold, arr, n_lead=1, name=name)
    if arr.ndim == 1 and manifold_obj.point_shape == (1,):
        arr = arr[:, None]
    _check_content([arr], manifold_obj, name, min_length, atol, single=True)
    return arr, manifold_obj


def check_series_collection(
    X: Any,
    manifold: str | Manifold = "euclidean",
    *,
    name: str = "X",
    min_length: int = 2,
    min_series: int = 1,
    atol: float = DEFAULT_ATOL,
) -> SeriesCollection:
    """Validate a collection of series and convert it to a :class:`SeriesCollection`.

    Parameters
    ----------
    X : array-like or list of array-like
        ``(n, T)``, ``(n, T, *point_shape)`` or a list of ``(T_i, *point_shape)`` series.
    manifold : str or Manifold, default="euclidean"
        Name (dimension inferred from the data) or manifold object.
    name : str, default="X"
        Name used in error messages.
    min_length : int, default=2
        Shortest series accepted.
    min_series : int, default=1
        Smallest number of series accepted.
    atol : float, default=1e-6
        Tolerance for the manifold constraint.

    Raises
    ------
    ValueError
        For empty input, wrong number of axes, NaN or infinite values, series shorter than
        ``min_length`` and points off the manifold (naming series and time index).
    TypeError
        For non-numeric input.
    """
    if isinstance(X, SeriesCollection):  # already validated
        if isinstance(manifold, Manifold) and manifold != X.manifold:
            raise ValueError(f"{name} holds points of {X.manifold!r}, not of {manifold!r}")
        if X.n_series < min_series or int(X.lengths.min()) < min_length:
            raise ValueError(
                f"{name} needs at least {min_series} series of at least {min_length} time points"
            )
        return X
    _reject_unsupported_containers(X, name)
    if isinstance(X, np.ndarray) and X.dtype == object and X.ndim == 1:
        X = list(X)  # np.array(list_of_series, dtype=object): the list it was made from
    if isinstance(X, (list, tuple)) and (len(X) == 0 or not _is_rectangular(X)):
        if len(X) == 0:
            raise ValueError(f"{name} is empty: at least {min_series} series are needed")
        series = [_to_float_array(s, f"{name}[{i}]") for i, s in enumerate(X)]
        ndims = {s.ndim for s in series}
        if 0 in ndims:
            raise ValueError(f"each series of {name} must be an array, got a scalar")
        ref = max(series, key=lambda s: s.ndim)
        manifold_obj = _resolve(manifold, ref, n_lead=1, name=f"{name}[i]")
        for i, s in enumerate(series):
            if s.ndim == 1 and manifold_obj.point_shape == (1,):
                series[i] = s[:, None]
            elif s.shape[1:] != manifold_obj.point_shape:
                raise ValueError(
                    f"{name}[{i}] has shape {s.shape}; with {manifold_obj!r} every series must be "
                    f"{_expected_layout(1, manifold_obj.point_shape)}."
                )
    else:
        if _is_tensor(X):
            X = _to_float_array(X, name)
        # scikit-learn's checks and messages for sparse, complex, object, empty and 1-D input
        ndim = 2 if issparse(X) else np.asarray(X).ndim
        try:
            arr = check_array(
                X,
                accept_sparse=False,
                dtype="numeric",
                ensure_all_finite=False,
                allow_nd=True,
                ensure_min_samples=max(1, min_series),
                ensure_min_features=max(1, min_length) if ndim == 2 else 1,
                input_name=name,
            ).astype(np.float64, copy=False)
        except ValueError as exc:  # say it in our words first, keep scikit-learn's after
            message = str(exc)
            if "feature(s)" in message:
                message = f"{name} has too few time points per series: {message}"
            elif "sample(s)" in message:
                message = f"{name} has too few series: {message}"
            else:
                raise
            raise ValueError(
                f"{message} (a 'feature' is a time point and a 'sample' a series here)"
            ) from None
        _reject_channels_first(arr, manifold, name)
        manifold_obj = _resolve(manifold, arr, n_lead=2, name=name)
        if arr.ndim == 2 and manifold_obj.point_shape == (1,):
            arr = arr[:, :, None]
        series = list(arr)
    if len(series) < min_series:
        raise ValueError(f"{name} holds {len(series)} series; at least {min_series} are needed")
    _check_content(series, manifold_obj, name, min_length, atol)
    lengths = np.array([len(s) for s in series], dtype=np.int64)
    t_max = int(lengths.max())
    data = np.empty((len(series), t_max, *manifold_obj.point_shape), dtype=np.float64)
    for i, s in enumerate(series):
        data[i, : len(s)] = s
        data[i, len(s) :] = s[-1]
    return SeriesCollection(data=data, lengths=lengths, manifold=manifold_obj)


def _reject_unsupported_containers(X: Any, name: str) -> None:
    """Clear errors for generators and sktime's nested DataFrames."""
    if isinstance(X, (Iterator, GeneratorType)):
        raise TypeError(
            f"{name} is a {type(X).__name__}; pass an array or a list of series "
            f"(e.g. list({name}))"
        )
    dtypes = getattr(X, "dtypes", None)
    nested = dtypes is not None and any(np.dtype(d).kind == "O" for d in np.ravel(dtypes))
    if nested and hasattr(X, "iloc"):
        raise TypeError(
            f"{name} is a DataFrame with object cells (sktime's nested layout?); convert it "
            "to aeon's 3-D array (n_cases, n_channels, n_timepoints), e.g. with "
            "aeon.utils.conversion.convert_collection(X, 'numpy3D'), then to sk_rtw's layout "
            "with sk_rtw.utils.from_aeon"
        )


#: How to convert aeon data, for error messages.
AEON_HINT = (
    "sk_rtw is time-major, (n_series, n_timepoints[, n_channels]); aeon's channels-first "
    "arrays (n_cases, n_channels, n_timepoints) convert with sk_rtw.utils.from_aeon(X), "
    "or take sk_rtw.aeon.RTWClassifier, which reads aeon's layouts as they are"
)


def _reject_channels_first(arr: np.ndarray, manifold: Any, name: str) -> None:
    """A 3-D array read as Euclidean with fewer time points than channels is ambiguous.

    aeon's ``(n_cases, n_channels, n_timepoints)`` would silently become series of
    ``n_channels`` time points in R^n_timepoints. With a manifold given by name, such an
    array is refused with the conversion to use; a ``Euclidean(d)`` object states the
    layout and is accepted.
    """
    if not (isinstance(manifold, str) and manifold.lower() == "euclidean" and arr.ndim == 3):
        return
    n_time, n_channels = arr.shape[1], arr.shape[2]
    if n_time < n_channels:
        raise ValueError(
            f"{name} has shape {arr.shape}: read time-major that is {n_time} time point(s) "
            f"of {n_channels} channels, which looks like aeon's channels-first layout "
            f"(n_cases={arr.shape[0]}, n_channels={n_time}, n_timepoints={n_channels}). "
            f"{AEON_HINT}. If the layout really is (n, T, d) with T < d, pass "
            f"manifold=Euclidean({n_channels})."
        )


def _is_rectangular(X: Sequence) -> bool:
    try:
        arr = np.asarray(X)
    except ValueError:
        return False
    return arr.dtype != object


def _resolve(manifold: str | Manifold, arr: np.ndarray, n_lead: int, name: str) -> Manifold:
    """Resolve the manifold against the trailing (point) axes of ``arr``."""
    if isinstance(manifold, Manifold):
        ps = manifold.point_shape
        if arr.shape[n_lead:] == ps or (ps == (1,) and arr.ndim == n_lead):
            return manifold
        raise ValueError(
            f"{name} has shape {arr.shape}; with {manifold!r} expected "
            f"{_expected_layout(n_lead, ps)}."
        )
    if not isinstance(manifold, str):
        raise TypeError(
            f"manifold must be a name or a Manifold object, got {type(manifold).__name__}"
        )
    if arr.ndim < n_lead:
        raise ValueError(f"{name} has shape {arr.shape}: too few axes")
    point_shape = tuple(arr.shape[n_lead:])
    if manifold.lower() == "euclidean" and len(point_shape) > 1:
        layout = (
            "(n_series, n_timepoints) or (n_series, n_timepoints, n_features)"
            if n_lead == 2
            else "(n_timepoints,) or (n_timepoints, n_features)"
        )
        raise ValueError(
            f"{name} has {arr.ndim} axes, shape {arr.shape}; Euclidean data must be {layout}"
        )
    return get_manifold(manifold, point_shape=point_shape)


def _check_content(
    series: list[np.ndarray],
    manifold: Manifold,
    name: str,
    min_length: int,
    atol: float,
    single: bool = False,
) -> None:
    for i, s in enumerate(series):
        label = name if single else f"{name}[{i}]"
        if len(s) < min_length:
            raise ValueError(f"{label} has {len(s)} time points; at least {min_length} are needed")
        finite = np.isfinite(s.reshape(len(s), -1)).all(axis=1)
        if not finite.all():
            t = int(np.argmin(finite))
            where = f"{name}[{t}]" if single else f"{name}[{i}] at time index {t}"
            raise ValueError(
                f"{where} contains NaN or infinite values; missing values are not supported "
                "(impute or drop them first)"
            )
    check_on_data(manifold, series, name)
    stacked_label = name if single else f"{name}[series, time]"
    if single:
        manifold.validate(series[0], atol=atol, name=stacked_label)
        return
    lengths = {len(s) for s in series}
    if len(lengths) == 1:
        manifold.validate(np.stack(series), atol=atol, name=name)
    else:
        for i, s in enumerate(series):
            try:
                manifold.validate(s, atol=atol, name=f"{name}[{i}]")
            except ValueError as exc:
                raise ValueError(str(exc).replace(f"{name}[{i}][", f"{name}[{i}, ")) from None
