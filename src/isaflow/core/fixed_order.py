"""Small linear algebra in a fixed order, the same bits on every machine: least-squares lines, 2-norms, 2-vector dot
products, 2 x 2 solves.

numpy's ``@``, ``np.dot``, ``np.linalg`` and ``np.polyfit`` call BLAS and LAPACK (OpenBLAS), whose kernels' summation
order and fused multiply-adds follow the CPU and memory alignment: an SPH run's free-surface slope (zero by symmetry,
round-off) read 3.2e-14 deg on one machine and 4.7e-14 on another.  Here every product and sum is a separate numpy
ufunc (no fused multiply-add) and every long sum numpy's pairwise one.  Physics kernels are numba loops, which
LLVM compiles without contraction; this module is for the NumPy code around them.
"""

import numpy as np


def line(x, y):
    """(slope, intercept) of the least-squares line y ~ slope x + intercept through points x, y (n,), n >= 2 with x
    not all equal (ValueError otherwise); the units of y per unit of x, and of y."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    if x.shape != y.shape or x.ndim != 1 or len(x) < 2:
        raise ValueError(f"a line needs two or more points x, y of one shape (got {x.shape}, {y.shape})")
    xm, ym = np.sum(x) / len(x), np.sum(y) / len(y)
    dx = x - xm
    sxx = np.sum(dx * dx)
    if sxx == 0.0:
        raise ValueError("a line through points at one x is not defined")
    slope = float(np.sum(dx * (y - ym)) / sxx)
    return slope, float(ym - slope * xm)


def residual(x, y):
    """y minus its least-squares line at x (n,) (:func:`line`)."""
    slope, intercept = line(x, y)
    return np.asarray(y, float) - (slope * np.asarray(x, float) + intercept)


def norm(x):
    """sqrt(sum x^2) over every element of x, by numpy's pairwise sum (np.linalg.norm calls BLAS ddot)."""
    x = np.asarray(x, float)
    return float(np.sqrt(np.sum(x * x)))


def dot2(a, b):
    """a . b over the last axis of length 2 (a, b broadcast: (..., 2) against (..., 2) or (2,)), in a's units
    times b's."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1]


def solve2(m, f):
    """x (2,) with m x = f for a 2 x 2 m (Cramer's rule; the caller guards a singular m)."""
    (a, b), (c, d) = np.asarray(m, float)
    det = det2(m)
    return np.array([(f[0] * d - b * f[1]) / det, (a * f[1] - c * f[0]) / det])


def det2(m):
    """Determinant of a 2 x 2 m."""
    (a, b), (c, d) = np.asarray(m, float)
    return a * d - b * c
