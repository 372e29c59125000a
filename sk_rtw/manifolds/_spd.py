"""Symmetric positive definite matrices with the affine-invariant metric."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import torch

from .._backend import safe_norm
from . import _spd2
from ._base import EXTREME_EXPONENT, Manifold, power_of_two_scale
from ._euclidean import Euclidean, _check_dim
from ._mean import group_expand
from ._symmetric import distinct, eigenvalues, sym, symmetric_function, symmetric_functions

#: Largest condition number of a non-diagonal SPD matrix accepted as a point (float64
#: keeps the smallest eigenvalue to about ``MAX_CONDITION * 2.2e-16`` relative accuracy).
MAX_CONDITION = 1e13

#: The axes a step's whitened logarithm is given in (:attr:`SPD.velocity_frame`).
VELOCITY_FRAMES = ("eigen", "world")


@dataclass(frozen=True)
class SPD(Manifold):
    """SPD(k): symmetric positive definite ``k x k`` matrices, affine-invariant metric.

    ``Exp_P(V) = P^½ expm(P^-½ V P^-½) P^½``, ``Log_P(X) = P^½ logm(P^-½ X P^-½) P^½`` and
    ``dist(P, X) = ||logm(P^-½ X P^-½)||_F``. For ``k = 2`` all three are closed forms in
    the two eigenvalues of ``P^-1 X`` (no eigendecomposition); for larger ``k`` every
    matrix function goes through one symmetric eigendecomposition (shared by ``P^½`` and
    ``P^-½``, once per distinct tangent point) and distances through eigenvalues only:
    those of ``L^-1 X L^-T`` (``P = L L^T``) and of the reverse pair, each log-eigenvalue
    from the side that holds it to full relative accuracy (float64's whitened matrix
    loses its small eigenvalues: two points of condition 1e10 gave NaN). Pairs of
    diagonal points take the maps and the distance entry by entry, exact at any spread.
    Gradients stay finite for repeated eigenvalues (``P = X``).

    Parameters
    ----------
    dim : int, default=2
        Matrix size ``k``; points have shape ``(k, k)``.
    velocity_frame : {"eigen", "world"}, default="eigen"
        The axes of :meth:`velocity` (a series' tangent velocity). ``"eigen"``: the
        step's whitened logarithm ``logm(P^-½ X P^-½)`` in the eigenbasis of ``P``
        (eigenvalues ascending), the SPD form of a body frame: a congruence of the whole
        series by a rotation ``R X R^T`` (a demonstration recorded in another world
        frame) leaves it unchanged. ``"world"``: the same matrix in the ambient axes,
        turned by ``R`` with the series. Both keep :meth:`dist` as the norm. See
        :meth:`velocity` for how the eigenvectors' signs are fixed.
    """

    dim: int = 2
    velocity_frame: str = "eigen"
    name = "spd"

    def __post_init__(self):
        _check_dim(self.dim, "SPD", minimum=1)
        if self.velocity_frame not in VELOCITY_FRAMES:
            raise ValueError(
                f"velocity_frame must be one of {VELOCITY_FRAMES}, got {self.velocity_frame!r}"
            )

    def __repr__(self) -> str:
        # the default frame left out, as scikit-learn prints estimators
        if self.velocity_frame == "eigen":
            return f"SPD(dim={self.dim!r})"
        return f"SPD(dim={self.dim!r}, velocity_frame={self.velocity_frame!r})"

    @property
    def point_shape(self) -> tuple[int, ...]:
        return (self.dim, self.dim)

    @property
    def distance_segments(self):
        return ((0, self.dim * self.dim, "spd"),)

    @property
    def intrinsic_dim(self) -> int:
        return self.dim * (self.dim + 1) // 2

    @property
    def velocity_dim(self) -> int:
        return self.intrinsic_dim

    def _velocity(self, p, x):
        # logm of the whitened matrix, in the isometric coordinates of _to_coordinates
        if _in_unit_range(p) and _in_unit_range(x):
            w = self._whitened_log(p, x)
        else:
            # points far from 1: logm(p^-1/2 x p^-1/2) = logm(p'^-1/2 x' p'^-1/2) + (f - e)
            # ln 2 I for p = 2^e p', x = 2^f x' (the whitening would over- or underflow);
            # diagonal pairs entry by entry, exact at any spread
            diagonal = (_is_diagonal(p) & _is_diagonal(x))[..., None, None]
            eye = torch.eye(self.dim, dtype=p.dtype, device=p.device)
            p_exponent, x_exponent = _scale_exponent(p), _scale_exponent(x)
            shift = ((x_exponent - p_exponent) * math.log(2.0))[..., None, None]
            rescaled = self._whitened_log(
                torch.where(diagonal, eye, _unscaled(p, p_exponent)),
                torch.where(diagonal, eye, _unscaled(x, x_exponent)),
            ) + shift * eye
            exact = torch.diag_embed(_log_entries(x) - _log_entries(p))
            w = torch.where(diagonal, exact, rescaled)
        if self.velocity_frame == "eigen":
            w = _in_eigenbasis(p, w)
        rows, cols, weight = self._triangle(w)
        return w[..., rows, cols] * weight

    def _whitened_log(self, p, x):
        si = symmetric_function(distinct(p), "invsqrt")
        return symmetric_function(sym(si @ x @ si), "log")

    def _triangle(self, like):
        """Upper-triangle indices and their weights: 1 on the diagonal, sqrt(2) off it."""
        rows, cols = torch.triu_indices(self.dim, self.dim, device=like.device)
        # in the coordinates' dtype from the start (a where() on Python scalars rounds
        # sqrt(2) to float32: 1.6e-8 relative error in every off-diagonal coordinate)
        weight = torch.ones(rows.shape, dtype=like.dtype, device=like.device)
        weight[rows != cols] = math.sqrt(2.0)
        return rows, cols, weight

    def _to_coordinates(self, p, v):
        # pyRiemann's ``upper``: the whitened matrix, diagonal and sqrt(2) x upper triangle
        si = symmetric_function(distinct(p), "invsqrt")
        w = sym(si @ v @ si)
        rows, cols, weight = self._triangle(w)
        return w[..., rows, cols] * weight

    def _from_coordinates(self, p, c):
        rows, cols, weight = self._triangle(c)
        lead = torch.broadcast_shapes(p.shape[:-2], c.shape[:-1])
        w = c.new_zeros(*lead, self.dim, self.dim)
        w[..., rows, cols] = (c / weight).expand(*lead, c.shape[-1])
        w = w + w.mT - torch.diag_embed(torch.diagonal(w, dim1=-2, dim2=-1))
        s = symmetric_function(distinct(p), "sqrt")
        return sym(s @ w @ s)

    @property
    def normalised_space(self):
        return Euclidean(self.dim)

    def normalise_windows(self, windows):
        # log-eigenvalues of M^-1 X (M the window's arithmetic mean, A M A^T for the
        # window A X A^T): the same under any congruence; ascending
        X = np.asarray(windows, dtype=np.float64)
        lower = np.linalg.cholesky(X.mean(axis=-3, keepdims=True))
        inverse = np.linalg.inv(lower)
        relative = inverse @ X @ np.swapaxes(inverse, -1, -2)
        relative = 0.5 * (relative + np.swapaxes(relative, -1, -2))
        return np.log(np.clip(np.linalg.eigvalsh(relative), 1e-300, None))

    def _whiten(self, p):
        """``p^½`` and ``p^-½`` from one eigendecomposition of each distinct ``p``."""
        s, si = symmetric_functions(distinct(p), "sqrt", "invsqrt")
        return s.expand_as(p), si.expand_as(p)

    def _group_log(self, means, codes, points):
        general = self._general_group_log(means, codes, points)
        if _ordinary(means, points):
            return general
        expanded = group_expand(means, codes)
        diagonal = (_is_diagonal(expanded) & _is_diagonal(points))[..., None, None]
        return torch.where(diagonal, _diagonal_log(expanded, points), general)

    def _general_group_log(self, means, codes, points):
        if self.dim == 2 and _spd2.compiled(means, points):  # one compiled pass
            return _spd2.log(group_expand(means, codes), points)
        if self.dim == 2:  # each mean's chart once, not once per member
            charts = _spd2.chart(means)
            return _spd2.log(_spd2.group_chart(charts, lambda f: group_expand(f, codes)), points)
        s, si = self._whiten(means)  # each mean once, not once per member
        s, si = group_expand(s, codes), group_expand(si, codes)
        return sym(s @ symmetric_function(si @ points @ si, "log") @ s)

    # The maps and the distance take ordinary points (:func:`_ordinary`) as they are.
    # Pairs of diagonal points (a diagonal point and a diagonal vector for exp) take them
    # entry by entry, exact at any spread: the closed forms and the whitening lose the
    # small entries beside large ones (to cancellation, or to ratios that over- or
    # underflow beyond 1e+-154); the other pairs are taken at a power of two near each
    # point's scale (the ``_rescaled_*`` routes). The general route gets the identity at
    # diagonal pairs, so that no NaN of it reaches the gradient through where().
    def _exp(self, p, v):
        return self._careful(p, v, self._plain_exp, self._rescaled_exp, _diagonal_exp,
                             matrix=True, x_is_point=False)  # fmt: skip

    def _log(self, p, x):
        return self._careful(p, x, self._plain_log, self._rescaled_log, _diagonal_log,
                             matrix=True)  # fmt: skip

    def _dist(self, p, x):
        return self._careful(p, x, self._plain_dist, self._rescaled_dist, _diagonal_dist,
                             matrix=False)  # fmt: skip

    def _careful(self, p, x, plain, rescaled, exact, matrix, x_is_point=True):
        if _ordinary(p, x, x_is_point):
            return plain(p, x)  # the usual case, at the closed forms' speed
        diagonal = _is_diagonal(p) & _is_diagonal(x)
        eye = torch.eye(self.dim, dtype=p.dtype, device=p.device)
        mask = diagonal[..., None, None]
        out = rescaled(torch.where(mask, eye, p), torch.where(mask, eye, x))
        return torch.where(mask if matrix else diagonal, exact(p, x), out)

    def _plain_exp(self, p, v):
        if self.dim == 2:
            return _spd2.exp(p, v)
        s, si = self._whiten(p)
        return sym(s @ symmetric_function(si @ v @ si, "exp") @ s)

    def _plain_log(self, p, x):
        if self.dim == 2:
            return _spd2.log(p, x)
        s, si = self._whiten(p)
        return sym(s @ symmetric_function(si @ x @ si, "log") @ s)

    def _plain_dist(self, p, x):
        if self.dim == 2:
            return _spd2.dist(p, x)
        return safe_norm(_log_generalized_eigenvalues(p, x), dim=-1)

    def _rescaled_exp(self, p, v):
        # Exp_p(v) = 2^e Exp_p'(v / 2^e) for p = 2^e p', and Exp_p'(v') = 2^n Exp_p'(v' -
        # n ln 2 p') with n the whitened vector's mean eigenvalue in powers of two, so that
        # the result's own scale leaves the matrix exponential (it may lie 1e+-300 from p)
        exponent = _scale_exponent(p)
        p, v = _unscaled(p, exponent), _unscaled(v, exponent)
        whitened = torch.linalg.solve(p.detach(), v.detach())
        n = torch.round(torch.diagonal(whitened, dim1=-2, dim2=-1).mean(-1) / math.log(2.0))
        v = v - (n * math.log(2.0))[..., None, None] * sym(p)
        return _scaled(self._plain_exp(p, v), exponent + n)

    def _rescaled_log(self, p, x):
        # Log_p(x) = 2^e (Log_p'(x') + (f - e) ln 2 p') for p = 2^e p', x = 2^f x'
        p_exponent, x_exponent = _scale_exponent(p), _scale_exponent(x)
        p, x = _unscaled(p, p_exponent), _unscaled(x, x_exponent)
        shift = ((x_exponent - p_exponent) * math.log(2.0))[..., None, None]
        log = self._plain_log(p, x) + shift * sym(p)  # sym: as the maps read p
        return _scaled(log, p_exponent)

    def _rescaled_dist(self, p, x):
        # the log of the scales' ratio added to every log-eigenvalue of p' and x'
        p_exponent, x_exponent = _scale_exponent(p), _scale_exponent(x)
        shift = (x_exponent - p_exponent) * math.log(2.0)
        logs = _log_generalized_eigenvalues(_unscaled(p, p_exponent), _unscaled(x, x_exponent))
        return safe_norm(logs + shift.unsqueeze(-1), dim=-1)

    def _norm(self, p, v):
        if p.device.type != "cpu" or not _in_unit_range(p):
            # ||p^-1/2 v p^-1/2|| is that of p / 2^e, v / 2^e: points of any scale
            exponent = _scale_exponent(p)
            p, v = _unscaled(p, exponent), _unscaled(v, exponent)
        si = symmetric_function(distinct(p), "invsqrt")
        return safe_norm(si @ v @ si, dim=(-2, -1))

    def _pairwise_dist(self, A, B):
        return self._dist(A.unsqueeze(-3), B.unsqueeze(-4))

    def extreme_scale(self, points):
        eigenvalues = np.linalg.eigvalsh(points)
        if not np.all(eigenvalues > 0):
            return None
        largest, smallest = float(eigenvalues.max()), float(eigenvalues.min())
        if largest < 10.0**EXTREME_EXPONENT and smallest > 10.0**-EXTREME_EXPONENT:
            return None
        return power_of_two_scale(float(np.exp(np.log(eigenvalues).mean())))

    def spread_note(self, points):
        values = np.linalg.eigvalsh(np.asarray(points, dtype=np.float64))
        return f"their eigenvalues run from {values.min():.3g} to {values.max():.3g}"

    def _project(self, x):
        w, U = torch.linalg.eigh(sym(x))
        floor = (w.abs().amax(-1, keepdim=True) * 1e-10).clamp_min(1e-12)
        return sym((U * w.clamp_min(floor).unsqueeze(-2)) @ U.mT)

    def _vector_problem(self, v):
        # the tangent space is the symmetric matrices: exp and norm would otherwise use the
        # symmetric part of v silently
        scale = np.maximum(np.abs(v).max(axis=(-2, -1)), 1.0)
        asymmetry = np.abs(v - np.swapaxes(v, -1, -2)).max(axis=(-2, -1)) / scale
        if np.all(asymmetry <= 1e-6):
            return None
        index = np.unravel_index(int(np.argmax(asymmetry)), asymmetry.shape)
        where = f" (at index {index})" if index else ""
        return (
            f"the matrix is not symmetric{where}: its entries differ from their transpose's "
            f"by {float(asymmetry.max()):.3g} relative to its largest entry (tolerance 1e-6); "
            "tangent vectors of SPD(k) are symmetric matrices"
        )

    def _point_problems(self, x, atol):
        scale = x.abs().amax(dim=(-2, -1)).clamp_min(1.0)
        asymmetry = (x - x.mT).abs().amax(dim=(-2, -1)) / scale
        not_symmetric = asymmetry > atol
        diagonal = _is_diagonal(x)
        # a diagonal matrix's eigenvalues are its entries, at any spread (eigvalsh scales
        # the matrix and loses entries 1e-300 beside 1e+300)
        eye = torch.eye(self.dim, dtype=x.dtype, device=x.device)
        w = torch.where(
            diagonal[..., None],
            torch.diagonal(x, dim1=-2, dim2=-1).sort(-1).values,
            torch.linalg.eigvalsh(torch.where(diagonal[..., None, None], eye, sym(x))),
        )
        not_pd = (w[..., 0] <= 0) & ~not_symmetric
        # a matrix that is not diagonal keeps its eigenvalues in float64 only while they
        # span fewer than 1 / MAX_CONDITION: below that, the smallest are rounding noise
        ill = ~not_symmetric & ~not_pd & ~diagonal & (w[..., 0] < w[..., -1] / MAX_CONDITION)

        def eigenvalue_range(point):
            values = torch.linalg.eigvalsh(sym(point))
            low, high = float(values[0]), float(values[-1])
            text = f"its eigenvalues run from {low:.3g} to {high:.3g}"
            if high > 0 and low > 0:
                text += f" (condition number {high / low:.3g})"
            return text

        return [
            (not_symmetric, "the matrix is not symmetric"),
            (
                not_pd,
                lambda point: (
                    "the matrix is not positive definite: "
                    + eigenvalue_range(point)
                    + "; a non-diagonal matrix whose true eigenvalues span more than "
                    f"{MAX_CONDITION:.0e} can get non-positive ones from rounding alone"
                ),
            ),
            (
                ill,
                lambda point: (
                    eigenvalue_range(point)
                    + f", beyond the condition number {MAX_CONDITION:.0e} up to which a "
                    "non-diagonal SPD matrix keeps its eigenvalues in float64 (smaller ones "
                    "are rounding noise and its geometry would be wrong); regularise it (add a "
                    "multiple of the identity) or pass it in its eigenbasis (diagonal matrices "
                    "of any conditioning work)"
                ),
            ),
        ]

    def _random_point(self, leading, rng):
        k = self.dim
        q, _ = np.linalg.qr(rng.standard_normal((*leading, k, k)))
        eig = np.exp(0.5 * rng.standard_normal((*leading, k)))
        return (q * eig[..., None, :]) @ np.swapaxes(q, -1, -2)

    def _random_tangent(self, p, scale, rng):
        a = scale * rng.standard_normal(p.shape)
        s = 0.5 * (a + np.swapaxes(a, -1, -2))
        w, U = np.linalg.eigh(p)
        root = (U * np.sqrt(w)[..., None, :]) @ np.swapaxes(U, -1, -2)
        return root @ s @ root


def _is_diagonal(p: torch.Tensor) -> torch.Tensor:
    """Whether each matrix of ``p`` (..., k, k) has zeros off its diagonal."""
    k = p.shape[-1]
    off = ~torch.eye(k, dtype=torch.bool, device=p.device).flatten()
    return (p.flatten(-2)[..., off] == 0).all(-1)


def _diagonal_entries(p: torch.Tensor) -> torch.Tensor:
    return torch.diagonal(p, dim1=-2, dim2=-1)


def _log_entries(p: torch.Tensor) -> torch.Tensor:
    """Logs of the diagonal entries (finite for any pair: the other branch of where())."""
    return torch.log(_diagonal_entries(p).abs().clamp_min(1e-300))


def _diagonal_log(p: torch.Tensor, x: torch.Tensor) -> torch.Tensor:
    """``Log_p(x)`` of diagonal points: ``diag(p_i (log x_i - log p_i))``."""
    return torch.diag_embed(_diagonal_entries(p) * (_log_entries(x) - _log_entries(p)))


def _diagonal_exp(p: torch.Tensor, v: torch.Tensor) -> torch.Tensor:
    """``Exp_p(v)`` of a diagonal point and vector: ``diag(p_i exp(v_i / p_i))`` (the
    exponent capped below float64's overflow, for the pairs where() does not keep)."""
    entries = _diagonal_entries(p)
    safe = torch.where(entries == 0, torch.ones_like(entries), entries)
    # exp(log p_i + v_i / p_i): p_i exp(v_i / p_i) would overflow or go subnormal first
    exponent = (_log_entries(p) + _diagonal_entries(v) / safe).clamp(max=709.0)
    return torch.diag_embed(torch.exp(exponent))


def _diagonal_dist(p: torch.Tensor, x: torch.Tensor) -> torch.Tensor:
    """The distance of diagonal points, ``||log diag(x) - log diag(p)||``: the log-ratios
    of their entries without the ratios (any other pair gets a finite, unused value)."""
    return safe_norm(_log_entries(x) - _log_entries(p), dim=-1)


def _congruence(L: torch.Tensor, X: torch.Tensor) -> torch.Tensor:
    """``L^-1 X L^-T`` (``L`` lower triangular, ``X`` symmetric) by two triangular solves."""
    half = torch.linalg.solve_triangular(L, X, upper=False)  # L^-1 X
    return sym(torch.linalg.solve_triangular(L, half.mT, upper=False))


def _in_eigenbasis(p: torch.Tensor, w: torch.Tensor) -> torch.Tensor:
    """``U^T W U`` for ``P = U diag(lambda) U^T``, eigenvalues ascending, the columns'
    signs fixed so that a rotation ``R`` of the pair (``R P R^T``, ``R W R^T``: the
    eigenbasis ``R U``) gives the same matrix: ``det U = +1``, and for ``k >= 3`` the
    first row's entries ``[0, j]`` non-negative (every ``j >= 1`` for odd ``k``, where
    the determinant may then be -1: flipping every column, ``-U``, changes no matrix;
    all but the last for even ``k``, whose sign ``det U = +1`` then fixes). ``P`` is
    eigendecomposed at its power-of-two scale (its eigenvectors are those of ``P``)."""
    p, w = torch.broadcast_tensors(p, w)
    basis = torch.linalg.eigh(sym(_unscaled(p, _scale_exponent(p))))[1]
    w = sym(basis.mT @ w @ basis)
    k = w.shape[-1]
    if k == 1:
        return w
    signs = torch.where(w[..., 0, :] < 0, -1.0, 1.0).to(w.dtype)
    signs[..., 0] = 1.0
    if k % 2 == 0:  # the last column's sign makes det(U S) = +1
        signs[..., -1] = torch.linalg.det(basis).sign() * signs[..., 1:-1].prod(-1)
    return w * signs[..., :, None] * signs[..., None, :]


def _scale_exponent(p: torch.Tensor) -> torch.Tensor:
    """The power of two nearest the mean diagonal entry of each point (a float tensor:
    ``torch.ldexp`` takes it), detached: a constant factor of the point."""
    mean = torch.diagonal(p, dim1=-2, dim2=-1).mean(-1).detach()
    return torch.round(torch.log2(mean.abs().clamp_min(1e-300)))


def _unscaled(p: torch.Tensor, exponent: torch.Tensor) -> torch.Tensor:
    return torch.ldexp(p, -exponent[..., None, None])


def _scaled(p: torch.Tensor, exponent: torch.Tensor) -> torch.Tensor:
    return torch.ldexp(p, exponent[..., None, None])


#: Diagonal entries within ``2^+-UNIT_RANGE`` of 1 keep the closed forms (their products
#: square the entries) and the whitening in range.
UNIT_RANGE = 200


def _in_unit_range(p: torch.Tensor) -> bool:
    if p.numel() == 0:
        return True
    low, high = torch.aminmax(torch.diagonal(p, dim1=-2, dim2=-1))
    return bool(low > 2.0**-UNIT_RANGE) and bool(high < 2.0**UNIT_RANGE)


def _ordinary(p: torch.Tensor, x: torch.Tensor, x_is_point: bool = True) -> bool:
    """Whether the maps and the distance can take ``p`` and ``x`` as they are: on the
    CPU (on a GPU the test would wait for the device: the careful routes run there),
    every diagonal entry within ``2^+-UNIT_RANGE`` and no pair of diagonal matrices (one
    needs a zero at ``[0, 1]`` in both). Two aminmax and two comparisons: the usual
    case pays little for the careful routes."""
    if p.device.type != "cpu" or p.shape[-1] == 1 or not _in_unit_range(p):
        return False  # SPD(1): every point is diagonal
    if x_is_point and not _in_unit_range(x):
        return False
    return not (bool((p[..., 0, 1] == 0).any()) and bool((x[..., 0, 1] == 0).any()))


#: Spread of a pair's eigenvalues (largest over smallest) up to which the forward side
#: alone keeps them to about ``eps * 1e4``: beyond it, the reverse pair is computed too.
SMALL_EIGENVALUES_KEPT = 1e4


def _log_generalized_eigenvalues(p: torch.Tensor, x: torch.Tensor) -> torch.Tensor:
    """Ascending logs of the eigenvalues of ``p^-1 x`` (the whitened matrix's), each from
    the side that holds it accurately.

    The eigenvalues of ``L^-1 x L^-T`` (``p = L L^T``) carry absolute errors of about
    ``eps`` times the largest: the large ones are accurate, the small ones lose their
    digits as the spread grows (the whitened matrix of two points of condition 1e10 has
    eigenvalues 1e-10 .. 1e10). The reverse pair ``(x, p)`` holds the inverses, its large
    ones accurate: each log-eigenvalue is taken from the side where it lies on the large
    half of the log-spectrum (the route of the DTW kernels, which keep the smallest of
    the reverse pair). Gradients through :func:`eigenvalues`: finite for repeated ones.
    """
    # cholesky reads one triangle: symmetric parts, so that the gradient goes to both;
    # p's factor once per distinct point (a broadcast mean is factored once)
    p_factor = torch.linalg.cholesky(sym(distinct(p)))
    p, x = sym(p), sym(x)
    forward = eigenvalues(_congruence(p_factor, x))
    spread = forward[..., 0] * SMALL_EIGENVALUES_KEPT < forward[..., -1]
    if forward.device.type == "cpu" and not bool(spread.any()):
        # every eigenvalue within 1e4 of the largest keeps 12 digits: no reverse pair
        # (the usual case; on a GPU the test would wait for the device, so both run)
        return torch.log(forward)
    reverse = eigenvalues(_congruence(torch.linalg.cholesky(x), p))
    return _combine(forward, reverse)


def _combine(forward: torch.Tensor, reverse: torch.Tensor) -> torch.Tensor:
    """Ascending log-eigenvalues from a pair's ascending eigenvalues (``forward``) and its
    reverse pair's (``reverse``, the inverses): each from the side where it is large."""
    tiny = torch.finfo(forward.dtype).tiny
    log_forward = torch.log(forward.clamp_min(tiny))
    log_reverse = -torch.log(reverse.clamp_min(tiny)).flip(-1)
    # the middle of the log-spectrum, from the two accurate ends
    middle = 0.5 * (log_forward[..., -1:] + log_reverse[..., :1])
    return torch.where(log_forward >= middle, log_forward, log_reverse)
