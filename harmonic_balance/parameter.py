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

The first point is solved like an FRF's (Newton from the stuck guess, else the
excitation homotopy), so the curve does not depend on where it starts.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np

from .aft import FrictionLink
from .continuation import ContinuationError, continuation
from .fourier import FourierBasis, parse_harmonics
from .homotopy import HomotopyError, homotopy_start
from .residual import FullResidual, make_residual

#: Relative step of the central difference in lam.
FD_STEP = 1e-6
#: Newton tolerance relative to the stuck response's size (as frf.TOL_REL).
TOL_REL = 1e-10


def forcing_level(model):
    """Factory lam -> the model with its excitation times lam."""
    return lambda lam: replace(model, forcing={h: lam * f for h, f in model.forcing.items()})


def slip_scale(model):
    """Factory lam -> the model with every friction slider's strength times lam (Iwan links)."""
    from fmu_src.element import IwanElement

    def at(lam):
        links = []
        for link in model.links:
            el = link.element
            if not isinstance(link, FrictionLink) or not isinstance(el, IwanElement):
                links.append(link)
                continue
            new = IwanElement.from_sliders(el.k, el.fs * el.scale * lam, el.k_res, el.N_ref)
            links.append(FrictionLink(new, link.dof_a, link.dof_b, link.name))
        return replace(model, links=links)
    return at


@dataclass
class ParameterCurve:
    """Solutions along lam at fixed omega: lam, amplitude (peak |x| of the response DOF)."""

    lam: np.ndarray
    amplitude: np.ndarray
    solutions: list
    newton_iterations: int
    time_s: float
    stable: list | None = None
    status: str = "complete"


class ParameterProblem:
    """R(x, lam) at fixed omega for a model family (module docstring)."""

    def __init__(self, model_at, harmonics, omega: float, n_t: int = 0, condensed=None,
                 affine: bool = False):
        self.model_at, self.omega, self.affine = model_at, float(omega), affine
        self.basis = FourierBasis(parse_harmonics(harmonics), n_t)
        self.condensed = condensed
        self._cache = {}

    def residual(self, lam):
        key = float(lam)
        if key not in self._cache:
            if len(self._cache) > 4:
                self._cache.clear()
            self._cache[key] = make_residual(self.model_at(key), self.basis, self.condensed)
        return self._cache[key]

    def __call__(self, x, lam):
        R, J, _ = self.residual(lam)(x, self.omega)
        h = FD_STEP * max(abs(lam), 1.0)
        if self.affine:  # R(x; lam) = N(x) - lam f: the difference is exact at any step
            dl = self.residual(lam + 1.0)(x, self.omega, jac=False) - R
        else:
            dl = (self.residual(lam + h)(x, self.omega, jac=False)
                  - self.residual(lam - h)(x, self.omega, jac=False)) / (2 * h)
        return R, J, dl


def parameter_curve(model_at, harmonics, lam_range, omega: float, n_t: int = 0,
                    condensed=None, affine: bool = False, ds_max: float = 0.1,
                    max_points: int = 2000, stability: bool = True) -> ParameterCurve:
    """Continuation in lam over ``lam_range = (start, end)`` at fixed ``omega`` [rad/s].

    Parameters
    ----------
    model_at : callable float -> Model (e.g. :func:`forcing_level`, :func:`slip_scale`)
    affine : bool, True when R is affine in lam (the excitation level): exact dR/dlam

    Raises
    ------
    RuntimeError (ContinuationError or HomotopyError) with the reason; the points so far
    are on ``err.branch`` for a ContinuationError.
    """
    from .frf import FRFProblem

    l0, l1 = (float(v) for v in lam_range)
    if not (np.isfinite(l0) and np.isfinite(l1)) or l0 == l1:
        raise ValueError(f"parameter range must be two different finite numbers, got {lam_range}")
    t0 = time.perf_counter()
    pp = ParameterProblem(model_at, harmonics, omega, n_t, condensed, affine)
    start = FRFProblem(model_at(l0), harmonics, n_t, condensed)
    tol = TOL_REL * max(float(np.linalg.norm(start.residual.linear_guess(omega))), 1e-300)
    x0, _ = homotopy_start(start, omega, tol)
    status = "complete"
    try:
        br = continuation(pp, x0, l0, l1, tol, ds_max=ds_max, max_points=max_points)
    except ContinuationError as err:
        br, status = err.branch, str(err)
    amp = np.array([FRFProblem(model_at(l), harmonics, n_t, condensed).amplitude(x, omega)
                    for x, l in zip(br.x, br.lam)])
    stable = _stable(pp, br) if stability else None
    return ParameterCurve(np.asarray(br.lam), amp, list(br.x), int(sum(br.iterations)),
                          time.perf_counter() - t0, stable, status)


def _stable(pp, br):
    from .stability import is_stable

    out = []
    for x, lam in zip(br.x, br.lam):
        res = pp.residual(lam)
        model = res.model
        if model.linear.M is None or model.linear.K is None:
            return None
        full = res if isinstance(res, FullResidual) else FullResidual(model, pp.basis)
        X = x if full is res else res.displacements(x, pp.omega).ravel()
        _, J, _ = full(X, pp.omega)
        out.append(is_stable(J, model.linear, pp.basis, pp.omega)[0])
    return out


__all__ = ["forcing_level", "slip_scale", "parameter_curve", "ParameterCurve", "HomotopyError"]
