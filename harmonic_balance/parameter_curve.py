"""Curves over a model parameter at a fixed frequency (forcing level, slip scale, ...).

The parameter's residual is :class:`.parameter.ParameterProblem`; this module traces it
with :func:`.continuation.continuation` from a homotopy start, with the friction links
exact as :func:`.frf.compute_frf` makes them, and checks each point's stability.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from .continuation import ContinuationError, continuation
from .frf import DS_MAX, TOL_REL, FRFProblem, exact_links
from .parameter import ParameterProblem
from .start import homotopy_start


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


def parameter_curve(model_at, harmonics, lam_range, omega: float, n_t: int = 0,
                    condensed=None, affine: bool = False, ds_max: float = DS_MAX,
                    max_points: int = 2000, stability: bool = True) -> ParameterCurve:
    """Continuation in lam over ``lam_range = (start, end)`` at fixed ``omega`` [rad/s].

    Parameters
    ----------
    model_at : callable float -> Model (e.g. :mod:`parameter`'s forcing_level, slip_scale,
        contact_stiffness_scale)
    affine : bool, True when R is affine in lam (the excitation level): exact dR/dlam

    Raises
    ------
    HomotopyError (a RuntimeError) when no first point is found; a curve that stops
    early is returned with its points and ``status`` saying why.
    """
    l0, l1 = (float(v) for v in lam_range)
    if not (np.isfinite(l0) and np.isfinite(l1)) or l0 == l1:
        raise ValueError(f"parameter range must be two different finite numbers, got {lam_range}")
    t0 = time.perf_counter()
    given = model_at

    def model_at(lam):  # exact friction links, as compute_frf's
        return exact_links(given(lam))
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
    stable = _parameter_stability(pp, br) if stability else None
    return ParameterCurve(np.asarray(br.lam), amp, list(br.x), int(sum(br.iterations)),
                          time.perf_counter() - t0, stable, status)


def _parameter_stability(pp, br):
    from .residual import FullResidual
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

