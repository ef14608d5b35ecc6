"""Banded symmetric matrices: storage, Cholesky factor (LAPACK ``dpbtrf``, once) and numba
kernels for the per-step triangular solves and matrix-vector products.

Storage (row-major, so that one row's band is contiguous for the kernels):

- ``rows`` ``(n, 2 kd + 1)``: ``rows[i, kd + j - i] = A[i, j]`` for ``|i - j| <= kd``;
- ``lower`` ``(n + kd, kd + 1)``: the Cholesky factor, ``lower[i, k] = L[i, i - k]``, with
  ``lower[i, 0] = 1 / L[i, i]`` (the kernels multiply by the inverse diagonal) and ``kd``
  trailing rows of zeros;
- vectors are *padded*: length ``n + 2 kd``, entry ``i`` of the matrix's space at ``kd + i``,
  zeros in the pads. Every loop then has a constant trip count and no bounds branch, which
  makes the triangular sweeps 2-3 times faster than the plain form.
"""
import numpy as np
import scipy.sparse as sp
from numba import njit
from scipy.linalg import lapack


def half_bandwidth(a):
    coo = sp.coo_matrix(a)
    return int(np.max(np.abs(coo.row - coo.col), initial=0))


def band_rows(a, kd):
    """Full band of the square sparse matrix ``a`` as ``(n, 2 kd + 1)`` rows."""
    coo = sp.coo_matrix(a)
    rows = np.zeros((a.shape[0], 2 * kd + 1))
    np.add.at(rows, (coo.row, kd + coo.col - coo.row), coo.data)
    return rows


class NotPositiveDefinite(Exception):
    """Cholesky failed at ``pivot`` (0-based index of the first non-positive leading minor)."""

    def __init__(self, pivot):
        super().__init__(pivot)
        self.pivot = pivot


def cholesky_band(a, kd):
    """Banded Cholesky factor of the SPD sparse matrix ``a`` in the kernels' ``lower`` layout."""
    n = a.shape[0]
    coo = sp.coo_matrix(a)
    keep = coo.row >= coo.col
    ab = np.zeros((kd + 1, n))
    ab[coo.row[keep] - coo.col[keep], coo.col[keep]] += coo.data[keep]
    factor, info = lapack.dpbtrf(ab, lower=1)
    if info > 0:
        raise NotPositiveDefinite(info - 1)
    lower = np.zeros((n + kd, kd + 1))
    for k in range(kd + 1):
        lower[k:n, k] = factor[k, : n - k]
    lower[:n, 0] = 1.0 / lower[:n, 0]
    return lower


def pad(x, kd):
    """Padded copy of the vector ``x``."""
    out = np.zeros(x.shape[0] + 2 * kd)
    out[kd: kd + x.shape[0]] = x
    return out


@njit(cache=True)
def cholesky_solve(lower, b):
    """Solve ``L Lᵀ x = b`` in place for the padded vector ``b`` (pads stay zero).

    The products with the nearest, just computed entries come last, so that the sequential
    dependency from one row to the next is one multiply-add long.
    """
    kd = lower.shape[1] - 1
    n = lower.shape[0] - kd
    for i in range(n):
        s = b[kd + i]
        for k in range(kd, 0, -1):
            s -= lower[i, k] * b[kd + i - k]
        b[kd + i] = s * lower[i, 0]
    for i in range(n - 1, -1, -1):
        s = b[kd + i]
        for k in range(kd, 0, -1):
            s -= lower[i + k, k] * b[kd + i + k]
        b[kd + i] = s * lower[i, 0]


@njit(cache=True)
def band_matvec_add(out, rows, x, scale):
    """``out += scale * A x`` for the band ``rows`` of ``A`` and padded ``out``, ``x``."""
    n, w = rows.shape
    for i in range(n):
        s = 0.0
        for k in range(w):
            s += rows[i, k] * x[i + k]
        out[(w - 1) // 2 + i] += scale * s
