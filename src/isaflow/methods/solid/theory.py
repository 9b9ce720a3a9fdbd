"""Analytic references of marko2017 section 4 (SI units in and out: m, Pa, N, s).

Hooke's law for the bar, Poisson necking (eq. 17), shear (eqs. 18-20),
Hertz contact as the paper writes it (eqs. 21-25) and the textbook line and
sphere contact loads, the Lame thick cylinder for the pressure vessel.
"""

import numpy as np


def hooke_stress(E, delta, L):
    """sigma = E delta / L [Pa] (eqs. 11-12)."""
    return E * delta / L


def implied_length(E, delta, sigma):
    """The length L [m] for which E delta / L = sigma."""
    return E * delta / sigma


def necking(d, strain, nu):
    """Width change delta d = -d (1 - (1 + strain)^-nu) [m] (eq. 17, sign as printed)."""
    return -d * (1.0 - (1.0 + strain) ** (-nu))


def poisson_from_necking(dd, d, strain):
    """Equivalent Poisson ratio from a width change |dd| of width d at axial strain (eq. 17 inverted)."""
    return -np.log(1.0 - abs(dd) / d) / np.log(1.0 + strain)


def shear_modulus(E, nu):
    """G = E / (2 (1 + nu)) [Pa] (eq. 18)."""
    return E / (2.0 * (1.0 + nu))


def shear_stress(G, deflection, H):
    """tau = G deflection / H [Pa] (eqs. 19-20)."""
    return G * deflection / H


def reduced_modulus(E, nu):
    """E' = E / (1 - nu^2) [Pa] for a rigid disk on an elastic flat (eqs. 21-22)."""
    return E / (1.0 - nu**2)


def chord_half_width(R, delta):
    """a = R sin(acos((R - delta) / R)) [m] (eq. 24)."""
    return R * np.sin(np.arccos((R - delta) / R))


def hertz_pmax(R, delta, E_red):
    """p_max = a E' / (2 R') with R' = R (eqs. 23-25) [Pa]."""
    return chord_half_width(R, delta) * E_red / (2.0 * R)


def load_candidates(R, delta, E_red, thickness):
    """Contact loads [N] the paper's 2.66-5.98 kN might be, for indentation delta [m]:

    - 'line_per_m': Hertz line contact P' = pi a p_max / 2 with the chord a, per metre [N/m];
    - 'line_times_thickness': that times thickness [m] (the disk's three 53 um particles);
    - 'sphere': a rigid sphere, F = 4/3 E' sqrt(R) delta^1.5.
    """
    a = chord_half_width(R, delta)
    line = np.pi * a * hertz_pmax(R, delta, E_red) / 2.0
    return {"line_per_m": line, "line_times_thickness": line * thickness,
            "sphere": 4.0 / 3.0 * E_red * np.sqrt(R) * np.asarray(delta) ** 1.5}


def lame_inner_displacement(a, b, p, E, nu):
    """Radial displacement [m] of the inner wall of a thick cylinder (inner radius a, outer b)
    under internal pressure p, plane strain: u = a p (1 + nu) ((1 - 2 nu) a^2 + b^2) / (E (b^2 - a^2))."""
    return a * p * (1.0 + nu) * ((1.0 - 2.0 * nu) * a**2 + b**2) / (E * (b**2 - a**2))


def lame_displacement(r, a, b, p, E, nu):
    """Lame radial displacement u(r) = A r + B / r [m] of a thick cylinder under internal pressure p,
    plane strain: A = (1 + nu)(1 - 2 nu) p a^2 / (E (b^2 - a^2)), B = (1 + nu) p a^2 b^2 / (E (b^2 - a^2))."""
    c = (1.0 + nu) * p * a**2 / (E * (b**2 - a**2))
    r = np.asarray(r, float)
    return c * ((1.0 - 2.0 * nu) * r + b**2 / r)


def beam_point_deflection(x, xi, P, L, EI):
    """Simply supported beam of span L [m or cm], point load P at xi: deflection w(x) (positive along P)."""
    x = np.asarray(x, float)[:, None]
    xi, P = np.atleast_1d(xi)[None, :], np.atleast_1d(P)[None, :]
    b = L - xi
    left = P * b * x * (L**2 - b**2 - x**2) / (6.0 * L * EI)
    right = P * xi * (L - x) * (L**2 - xi**2 - (L - x) ** 2) / (6.0 * L * EI)
    return np.where(x <= xi, left, right).sum(1)


def beam_uniform_deflection(x, q, L, EI):
    """Simply supported beam of span L under uniform load q per length: w(x) = q x (L^3 - 2 L x^2 + x^3) / (24 EI)."""
    x = np.asarray(x, float)
    return q * x * (L**3 - 2.0 * L * x**2 + x**3) / (24.0 * EI)
