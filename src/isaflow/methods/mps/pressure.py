"""Sparse solves of the MPS pressure equation (scipy.sparse, pyamg).

The matrix of model.assemble is symmetric positive definite.  Solvers:
- ``amg``: pyamg smoothed aggregation as preconditioner of conjugate gradients;
- ``cg_jacobi``: scipy conjugate gradients with the diagonal as preconditioner;
- ``direct``: scipy sparse LU (SuperLU).
Chosen by benchmarks/bench_mps.py.  The residual reported is the true
relative residual |b - A x| / |b| of the returned solution.
"""

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

SOLVERS = ("amg", "cg_jacobi", "direct")


def csr(indptr, indices, data):
    """scipy CSR matrix of model.assemble's arrays (columns sorted)."""
    n = len(indptr) - 1
    A = sp.csr_matrix((data, indices, indptr), shape=(n, n))
    A.sort_indices()
    return A


def solve(A, rhs, method="amg", rtol=1e-8, maxiter=200, x0=None):
    """Solve A x = rhs.  Returns (x, relative residual, iterations)."""
    n = A.shape[0]
    if n == 0:
        return np.zeros(0), 0.0, 0
    bnorm = np.linalg.norm(rhs)
    if bnorm == 0.0:
        return np.zeros(n), 0.0, 0
    if method == "direct":
        x = spla.spsolve(A.tocsc(), rhs)
        its = 1
    elif method == "amg":
        import pyamg

        ml = pyamg.smoothed_aggregation_solver(A, symmetry="symmetric", max_coarse=50)
        res = []
        x = ml.solve(rhs, x0=x0, tol=rtol, maxiter=maxiter, accel="cg", residuals=res)
        its = len(res) - 1
    elif method == "cg_jacobi":
        d = A.diagonal()
        M = sp.diags(1.0 / d)
        its = [0]

        def count(_):
            its[0] += 1

        x, _ = spla.cg(A, rhs, x0=x0, rtol=rtol, atol=0.0, maxiter=maxiter * 20, M=M, callback=count)
        its = its[0]
    else:
        raise ValueError(f"unknown pressure solver '{method}' (choose from {', '.join(SOLVERS)})")
    resid = float(np.linalg.norm(rhs - A @ x) / bnorm)
    return x, resid, its
