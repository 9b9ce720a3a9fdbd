"""Solves of the MPS pressure equation.

The matrix of model.assemble is symmetric positive definite.  Solvers:
- ``cg_jacobi``: conjugate gradients with the diagonal as preconditioner, compiled (numba): matrix-vector
  products by rows and dot products as sums of fixed blocks of BLOCK entries added in block order, so the
  result is bit-identical for any thread count and uses no BLAS;
- ``scipy_cg``: the same method from scipy.sparse.linalg.cg (BLAS dot products);
- ``amg``: pyamg smoothed aggregation as preconditioner of conjugate gradients;
- ``direct``: scipy sparse LU (SuperLU).
Chosen by benchmarks/bench_mps.py.  The residual reported is the true
relative residual |b - A x| / |b| of the returned solution.
"""

import numba
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import prange, uint64

from ...core.jit import njit

SOLVERS = ("cg_jacobi", "scipy_cg", "amg", "direct")
ZERO_DIAGONAL = "division by zero"  # cg_jacobi's error where a diagonal entry is 0 (numba's ZeroDivisionError)
BLOCK = 512  # entries per partial sum of a dot product (fixed: the sum order does not depend on the threads)
PAR = dict(cache=True, nogil=True, parallel=True)


def csr(indptr, indices, data):
    """scipy CSR matrix of model.assemble's arrays (columns sorted)."""
    n = len(indptr) - 1
    A = sp.csr_matrix((data, indices, indptr), shape=(n, n))
    A.sort_indices()
    return A


PAR_MIN = 50000  # rows from which the solve runs its loops in parallel when numba has more than one thread (below it
# the per-iteration thread synchronisations cost more than they save: 2 threads made the 5,000-particle solve
# 1.6x slower on the shared 2-core machine, 42 against 26 ms)


@njit(inline="always", cache=True, nogil=True)
def _block_dot(a, b, q):
    """Block q's partial sum of a . b: entries q BLOCK <= i < (q + 1) BLOCK in order."""
    t = 0.0
    for i in range(q * BLOCK, min(a.shape[0], (q + 1) * BLOCK)):
        t += a[i] * b[i]
    return t


@njit(inline="always", cache=True, nogil=True)
def _row_dot(indptr, indices, data, x, r):
    """Row r of the CSR matrix times x, summed in row order.  Unsigned indices: numba then skips the
    negative-index wraparound test of every access (the same arithmetic, half the time)."""
    s = 0.0
    for k in range(uint64(indptr[r]), uint64(indptr[r + 1])):
        s += data[k] * x[uint64(indices[k])]
    return s


@njit(cache=True, nogil=True)
def _dot_serial(a, b):
    s = 0.0
    for q in range((a.shape[0] + BLOCK - 1) // BLOCK):
        s += _block_dot(a, b, q)
    return s


@njit(**PAR)
def _dot_par(a, b):
    nb = (a.shape[0] + BLOCK - 1) // BLOCK
    part = np.zeros(nb)
    for q in prange(nb):
        part[q] = _block_dot(a, b, q)
    s = 0.0
    for q in range(nb):
        s += part[q]
    return s


@njit(cache=True, nogil=True)
def _matvec_serial(indptr, indices, data, x, out):
    for r in range(indptr.shape[0] - 1):
        out[r] = _row_dot(indptr, indices, data, x, r)


@njit(**PAR)
def _matvec_par(indptr, indices, data, x, out):
    for r in prange(indptr.shape[0] - 1):
        out[r] = _row_dot(indptr, indices, data, x, r)


@njit(cache=True, nogil=True)
def _update_serial(alpha, p, ap, x, r, z, dinv):
    for i in range(x.shape[0]):
        x[i] += alpha * p[i]
        r[i] -= alpha * ap[i]
        z[i] = r[i] * dinv[i]


@njit(**PAR)
def _update_par(alpha, p, ap, x, r, z, dinv):
    for i in prange(x.shape[0]):
        x[i] += alpha * p[i]
        r[i] -= alpha * ap[i]
        z[i] = r[i] * dinv[i]


@njit(cache=True, nogil=True)
def _direction_serial(beta, z, p):
    for i in range(p.shape[0]):
        p[i] = z[i] + beta * p[i]


@njit(**PAR)
def _direction_par(beta, z, p):
    for i in prange(p.shape[0]):
        p[i] = z[i] + beta * p[i]


@njit(cache=True, nogil=True)
def cg_jacobi(indptr, indices, data, b, x0, rtol, maxiter, parallel=False):
    """Jacobi-preconditioned CG for the CSR matrix (indptr, indices, data).  Returns (x, relative residual
    |b - A x| / |b| of x, iterations); stops when the recursive residual is below rtol |b| or after maxiter.
    parallel: loops over rows in parallel (numba threads); the arithmetic, and so the result, is the same
    either way (row sums in row order, dot products as sums of BLOCK-entry partial sums in block order)."""
    n = b.shape[0]
    x = x0.copy()
    dinv = np.zeros(n)
    for r in range(n):
        for k in range(indptr[r], indptr[r + 1]):
            if indices[k] == r:
                dinv[r] = 1.0 / data[k]
    bnorm = np.sqrt(_dot_serial(b, b))
    if bnorm == 0.0:
        return np.zeros(n), 0.0, 0
    ax = np.empty(n)
    if parallel:
        _matvec_par(indptr, indices, data, x, ax)
    else:
        _matvec_serial(indptr, indices, data, x, ax)
    r = b - ax
    z = r * dinv
    p = z.copy()
    ap = np.empty(n)
    rz = _dot_serial(r, z)
    its = 0
    tol2 = (rtol * bnorm) ** 2
    while its < maxiter:
        rr = _dot_par(r, r) if parallel else _dot_serial(r, r)
        if not rr > tol2:
            break
        if parallel:
            _matvec_par(indptr, indices, data, p, ap)
            alpha = rz / _dot_par(p, ap)
            _update_par(alpha, p, ap, x, r, z, dinv)
            rz_new = _dot_par(r, z)
        else:
            _matvec_serial(indptr, indices, data, p, ap)
            alpha = rz / _dot_serial(p, ap)
            _update_serial(alpha, p, ap, x, r, z, dinv)
            rz_new = _dot_serial(r, z)
        beta = rz_new / rz
        rz = rz_new
        if parallel:
            _direction_par(beta, z, p)
        else:
            _direction_serial(beta, z, p)
        its += 1
    _matvec_serial(indptr, indices, data, x, ax)
    res = b - ax
    return x, np.sqrt(_dot_serial(res, res)) / bnorm, its


@njit(cache=True, nogil=True)
def cg_solve(indptr, indices, data, rhs, x0, rtol, maxiter, threads):
    """solve_csr's cg_jacobi, callable from compiled code: (x, relative residual, iterations, failed), the loops in
    parallel from PAR_MIN rows when numba has more than one thread (threads: numba.get_num_threads(), which compiled
    code that is cached cannot ask).  failed: a diagonal entry is 0 (cg_jacobi would
    divide by it; x NaN, residual inf, 0 iterations)."""
    n = rhs.shape[0]
    if n == 0:
        return np.zeros(0), 0.0, 0, False
    for r in range(n):
        for k in range(indptr[r], indptr[r + 1]):
            if indices[k] == r and data[k] == 0.0:
                return np.full(n, np.nan), np.inf, 0, True
    x, resid, its = cg_jacobi(indptr, indices, data, rhs, x0, rtol, maxiter, threads > 1 and n >= PAR_MIN)
    return x, resid, its, False


def solve_csr(indptr, indices, data, rhs, method="cg_jacobi", rtol=1e-8, maxiter=2000, x0=None):
    """Solve the CSR system of model.assemble.  Returns (x, relative residual, iterations)."""
    n = len(rhs)
    if n == 0:
        return np.zeros(0), 0.0, 0
    x0 = np.zeros(n) if x0 is None else x0
    if method == "cg_jacobi":
        x, resid, its, failed = cg_solve(indptr, indices, data, rhs, x0, rtol, maxiter, numba.get_num_threads())
        if failed:
            raise ZeroDivisionError(ZERO_DIAGONAL)
        return x, resid, its
    return solve(csr(indptr, indices, data), rhs, method, rtol, maxiter, x0)


def solve(A, rhs, method="amg", rtol=1e-8, maxiter=2000, x0=None):
    """Solve A x = rhs (scipy sparse A).  Returns (x, relative residual, iterations)."""
    n = A.shape[0]
    if n == 0:
        return np.zeros(0), 0.0, 0
    bnorm = np.linalg.norm(rhs)
    if bnorm == 0.0:
        return np.zeros(n), 0.0, 0
    if method == "cg_jacobi":
        A = A.tocsr()
        return cg_jacobi(A.indptr.astype(np.int64), A.indices.astype(np.int32), A.data, rhs,
                         np.zeros(n) if x0 is None else x0, rtol, maxiter)
    if method == "direct":
        x = spla.spsolve(A.tocsc(), rhs)
        its = 1
    elif method == "amg":
        import pyamg

        ml = pyamg.smoothed_aggregation_solver(A, symmetry="symmetric", max_coarse=50)
        res = []
        x = ml.solve(rhs, x0=x0, tol=rtol, maxiter=maxiter, accel="cg", residuals=res)
        its = len(res) - 1
    elif method == "scipy_cg":
        d = A.diagonal()
        M = sp.diags(1.0 / d)
        its = [0]

        def count(_):
            its[0] += 1

        x, _ = spla.cg(A, rhs, x0=x0, rtol=rtol, atol=0.0, maxiter=maxiter, M=M, callback=count)
        its = its[0]
    else:
        raise ValueError(f"unknown pressure solver '{method}' (choose from {', '.join(SOLVERS)})")
    resid = float(np.linalg.norm(rhs - A @ x) / bnorm)
    return x, resid, its
