"""SPH smoothing kernels shared by every method (numba), in 1, 2 and 3 dimensions.

Convention (all kernels): support radius 2 h, q = r / h in [0, 2].
- ``cubic_spline``: Monaghan & Lattanzio (1985), Monaghan (1992); the kernel
  of eq. 4 of marko2017: W = sigma (1 - 1.5 q^2 + 0.75 q^3) for q < 1,
  sigma (2 - q)^3 / 4 for 1 <= q < 2.
- ``wendland_c2``, ``wendland_c4``, ``wendland_c6``: Wendland (1995) functions
  psi_{3,1}, psi_{3,2}, psi_{3,3} (positive definite up to 3D, the form SPH
  codes use in every dimension; Dehnen & Aly 2012), with s = q / 2:
  C2 (1 - s)^4 (1 + 4 s); C4 (1 - s)^6 (1 + 6 s + 35/3 s^2);
  C6 (1 - s)^8 (1 + 8 s + 25 s^2 + 32 s^3).
- ``wendland_c2_1d``, ``wendland_c4_1d``, ``wendland_c6_1d``: the 1D forms, Wendland functions psi_{2,1},
  psi_{3,2}, psi_{4,3} (positive definite in 1D; Dehnen & Aly 2012, Table 1, nu = 1), s = q / 2:
  C2 (1 - s)^3 (1 + 3 s); C4 (1 - s)^5 (1 + 5 s + 8 s^2); C6 (1 - s)^7 (1 + 7 s + 19 s^2 + 21 s^3).
Normalisations sigma_d / h^d are computed exactly (polynomial integration) at
import, so that the integral of W over R^d is 1 in d = 1, 2, 3.

Numba API: ``w(kind, q)`` and ``dw(kind, q)`` are the unnormalised shape and
its derivative d/dq; multiply by ``norm[kind, dim] / h**dim`` (and by 1 / h for
the radial derivative dW/dr).  Python API: :func:`kernel_id`, :func:`W`,
:func:`dWdr` (vectorised, normalised).
"""

import numpy as np
from .jit import njit
from numpy.polynomial import Polynomial as P

JIT = dict(cache=True, nogil=True)

NAMES = ("cubic_spline", "wendland_c2", "wendland_c4", "wendland_c6", "wendland_c2_1d", "wendland_c4_1d", "wendland_c6_1d")
CUBIC, WC2, WC4, WC6, WC2_1D, WC4_1D, WC6_1D = range(7)
SUPPORT = 2.0  # support radius in units of h


def _pieces(kind):
    """[(q0, q1, polynomial in q)] of a kernel's unnormalised shape."""
    if kind == CUBIC:
        return [(0.0, 1.0, P([1.0, 0.0, -1.5, 0.75])), (1.0, 2.0, 0.25 * P([2.0, -1.0]) ** 3)]
    s = P([0.0, 0.5])
    one = 1.0 - s
    poly = {WC2: one**4 * (1 + 4 * s),
            WC4: one**6 * (1 + 6 * s + 35.0 / 3.0 * s**2),
            WC6: one**8 * (1 + 8 * s + 25 * s**2 + 32 * s**3),
            WC2_1D: one**3 * (1 + 3 * s),
            WC4_1D: one**5 * (1 + 5 * s + 8 * s**2),
            WC6_1D: one**7 * (1 + 7 * s + 19 * s**2 + 21 * s**3)}[kind]
    return [(0.0, 2.0, poly)]


def _norm(kind, dim):
    """sigma_d with W = sigma_d / h^d f(q), so that the d-dimensional integral is 1."""
    area = {1: 2.0, 2: 2.0 * np.pi, 3: 4.0 * np.pi}[dim]  # surface of the unit sphere
    total = 0.0
    for q0, q1, f in _pieces(kind):
        g = (f * P([0.0] * (dim - 1) + [1.0])).integ()
        total += g(q1) - g(q0)
    return 1.0 / (area * total)


NORM = np.array([[np.nan] + [_norm(k, d) for d in (1, 2, 3)] for k in range(len(NAMES))])  # (kind, dim)


def kernel_id(name):
    """Integer id of a kernel name (ValueError naming the choices if unknown)."""
    try:
        return NAMES.index(name)
    except ValueError:
        raise ValueError(f"unknown smoothing kernel '{name}' (choose from {', '.join(NAMES)})") from None


@njit(**JIT)
def w(kind, q):
    """Unnormalised kernel shape f(q), q = r / h >= 0."""
    if q >= 2.0:
        return 0.0
    if kind == 0:
        if q < 1.0:
            return 1.0 - 1.5 * q * q + 0.75 * q * q * q
        t = 2.0 - q
        return 0.25 * t * t * t
    s = 0.5 * q
    o = 1.0 - s
    if kind == 1:
        return o**4 * (1.0 + 4.0 * s)
    if kind == 2:
        return o**6 * (1.0 + 6.0 * s + 35.0 / 3.0 * s * s)
    if kind == 3:
        return o**8 * (1.0 + 8.0 * s + 25.0 * s * s + 32.0 * s * s * s)
    if kind == 4:
        return o**3 * (1.0 + 3.0 * s)
    if kind == 5:
        return o**5 * (1.0 + 5.0 * s + 8.0 * s * s)
    return o**7 * (1.0 + 7.0 * s + 19.0 * s * s + 21.0 * s * s * s)


@njit(**JIT)
def dw(kind, q):
    """d f / d q of the unnormalised shape (<= 0)."""
    if q >= 2.0:
        return 0.0
    if kind == 0:
        if q < 1.0:
            return -3.0 * q + 2.25 * q * q
        t = 2.0 - q
        return -0.75 * t * t
    s = 0.5 * q
    o = 1.0 - s
    # d/dq = 0.5 d/ds
    if kind == 1:
        return 0.5 * (-20.0 * s * o**3)
    if kind == 2:
        return 0.5 * (-(56.0 / 3.0) * s * (1.0 + 5.0 * s) * o**5)
    if kind == 3:
        return 0.5 * (-22.0 * s * (1.0 + 7.0 * s + 16.0 * s * s) * o**7)
    if kind == 4:
        return 0.5 * (-12.0 * s * o**2)
    if kind == 5:
        return 0.5 * (-14.0 * s * (1.0 + 4.0 * s) * o**4)
    return 0.5 * (-6.0 * s * (3.0 + 18.0 * s + 35.0 * s * s) * o**6)


def W(name, r, h, dim):
    """Normalised kernel W(r, h) [1/cm^dim], vectorised over r [cm]."""
    k = kernel_id(name)
    q = np.abs(np.asarray(r, float)) / h
    return NORM[k, dim] / h**dim * np.vectorize(lambda x: w(k, x))(q)


def dWdr(name, r, h, dim):
    """Normalised radial derivative dW/dr [1/cm^(dim+1)], vectorised over r >= 0 [cm]."""
    k = kernel_id(name)
    q = np.abs(np.asarray(r, float)) / h
    return NORM[k, dim] / h ** (dim + 1) * np.vectorize(lambda x: dw(k, x))(q)
