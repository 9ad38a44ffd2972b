"""Continuation over any model parameter at a fixed frequency (forcing level, slip scale, ...).

NLvib style: :func:`continuation.continuation` knows only ``R(x, lam) -> (R, dR/dx,
dR/dlam)``; this module builds that callable for an HB problem whose model depends
on a parameter through a factory ``model_at(lam) -> Model``:

* ``dR/dlam`` exactly when the parameter is the excitation level (R is affine in it:
  ``R(x; lam) = N(x) - lam f``, :func:`homotopy.forcing_vector`), else by a central
  difference of the residual at fixed x (two residual evaluations without Jacobian,
  step ``FD_STEP`` relative; the residual is piecewise smooth in the slip strengths,
  so the difference is exact to O(h^2) between kinks).
* Ready-made factories: :func:`forcing_level` and :func:`slip_scale` (every friction
  slider's strength times lam, for Iwan/Jenkins links).

Curves over a parameter: :func:`.parameter_curve.parameter_curve`; the contact-stiffness factory
also serves the start of stiff models (:mod:`start`).
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from .aft import FrictionLink
from .fourier import FourierBasis, parse_harmonics
from .residual import make_residual

#: Relative step of the central difference in lam.
FD_STEP = 1e-6
#: Residuals kept (a point and its two difference neighbours, for two points).
CACHE_SIZE = 6


def forcing_level(model):
    """Factory lam -> the model with its excitation times lam."""
    return lambda lam: replace(model, forcing={h: lam * f for h, f in model.forcing.items()})


def slip_scale(model):
    """Factory lam -> the model with every friction slider's strength times lam (Iwan links)."""
    from fmu_src.element import IwanElement

    def at(lam):
        return _with_iwan_links(model, lambda el: IwanElement.from_sliders(
            el.k, el.fs * el.scale * lam, el.k_res, el.N_ref))
    return at


def contact_stiffness_scale(model):
    """Factory lam -> the model with every friction slider's stiffness (and residual
    stiffness) times 10**lam, slip strengths unchanged (lam = 0: the model itself).

    The logarithmic parameter lets one continuation run over decades of stiffness.
    The factory carries the exact dR/dlam (:class:`StiffnessScale`).
    """
    return StiffnessScale(model)


class StiffnessScale:
    """Model family of :func:`contact_stiffness_scale`, with its exact dR/dlam.

    An Iwan link whose spring stiffnesses are all scaled by s (strengths kept) has the
    force of the unscaled link at s times the displacement: every play radius
    r_j = g_j / (s k_j) shrinks as the input grows, F(q; s k) = F(s q; k) (the fully
    stuck line k_0 s q too). So dF/ds = F'(s q; k) q = (dF/dq at s) q / s and, with
    s = 10**lam, dF/dlam = ln(10) (dF/dq) q: the links' Jacobian applied to their own
    displacement, from the evaluation just made. Saves the two residual evaluations of
    the central difference per continuation step and has no truncation error.
    """

    def __init__(self, model):
        self.model = model

    def __call__(self, lam):
        from fmu_src.element import IwanElement

        s = 10.0**lam
        return _with_iwan_links(self.model, lambda el: IwanElement.from_sliders(
            el.k * s, el.fs * el.scale, el.k_res * s, el.N_ref))

    @staticmethod
    def dR_dlam(residual, x, omega):
        """dR/dlam (N,) at x of ``residual`` (a residual of this family)."""
        from fmu_src.element import IwanElement

        def scaled(el):
            return isinstance(el, FrictionLink) and isinstance(el.element, IwanElement)
        return np.log(10.0) * residual.element_action(x, omega, scaled)


class ParameterProblem:
    """R(x, lam) at fixed omega for a model family (module docstring)."""

    def __init__(self, model_at, harmonics, omega: float, n_t: int = 0, condensed=None,
                 affine: bool = False):
        self.model_at, self.omega, self.affine = model_at, float(omega), affine
        self.basis = FourierBasis(parse_harmonics(harmonics), n_t)
        self.condensed = condensed
        self._cache = {}
        self._base = None

    def residual(self, lam):
        """The residual at ``lam`` (a few kept). A model that differs from the first only
        in its links' elements (slip strength, contact stiffness) reuses the first
        residual's operators (``with_elements``): no rebuild per parameter value."""
        key = float(lam)
        if key not in self._cache:
            if len(self._cache) >= CACHE_SIZE:
                self._cache.pop(next(iter(self._cache)))   # the oldest
            model = self.model_at(key)
            try:
                res = self._base.with_elements(model) if self._base is not None else None
            except ValueError:
                res = None
            if res is None:
                res = make_residual(model, self.basis, self.condensed)
                self._base = self._base or res
            self._cache[key] = res
        return self._cache[key]

    def __call__(self, x, lam):
        """R, dR/dx, dR/dlam; a parameter the factory refuses (a predictor that left the
        model's range) gives a non-finite residual, which Newton's line search rejects."""
        try:
            return self._eval(x, lam)
        except (ValueError, ArithmeticError):
            n = np.size(x)
            return np.full(n, np.nan), np.eye(n), np.zeros(n)

    def _eval(self, x, lam):
        res = self.residual(lam)
        R, J, _ = res(x, self.omega)
        exact = getattr(self.model_at, "dR_dlam", None)
        if exact is not None:
            return R, J, exact(res, x, self.omega)
        h = FD_STEP * max(abs(lam), 1.0)
        if self.affine:  # R(x; lam) = N(x) - lam f: the difference is exact at any step
            dl = self.residual(lam + 1.0)(x, self.omega, jac=False) - R
        else:
            dl = (self.residual(lam + h)(x, self.omega, jac=False)
                  - self.residual(lam - h)(x, self.omega, jac=False)) / (2 * h)
        return R, J, dl


def _with_iwan_links(model, remake):
    """The model with every Iwan friction link's element replaced by ``remake(element)``."""
    from fmu_src.element import IwanElement

    links = [FrictionLink(remake(link.element), link.dof_a, link.dof_b, link.name, link.exact)
             if isinstance(link, FrictionLink) and isinstance(link.element, IwanElement) else link
             for link in model.links]
    return replace(model, links=links)
