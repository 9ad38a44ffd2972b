"""Analytic Hertz references (Johnson, Contact Mechanics, ch. 4; seed eqs 2.1-2.2).

Symbols (SI units): E1, nu1, E2, nu2 Young's moduli [Pa] and Poisson ratios of
the two bodies; E* the contact modulus, 1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2;
R the radius of the curved body [m]; F the normal force [N]; L a cylinder's
length [m]; a the contact radius, b the contact half-width [m]; p0 the peak
pressure [Pa]; d the approach [m].
"""
from __future__ import annotations

import math

import numpy as np


def contact_modulus(E1: float, nu1: float, E2: float, nu2: float) -> float:
    """E* [Pa] from 1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2 (Johnson eq. 4.22)."""
    return 1.0 / ((1.0 - nu1**2) / E1 + (1.0 - nu2**2) / E2)


def sphere(F: float, R: float, Estar: float) -> dict:
    """Hertz sphere on plane: a, p0, p_mean, approach d = a^2/R and k_n = 2 E* a."""
    a = (3.0 * F * R / (4.0 * Estar)) ** (1.0 / 3.0)
    return {
        "a": a,
        "p0": 3.0 * F / (2.0 * math.pi * a**2),
        "p_mean": F / (math.pi * a**2),
        "approach": a**2 / R,
        "k_n": 2.0 * Estar * a,
        "area": math.pi * a**2,
    }


def sphere_radius_for_peak(p0: float, R: float, Estar: float) -> float:
    """Contact radius at which the Hertz peak pressure is ``p0``: a = pi R p0 / (2 E*)."""
    return math.pi * R * p0 / (2.0 * Estar)


def cylinder(F: float, L: float, R: float, Estar: float) -> dict:
    """2D (plane-strain) Hertz line contact, load per length P' = F/L (seed eq. 2.1-2.2)."""
    P = F / L
    b = math.sqrt(4.0 * P * R / (math.pi * Estar))
    return {"b": b, "p0": 2.0 * P / (math.pi * b), "p_mean": P / (2.0 * b),
            "area": 2.0 * b * L}


def cylinder_halfwidth_for_peak(p0: float, R: float, Estar: float) -> float:
    """Half-width at which the 2D Hertz peak pressure is ``p0``: b = 2 R p0 / E*."""
    return 2.0 * R * p0 / Estar


def sphere_approach_fit(force, approach, Estar: float, R: float) -> dict:
    """Fit d = A F^(2/3) + B F to a sphere's force-approach curve; A against Hertz.

    The finite bodies add a nearly linear compliance B (references.md), so the
    Hertzian coefficient A_H = (3 / (4 E*))^(2/3) R^(-1/3) is compared on its own.

    Parameters
    ----------
    force, approach : array_like, shape (n,)
        Normal forces [N] and approaches [m].
    Estar, R : float
        Contact modulus [Pa] and sphere radius [m].

    Returns
    -------
    dict: A [m N^-2/3], B [m/N], A_hertz, error_A (A / A_hertz - 1)
    """
    F, d = np.asarray(force, dtype=float), np.asarray(approach, dtype=float)
    (A, B), *_ = np.linalg.lstsq(np.stack([F ** (2 / 3), F], axis=1), d, rcond=None)
    A_h = (3 / (4 * Estar)) ** (2 / 3) / R ** (1 / 3)
    return {"A": float(A), "B": float(B), "A_hertz": A_h, "error_A": float(A / A_h - 1)}
