"""Equations of state of the weakly compressible SPH (numba): Tait or linear, and their inverses.

Units: densities N s^2/cm^4, pressures N/cm^2, sound speed cm/s.
"""

from ...core.jit import njit

JIT = dict(cache=True, nogil=True)


@njit(inline="always", **JIT)
def pressure_of(rho, rho0, c0, gamma, tait, clamp):
    """Equation of state P(rho) [N/cm^2]: Tait B((rho/rho0)^gamma - 1), B = rho0 c0^2/gamma, or linear."""
    if tait:
        r = rho / rho0
        if gamma == 7.0:  # the usual exponent, without a pow call
            r2 = r * r
            rg = r2 * r2 * r2 * r
        else:
            rg = r**gamma
        p = rho0 * c0 * c0 / gamma * (rg - 1.0)
    else:
        p = c0 * c0 * (rho - rho0)
    if clamp and p < 0.0:
        p = 0.0
    return p


@njit(inline="always", **JIT)
def density_of(p, rho0, c0, gamma, tait):
    """Inverse equation of state rho(P) [N s^2/cm^4]."""
    if tait:
        return rho0 * max(1.0 + p * gamma / (rho0 * c0 * c0), 1e-6) ** (1.0 / gamma)
    return rho0 + p / (c0 * c0)
