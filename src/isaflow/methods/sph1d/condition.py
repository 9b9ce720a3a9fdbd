"""1-norm condition number of a banded matrix from its LAPACK dgbtrf factors, deterministically.

``inverse_norm_1`` is Higham's estimator of ||A^-1||_1 (Higham 1988, the algorithm of LAPACK's dlacn2
that dgbcon runs), with the band solves written out here as plain loops: every sum is taken in index
order, so the estimate is the same number in every run. LAPACK's own dgbcon sums through OpenBLAS's
vector kernels, whose order follows the memory alignment they meet, and its estimate moved by up to
5e-6 between two runs of the same sweep.

Storage (LAPACK band LU, kl = ku): ``lu`` (3 kl + 1, N), U(i, j) at lu[2 kl + i - j, j], the
multipliers of column j at lu[2 kl + 1 : 3 kl + 1, j]; ``ipiv`` (N,) 0-based row interchanges.
"""

import numpy as np
from ...core.jit import njit

JIT = dict(cache=True, nogil=True)
ITMAX = 5  # dlacn2's limit on the power iterations


@njit(**JIT)
def band_solve(lu, ipiv, kl, x, transpose):
    """Overwrite x (N,) with A^-1 x (transpose False) or A^-T x (True), A = P L U from dgbtrf."""
    n = x.shape[0]
    kv = 2 * kl  # row of U's diagonal
    if not transpose:
        for j in range(n - 1):  # L: apply the interchange, then the multipliers of column j
            p = ipiv[j]
            if p != j:
                x[p], x[j] = x[j], x[p]
            for i in range(1, min(kl, n - 1 - j) + 1):
                x[j + i] -= lu[kv + i, j] * x[j]
        for j in range(n - 1, -1, -1):  # U, column by column (upper bandwidth 2 kl)
            x[j] /= lu[kv, j]
            for i in range(max(0, j - kv), j):
                x[i] -= lu[kv + i - j, j] * x[j]
    else:
        for j in range(n):  # U^T, row by row
            s = x[j]
            for i in range(max(0, j - kv), j):
                s -= lu[kv + i - j, j] * x[i]
            x[j] = s / lu[kv, j]
        for j in range(n - 2, -1, -1):  # L^T, then undo the interchange
            s = x[j]
            for i in range(1, min(kl, n - 1 - j) + 1):
                s -= lu[kv + i, j] * x[j + i]
            x[j] = s
            p = ipiv[j]
            if p != j:
                x[p], x[j] = x[j], x[p]


@njit(**JIT)
def _norm_1(x):
    s = 0.0
    for v in x:
        s += abs(v)
    return s


@njit(**JIT)
def _argmax_abs(x):
    j = 0
    for i in range(1, x.shape[0]):
        if abs(x[i]) > abs(x[j]):
            j = i
    return j


@njit(**JIT)
def _signs(x):
    return np.where(x >= 0.0, 1.0, -1.0)


@njit(**JIT)
def inverse_norm_1(lu, ipiv, kl):
    """Higham's lower-bound estimate of ||A^-1||_1 (units of 1/A; usually within a factor of 3 of it)."""
    n = ipiv.shape[0]
    x = np.full(n, 1.0 / n)
    band_solve(lu, ipiv, kl, x, False)
    if n == 1:
        return abs(x[0])
    est = _norm_1(x)
    sgn = _signs(x)
    x = sgn.copy()
    band_solve(lu, ipiv, kl, x, True)
    j = _argmax_abs(x)
    for _ in range(2, ITMAX + 1):
        x = np.zeros(n)
        x[j] = 1.0
        band_solve(lu, ipiv, kl, x, False)
        old = est
        est = _norm_1(x)
        new = _signs(x)
        if np.all(new == sgn) or est <= old:  # repeated sign vector or no growth: stop
            break
        sgn = new
        x = sgn.copy()
        band_solve(lu, ipiv, kl, x, True)
        last, j = j, _argmax_abs(x)
        if x[last] == abs(x[j]):
            break
    alt = np.empty(n)  # the alternating test vector guards against the power method's blind spots
    for i in range(n):
        alt[i] = (-1.0) ** i * (1.0 + i / (n - 1))
    band_solve(lu, ipiv, kl, alt, False)
    return max(est, 2.0 * _norm_1(alt) / (3.0 * n))
