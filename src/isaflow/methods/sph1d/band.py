"""Banded LU with partial pivoting, its solves and the 1-norm condition number, deterministically.

Everything here is a plain compiled loop whose sums run in index order, so a column's pressure, error and
condition estimate are the same bits on every machine and in every run. LAPACK's dgbtrf/dgbtrs/dgbcon
(through scipy) reach the same numbers only to round-off: they call OpenBLAS's vector kernels (dger, dscal,
dtbsv, ddot), whose order and fused multiply-adds follow the CPU and the memory alignment they meet. With
them the sweep's ill-conditioned cases moved between two values from one machine to the next (the
one-neighbour claim's 1.63e-13 / 1.66e-13, a minimum error 1.31e-14 / 8.33e-15), and dgbcon's estimate by up
to 5e-6 between two runs of the same sweep.

- ``band_lu``: LAPACK's dgbtf2 (the unblocked band LU that dgbtrf runs for kl below its block size), the
  multipliers scaled by the pivot's reciprocal as there.
- ``band_solve``: dgbtrs's forward and back substitution (and the transposed pair for the estimate).
- ``inverse_norm_1``: Higham's estimator of ||A^-1||_1 (Higham 1988, the algorithm of LAPACK's dlacn2 that
  dgbcon runs).

Storage (LAPACK band LU, kl = ku): ``lu`` (3 kl + 1, N), A(i, j) and then U(i, j) at lu[2 kl + i - j, j], the
top kl rows fill-in space (zero on entry), the multipliers of column j at lu[2 kl + 1 : 3 kl + 1, j];
``ipiv`` (N,) 0-based row interchanges.
"""

import numpy as np
from ...core.jit import njit

JIT = dict(cache=True, nogil=True)
ITMAX = 5  # dlacn2's limit on the power iterations


@njit(**JIT)
def band_lu(ab, kl):
    """(lu, ipiv, info) of the band matrix ab (3 kl + 1, N) (module docstring; ab is left unchanged): info 0, or
    j + 1 if U(j, j) is exactly zero (the first such j; the factorisation is completed as dgbtf2 does)."""
    lu = ab.copy()
    n = lu.shape[1]
    kv = 2 * kl
    ipiv = np.zeros(n, np.int64)
    info = 0
    ju = 0  # last column of U touched so far
    for j in range(n):
        km = min(kl, n - 1 - j)
        jp = 0  # the first row of largest magnitude at or below the diagonal (idamax)
        for i in range(1, km + 1):
            if abs(lu[kv + i, j]) > abs(lu[kv + jp, j]):
                jp = i
        ipiv[j] = j + jp
        if lu[kv + jp, j] == 0.0:
            if info == 0:
                info = j + 1
            continue
        ju = max(ju, min(j + kl + jp, n - 1))
        if jp != 0:  # swap rows j and j + jp over columns j .. ju
            for c in range(j, ju + 1):
                a, b = kv + jp + j - c, kv + j - c
                lu[a, c], lu[b, c] = lu[b, c], lu[a, c]
        if km > 0:
            r = 1.0 / lu[kv, j]
            for i in range(1, km + 1):
                lu[kv + i, j] *= r
            for c in range(j + 1, ju + 1):  # rank-1 update of the trailing band
                u = lu[kv + j - c, c]
                if u != 0.0:
                    for i in range(1, km + 1):
                        lu[kv + i + j - c, c] -= lu[kv + i, j] * u
    return lu, ipiv, info


@njit(**JIT)
def band_solve(lu, ipiv, kl, x, transpose):
    """Overwrite x (N,) with A^-1 x (transpose False) or A^-T x (True), A = P L U from band_lu."""
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
