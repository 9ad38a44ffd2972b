"""The first solution of a curve, wherever it starts: Newton, else homotopies.

Order (each step only when the previous one failed):

1. Newton (globalised, :mod:`newton`) from the stuck linear guess.
2. Homotopy in the excitation level (:func:`homotopy.solve_with_homotopy`): from a
   level where the links stick up to the requested one.
3. Homotopy in the contact stiffness (:func:`parameter.contact_stiffness_scale`):
   every friction slider softened to the structure's stiffness, solved there (by
   1-2), then continued in log10 of the stiffness factor back to the model.

Why both homotopies: the excitation homotopy crosses the stick-slip onset, where a
very stiff contact (1e4 k and more) makes the HB residual a staircase of AFT-sample
kinks with local minima of |R| (measured: Newton and Levenberg-Marquardt stall at
|R| ~ 0.2-0.3 for contact stiffness 1e6 k at omega = 0.5); the stiffness homotopy
stays at the requested excitation, in gross slip when the requested point slips,
and reached 1e6 k at omega = 1 and 2 rad/s in 31 and 65 points (1.5 s, 2 s, H = 7).
Models whose links are STIFF_RATIO times stiffer than the structure try the
stiffness homotopy first (the excitation homotopy's failures cost up to ~75 s), their
first Newton fails fast (no Levenberg-Marquardt: the stuck guess of a stiff link is
rarely near the answer), and when their AFT grid is COARSE_FACTOR times H's default
(1e5 k and stiffer, :func:`frf.stiff_samples`) the stiffness homotopy runs on the
default grid and Newton finishes on the requested one (the slow part, the homotopy's
steps, on the cheap grid).
"""
from __future__ import annotations

import numpy as np

from .aft import FrictionLink
from .continuation import ContinuationError, continuation
from .fourier import FourierBasis, default_samples
from .homotopy import HomotopyError, forcing_vector, solve_with_homotopy
from .newton import NewtonError, evaluation_errors, newton
from .parameter import ParameterProblem, contact_stiffness_scale
from .residual import CondensedResidual, make_residual

#: Ratio of the stiffest friction link's stuck stiffness to the structure's largest
#: diagonal stiffness above which the stiffness homotopy is tried before the
#: excitation homotopy.
STIFF_RATIO = 100.0


def homotopy_start(prob, omega: float, tol: float):
    """First solution (N,) of an FRF problem at ``omega`` (module docstring) and an info dict.

    Parameters
    ----------
    prob : harmonic_balance.frf.FRFProblem (model, basis, residual; callable (x, omega))
    omega : float [rad/s]
    tol : float, absolute tolerance on |R|_2

    Raises
    ------
    HomotopyError naming every attempt and why it failed.
    """
    x0 = prob.residual.linear_guess(omega)
    ratio = _stiffness_ratio(prob.model)
    stiff = ratio is not None and ratio >= STIFF_RATIO

    def fine(z):
        return prob(z, omega)[:2]

    try:
        # a stiff link's stuck guess is rarely near the answer: fail fast (no LM)
        res = newton(fine, x0, tol, lm=not stiff)
        return res.x, {"method": "newton", "iterations": res.iterations}
    except NewtonError as err:
        errors = [f"from the stuck linear guess: {err}"]
    cond = isinstance(prob.residual, CondensedResidual)
    basis = prob.basis
    coarse = default_samples(max(basis.harmonics))
    if stiff and basis.n_t >= COARSE_FACTOR * coarse:
        # The stiffness homotopy on a coarse AFT grid, then Newton on the requested one
        # from there (the excitation homotopy's failures are the slow ones: not here).
        try:
            xc, info = _stiffness(prob.model, FourierBasis(basis.harmonics, coarse), cond,
                                  omega, tol, ratio)
            res = newton(fine, xc, tol, lm=False)
            info.update(method=f"stiffness homotopy on {coarse} samples, then Newton",
                        polish_iterations=res.iterations)
            return res.x, info
        except (HomotopyError, NewtonError) as err:
            errors.append(f"on {coarse} samples: {err}")
    x, info = _homotopies(prob.model, basis, cond, omega, tol, ratio, errors)
    return x, info


#: A stiff model's homotopy runs on the harmonics' default AFT grid first when the
#: requested grid is at least this many times finer: measured on the Jenkins
#: oscillator at 1e6 k, H = 15, 8192 samples: the stiffness homotopy from 0.5 rad/s
#: 1.8 s on the fine grid, 0.5 s on 512 samples + 3 Newton iterations on 8192; of
#: 36 (c, f_s, omega) starts, the polish failed in none, the coarse homotopy in two
#: (at resonance, then the fine grid's homotopy is run as before).
COARSE_FACTOR = 4


def _homotopies(model, basis, cond, omega, tol, ratio, errors):
    """The excitation and stiffness homotopies (stiffness first for stiff models) on
    ``basis``; (x, info) of the first that arrives, else HomotopyError with ``errors``
    and theirs."""
    tries = [("excitation homotopy", _forcing), ("stiffness homotopy", _stiffness)]
    if ratio is not None and ratio >= STIFF_RATIO:
        tries.reverse()
    for name, attempt in tries:
        try:
            x, info = attempt(model, basis, cond, omega, tol, ratio)
        except HomotopyError as err:
            errors.append(f"{name}: {err}")
            continue
        info["method"] = name
        return x, info
    raise HomotopyError(f"no solution at fixed parameter {omega:.6g}: " + "; ".join(errors))


def _forcing(model, basis, cond, omega, tol, ratio):
    res = make_residual(model, basis, cond)
    x0 = res.linear_guess(omega)
    try:
        f = forcing_vector(lambda m: make_residual(m, basis, cond), model, x0, omega)
    except evaluation_errors() as err:  # evaluated only when it raised
        raise HomotopyError(f"the residual cannot be evaluated at the linear guess ({err})") from err
    return solve_with_homotopy(lambda z: res(z, omega)[:2], x0, f, tol)


def _stiffness(model, basis, cond, omega, tol, ratio):
    if ratio is None or ratio <= 1.0:
        raise HomotopyError("no friction link stiffer than the structure to soften")
    pp = ParameterProblem(contact_stiffness_scale(model), basis.harmonics, omega, basis.n_t, cond)
    lam0 = -float(np.log10(ratio))
    soft = pp.model_at(lam0)
    try:
        x_soft = newton(lambda z: pp(z, lam0)[:2], pp.residual(lam0).linear_guess(omega), tol).x
    except NewtonError:
        x_soft, _ = _forcing(soft, basis, cond, omega, tol, None)
    try:
        # A homotopy only has to arrive, not to resolve its path (as the excitation
        # homotopy): no curve tolerance, long steps. Measured at 1e6 k, H = 15, 4096 samples:
        # 70 -> 33 points from 0.5 rad/s, 33 -> 14 from 2 rad/s.
        br = continuation(pp, x_soft, lam0, 0.0, tol, ds_max=2.0, tolerance=None)
    except ContinuationError as err:
        raise HomotopyError(f"from 10^{lam0:.3g} of the contact stiffness: {err}") from None
    return br.x[-1], {"start_level": lam0, "points": len(br.lam),
                      "iterations": int(sum(br.iterations))}


def _stiffness_ratio(model):
    """Stiffest friction link's k0 over the structure's largest diagonal stiffness, or None."""
    k0 = [link.k0 for link in model.links if isinstance(link, FrictionLink)]
    K = model.linear.K
    if not k0 or K is None:
        return None
    ks = float(np.abs(np.diag(K)).max())
    return max(k0) / ks if ks > 0 else None
