"""Forced-response curves: continuation of the HB residual over frequency + peak refinement.

``compute_frf(model, harmonics, (omega_start, omega_end))`` traces the branch with
:func:`continuation.continuation`, reports for the response DOF the peak absolute
displacement over the period (``amplitude``) and the first-harmonic magnitude
(``amplitude_h1``), and refines the resonance peaks of ``amplitude``
(:func:`peaks.refine_peaks`); the highest is ``peak_omega``/``peak_amplitude``. The
points are as many as the curve's shape needs at the curve ``tolerance``
(:mod:`continuation`), at least ~1 / LAM_STEP.

Accuracy of the peak: the refinement locates the maximum of the *discrete* HB
curve (given H) to peaks.PEAK_TOL_REL in frequency, hence its amplitude to ~1e-12. The
discrete curve differs from the exact one by the truncation in H only when the friction
links are exact (the default, :func:`exact_links`); a sampled AFT (``aft="sampled"``,
and contacts whose normal load varies) adds an O(n_t^-2) error (2e-4 relative at
n_t = 256 on the Jenkins describing function) and ripples of that order on the curve
(the reversal point moves between samples as omega changes), so on a very flat peak two
neighbouring ripple maxima can compete: measured 4e-5 in amplitude and 3e-4 in
frequency between two runs of the same model.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np

from .aft import FrictionLink
from .block_lu import chain_factorizer
from .contact import ContactElement
from .continuation import CURVE_TOL, LAM_STEP, Branch, ContinuationError, continuation
from .fourier import FourierBasis, default_samples, parse_harmonics
from .homotopy import HomotopyError
from .model import Model
from .peaks import peak_indices, refine_peaks
from .residual import CondensedResidual, FullResidual, energy_per_cycle, make_residual
from .start import _stiffness_ratio, homotopy_start
from .steady_state import annotate

#: Newton tolerance relative to the residual's reference size (|F_ext| for the
#: full residual, |X| of the stuck linear response for the condensed one).
TOL_REL = 1e-10


#: Aliasing indicator (FourierBasis.alias_ratio at the peak) above which the
#: result carries a warning: a stick-slip force with kinks has a 1/h^2 tail,
#: ~1e-4 of its fundamental at h = n_t / 4 = 64; 1e-2 means the grid is too coarse.
ALIAS_WARN = 1e-2


class FRFError(RuntimeError):
    """The curve could not be completed; ``result`` holds the points computed so far."""

    def __init__(self, message: str, result: FRFResult):
        super().__init__(message)
        self.result = result


@dataclass
class FRFResult:
    """One forced-response curve (SI units: omega [rad/s], amplitudes [m])."""

    omega: np.ndarray
    amplitude: np.ndarray
    amplitude_h1: np.ndarray
    response: np.ndarray          # (points, n_b) harmonics of the response DOF
    solutions: list               # raw unknowns per point
    newton_iterations: int
    evaluations: int
    time_s: float
    harmonics: tuple
    n_t: int
    peak_omega: float = float("nan")
    peak_amplitude: float = float("nan")
    peak_amplitude_h1: float = float("nan")
    peak_h1_max: float = float("nan")
    peak_h1_max_omega: float = float("nan")
    peak_solution: np.ndarray | None = None
    peak_interior: bool = False
    alias_ratio: float = float("nan")
    peaks: list = field(default_factory=list)
    status: str = "complete"
    stable: list | None = None    # per point: Hill stability (None: not computed)
    extra: dict = field(default_factory=dict)
    truncation_error: dict | None = None
    problem: FRFProblem | None = field(default=None, repr=False)

    @property
    def points(self) -> int:
        return len(self.omega)

    def summary(self) -> dict:
        """JSON-able dictionary (the CLI's output); undefined numbers become None."""
        out = {
            "omega": self.omega, "amplitude": self.amplitude, "amplitude_h1": self.amplitude_h1,
            "peak_omega": self.peak_omega, "peak_amplitude": self.peak_amplitude,
            "peak_amplitude_h1": self.peak_amplitude_h1, "peak_h1_max": self.peak_h1_max,
            "peak_h1_max_omega": self.peak_h1_max_omega, "peak_interior": self.peak_interior,
            "peaks": [{k: _finite(v) for k, v in p.items()} for p in self.peaks],
            "points": self.points, "newton_iterations": self.newton_iterations,
            "residual_evaluations": self.evaluations, "time_s": self.time_s,
            "harmonics": list(self.harmonics), "n_t": self.n_t, "alias_ratio": self.alias_ratio,
            "aft": self.extra.get("aft"),
            "status": self.status, "stable": self.stable,
            "stability_checks": self.extra.get("stability_checks", 0),
            "peak_refined": self.extra.get("peak_refined"),
            "truncation_error": _finite_dict(self.truncation_error),
            "truncation_warning": self.extra.get("truncation_warning"),
        }
        if "accuracy" in self.extra:
            out["accuracy"] = _finite_dict(self.extra["accuracy"])
        out["stuck_links"] = self.extra.get("stuck_links")
        if "steady_state" in self.extra:
            out["steady_state"] = _finite_dict(self.extra["steady_state"])
            out["steady_state_warning"] = self.extra.get("steady_state_warning")
        return {k: _finite(v) for k, v in out.items()}


def _finite_dict(d):
    """A nested record with NaN/inf -> None (JSON has no NaN)."""
    if isinstance(d, dict):
        return {k: _finite_dict(v) for k, v in d.items()}
    if isinstance(d, (list, tuple)):
        return [_finite_dict(v) for v in d]
    return _finite(float(d)) if isinstance(d, (float, np.floating)) else d


def _finite(v):
    """NaN/inf -> None (JSON has no NaN), recursively through arrays."""
    if isinstance(v, np.ndarray):
        return [_finite(float(e)) for e in v.ravel()]
    if isinstance(v, float) and not np.isfinite(v):
        return None
    return v


class FRFProblem:
    """Residual, basis and response extraction for one model and harmonic set."""

    def __init__(self, model: Model, harmonics, n_t: int = 0, condensed: bool | None = None):
        self.model = model
        self.basis = FourierBasis(parse_harmonics(harmonics), n_t)
        self.residual = make_residual(model, self.basis, condensed)
        self.evaluations = 0
        # the continuation's LU (:class:`.corrector.ScaledSystem`): by blocks on a chain
        self.factorize = (chain_factorizer(self.basis.nb, self.residual.m, self.residual.dof_couplings())
                          if isinstance(self.residual, FullResidual) else None)

    def __call__(self, x, omega):
        if not self._valued(x, omega):
            self.evaluations += 1
        return self.residual(x, omega)

    def value(self, x, omega):
        """R alone (the residual's ``value``: a line search's trial point)."""
        self.evaluations += 1
        self._last_value = (x.copy(), omega)
        return self.residual.value(x, omega)

    def _valued(self, x, omega) -> bool:
        """True when :meth:`value` was last called at this point (its Jacobian is no new
        evaluation of the elements)."""
        last, self._last_value = getattr(self, "_last_value", None), None
        return last is not None and last[1] == omega and np.array_equal(last[0], x)

    def response(self, x, omega) -> np.ndarray:
        """Harmonics (n_b,) of the response DOF."""
        r = self.model.response_dof
        res = self.residual
        if isinstance(res, FullResidual):
            return x.reshape(self.basis.nb, res.m)[:, r]
        pos = np.flatnonzero(res.dofs == r)
        if pos.size:
            return x.reshape(self.basis.nb, res.m)[:, pos[0]]
        return res.displacements(x, omega, [r])[:, 0]

    def amplitude(self, x, omega) -> float:
        return self.basis.peak_abs(self.response(x, omega))

    def reference(self, omega0) -> float:
        """Size the Newton tolerance refers to."""
        if isinstance(self.residual, FullResidual):
            return float(np.linalg.norm(self.residual.Fext))
        return float(np.linalg.norm(self.residual.linear_guess(omega0)))

    def alias_ratio(self, x) -> float:
        """Largest aliasing indicator of the links' sampled forces (FourierBasis.alias_ratio);
        exact links (no sampling, ``FrictionLink.exact``) have none: 0."""
        samples = self.residual.link_samples(x)
        return max([self.basis.alias_ratio(F) for el, (_, F, _) in zip(self.residual.elements, samples)
                    if F is not None and not getattr(el, "exact", False)], default=0.0)

    def energy(self, x, omega) -> dict:
        """Energy per cycle [J]: excitation, viscous, friction (sampled loops), and the
        friction work of the retained force harmonics (equal to W_ext - W_visc exactly)."""
        X = self.residual.displacements(x, omega)
        out = energy_per_cycle(self.model, self.basis, X, omega)
        loops = self.residual.link_samples(x)
        out["W_friction"] = float(sum(w for _, _, w in loops))
        out["links"] = [w for _, _, w in loops]
        return out


#: Smallest curve tolerance: finer steps would resolve the corrector's own accuracy
#: (TOL_REL of the residual, ~1e-8 of the response near a resonance).
MIN_TOLERANCE = 1e-6
#: Default largest continuation step (scaled arclength, :mod:`continuation`): the
#: curve tolerance sizes the steps; this only bounds them on straight stretches.
DS_MAX = 0.5


#: Largest number of full-residual unknowns for which ``stability="auto"`` runs
#: Hill's method at every point (a (2N)^2 eigenproblem: ~5 ms at N = 200).
STABILITY_AUTO_MAX = 200


def check_peak_traced(result: FRFResult) -> None:
    """Raise FRFError when the highest peak lies at a stretch the continuation jumped (its
    corrector stalled and a homotopy restarted past it, ``result.extra["gaps"]``): the peak
    there is not resolved, and the response may grow without bound (a resonance without
    viscous damping whose friction cannot bound it, Den Hartog's: sdof, c = 0, slip force
    0.01 N against a force 0.05 N gave a peak of 1.4e5 m as a complete curve). The error's
    ``hint`` says what to change; ``result.status`` says what happened."""
    p = result.peak_omega
    for a, b in result.extra.get("gaps") or ():
        if p is not None and a - (b - a) <= p <= b + (b - a):  # within a gap's width of it
            result.status = (f"the peak at omega {p:.6g} rad/s lies at a stretch the corrector could not "
                             f"trace (no points in omega {a:.6g}-{b:.6g}): the response may grow without bound "
                             "there (a resonance with too little damping)")
            err = FRFError(result.status, result)
            err.hint = "add damping (C) or a larger slip force, or leave that frequency out of the range"
            raise err


def compute_frf(model: Model, harmonics, omega_range, n_t: int = 0, condensed=None,
                ds_max: float = DS_MAX, max_points: int = 2000, refine: bool = True,
                stability="auto", progress=None, aft: str = "exact",
                tolerance: float = CURVE_TOL, truncation_check: bool = True,
                accuracy: float | None = None, max_harmonic: int = 200,
                steady_state_check: bool = False) -> FRFResult:
    """Forced-response curve over ``omega_range = (start, end)`` [rad/s].

    The first point is Newton's from the stuck linear guess or, when that fails, the
    end of a homotopy in the excitation level (:mod:`homotopy`), so the curve does
    not depend on where the sweep starts. ``stability`` adds Hill's stability of every
    point (``result.stable``): "auto" (default) when the model has matrices and at most
    STABILITY_AUTO_MAX full unknowns, True at any size, both by Hill checks only where
    it can change (:func:`stability.along_branch`: the sign changes of det(dR/dx), the
    local maxima of the amplitude, the ends, every CHECK_SPACING points, bisection
    between checks that disagree), "all" by Hill's method at every point, False or
    "off" not at all. ``progress(done, total, label)``, if
    given, is called after every continuation point with the share of the frequency
    range covered, in percent (``total`` = 100), as ``contact_core``'s long stages do.
    ``aft``: "exact" (default) evaluates every Iwan friction link by its exact periodic
    loop (:func:`exact_links`), "sampled" by the sampled AFT on ``n_t`` samples (the
    reference of the sampling error); contacts with a normal load varying in time and
    elements without the exact path are sampled either way. ``tolerance``: the curve's
    accuracy, which sizes the continuation's steps (:mod:`continuation`, at least
    MIN_TOLERANCE); ``ds_max`` bounds them (scaled arclength). A peak refinement that
    fails keeps the curve's highest point (``extra["peak_refined"]`` False, a warning in
    the status; :mod:`peaks`). ``truncation_check``: estimate the truncation error of
    the peak in H (``result.truncation_error``, :func:`frf_accuracy.truncation_error`:
    the peak re-solved with ~1.5 H and ~2.25 H harmonics, capped at ``max_harmonic``), with a
    warning in ``extra["truncation_warning"]`` above :data:`accuracy.WARN_REL`.
    ``accuracy``: a relative tolerance on the peak amplitude; the harmonics are then
    raised per curve from ``harmonics`` until the estimate is below it
    (:func:`frf_accuracy.frf_to_accuracy`; ``extra["accuracy"]`` says what was used).
    ``steady_state_check``: time integrations at the refined peak from rest and from the
    harmonic balance's state (:func:`steady_state.check_peak`, seconds per model of a few
    DOFs) say whether the curve's branch is the state a start from rest reaches
    (``extra["steady_state"]``, a warning in ``extra["steady_state_warning"]`` when not).
    Every refined result names the links that never slip at the peak
    (``extra["stuck_links"]``: their mean position is the harmonic balance's convention).

    Raises
    ------
    ValueError for bad input; FRFError (a RuntimeError) when the continuation fails,
    carrying the points computed so far and the frequency reached.
    """
    w0, w1 = (float(w) for w in omega_range)
    if not (np.isfinite(w0) and np.isfinite(w1)) or w0 <= 0 or w1 <= 0 or w0 == w1:
        raise ValueError(f"omega range must be two different positive numbers, got {omega_range}")
    if aft not in ("exact", "sampled"):
        raise ValueError(f"aft must be 'exact' or 'sampled', got {aft!r}")
    if not (MIN_TOLERANCE <= tolerance < 1 and np.isfinite(ds_max) and ds_max > 0):
        raise ValueError(f"the curve tolerance must be in [{MIN_TOLERANCE:g}, 1) and the largest "
                         f"step a finite number > 0, got {tolerance}, {ds_max}")
    if accuracy is not None:
        from .frf_accuracy import frf_to_accuracy

        result = frf_to_accuracy(compute_frf, model, accuracy, omega_range, harmonics, max_harmonic,
                                 tol_rel=TOL_REL, n_t=n_t,
                                 condensed=condensed, ds_max=ds_max, max_points=max_points,
                                 refine=refine, stability=stability, progress=progress, aft=aft,
                                 tolerance=tolerance)
        return annotate(result, steady_state_check)
    t0 = time.perf_counter()
    model = exact_links(model, aft == "exact")
    n_base = n_t or stiff_samples(model, harmonics) or default_samples(max(parse_harmonics(harmonics)))
    tries = 1 if n_t else 1 + min(GRID_DOUBLINGS, max(0, int(np.log2(GRID_MAX / n_base))))
    spent = 0
    for k in range(tries):
        prob = FRFProblem(model, harmonics, n_base * 2**k, condensed)
        branch, gaps, error, start, tol = _trace(prob, w0, w1, (ds_max, tolerance), max_points,
                                                 progress)
        if not _grid_limited(error, gaps) or k == tries - 1:
            break
        spent += prob.evaluations
    prob.evaluations += spent  # the cost of the coarser attempts counts
    if error is not None:
        result = _collect(prob, branch, t0)
        result.status = branch.status = error
        result.extra["gaps"] = gaps
        result.extra["grid_doublings"] = k
        result.stable = _stability(prob, branch, stability)[0] if branch.lam else None
        raise FRFError(error, result)
    result = _collect(prob, branch, t0)
    result.extra["start"] = start
    result.extra["gaps"] = gaps
    result.extra["grid_doublings"] = k
    # how the friction links were evaluated: "exact" (no AFT sampling, n_t only scans
    # for the extrema), "sampled", or "mixed" (e.g. exact links and sampled contacts)
    kinds = {link.exact if isinstance(link, FrictionLink) else False for link in prob.model.links
             if isinstance(link, (FrictionLink, ContactElement))}
    result.extra["aft"] = {frozenset({True}): "exact", frozenset({False}): "sampled"}.get(
        frozenset(kinds), "mixed" if kinds else None)
    if gaps:
        result.status = (f"complete; {len(gaps)} restart(s) by homotopy after a stalled corrector, "
                         "no points in omega " + ", ".join(f"{a:.6g}-{b:.6g}" for a, b in gaps))
    result.stable, result.extra["stability_checks"] = _stability(
        prob, branch, stability, peak_indices(result.amplitude, 0.0))
    if refine:
        exact = None if all(getattr(el, "exact", True) for el in prob.model.links) else (
            lambda: FRFProblem(exact_links(prob.model), prob.basis.harmonics, prob.basis.n_t,
                               isinstance(prob.residual, CondensedResidual)))
        refine_peaks(prob, branch, result, tol, exact)
    result.alias_ratio = prob.alias_ratio(result.peak_solution)
    if result.alias_ratio > ALIAS_WARN:
        result.status += (f"; warning: AFT grid of {prob.basis.n_t} samples leaves "
                          f"{result.alias_ratio:.1e} of the force spectrum near Nyquist: "
                          "raise n_t")
    result.evaluations = prob.evaluations
    if truncation_check and refine:
        _check_truncation(result, max_harmonic)
    annotate(result, steady_state_check)
    result.time_s = time.perf_counter() - t0
    return result


def _check_truncation(result: FRFResult, max_harmonic: int) -> None:
    """``result.truncation_error`` and its warning (:mod:`frf_accuracy`), in place."""
    from .accuracy import warning
    from .frf_accuracy import truncation_error

    result.truncation_error = truncation_error(result, max_harmonic, tol_rel=TOL_REL)
    result.extra["truncation_warning"] = warning(result.truncation_error)


#: Stiffness ratio (stiffest friction link over the structure) up to which the
#: default AFT samples resolve the stick episodes, and the samples per period that
#: do so there (measured: 1e4 k, H = 15, 512 samples, 0.5 -> 2 rad/s: no gaps).
STIFF_SAMPLES_RATIO = 1e4
STIFF_SAMPLES_BASE = 512


def exact_links(model: Model, exact: bool = True) -> Model:
    """``model`` with every Iwan friction link's ``exact`` flag set to ``exact`` (links of
    other elements and other force elements as they are).

    Exact (:func:`aft.aft_link`): the loop's Fourier coefficients from the C core, the
    extrema of u located exactly and the loop between them integrated in closed form: no
    sampling error and no kinks where a stick episode starts or ends between samples, at
    the cost of a sampled evaluation (measured per link evaluation, H = 7, 256 samples:
    30 us sampled, 50 us exact; H = 15, 512: 90 us both). The sampled loop carries an
    O(n_t^-2) error that grows with the link's stiffness (a stick episode spans fewer
    samples): first-harmonic force of a Jenkins link at H = 7, 256 samples, k_t = 20:
    7e-4 relative, 2000: 1.2e-2; a stiff sampled curve needs thousands of samples
    (:func:`stiff_samples`) and stalls at its kinks.
    """
    from fmu_src.element import IwanElement

    links = [replace(link, exact=exact) if isinstance(link, FrictionLink)
             and isinstance(link.element, IwanElement) and link.exact != exact else link
             for link in model.links]
    return replace(model, links=links)


def stiff_samples(model: Model, harmonics) -> int:
    """Default AFT samples for ``model``: 0 (the basis default) unless its friction links
    are more than STIFF_SAMPLES_RATIO times stiffer than the structure.

    A slider sticks at a reversal until the relative displacement has changed by
    2 f_s / k_t; near a reversal u ~ u_r - a t^2 / 2, so a stick episode lasts
    ~ sqrt(4 f_s / (k_t a)): its share of the period, and the samples it spans at a
    fixed n_t, fall like k_t^-1/2. Above STIFF_SAMPLES_RATIO the grid is
    STIFF_SAMPLES_BASE sqrt(ratio / STIFF_SAMPLES_RATIO) samples, rounded up to a
    power of two (at least the default), so the samples per stick episode stay those
    that work at STIFF_SAMPLES_RATIO. Measured on the Jenkins FRF (gaps = stretches the
    corrector could not cross): H = 15, 0.5 -> 2 rad/s: 1e5 k: 512 samples 7 gaps,
    1024 4, 2048 (this rule) none; 1e6 k: 2048 2 gaps, 4096 none, 8192 (this rule)
    none; H = 3 from 0.5 rad/s at 1e5 k: 1024 samples 1 gap. Since the AFT's Jacobian
    costs only the stuck samples (``periodic_jac_rows``), a finer grid is cheap and
    its smaller kinks save corrector work: 1e6 k, H = 15: 4096 samples 737 points,
    11.1 evaluations per point, 3.4 s; 8192: 474 points, 5.4 per point, 2.2 s.
    """
    ratio = _stiffness_ratio(model)
    if ratio is None or ratio <= STIFF_SAMPLES_RATIO:
        return 0
    if all(link.exact for link in model.links if isinstance(link, FrictionLink)):
        return 0   # exact links: the grid only scans u' for its extrema
    need = STIFF_SAMPLES_BASE * np.sqrt(ratio / STIFF_SAMPLES_RATIO)
    default = default_samples(max(parse_harmonics(harmonics)))
    return int(max(default, 2 ** int(np.ceil(np.log2(need) - 1e-9))))


#: Doublings of the AFT grid tried, when n_t is not given, after a curve that stalled
#: (no first point, a stop with the step below its minimum, or restart gaps): the
#: whole curve is traced again on the finer grid. Measured on the Jenkins FRF with
#: f_s = P and c = 1e-4 (the link's force grazes f_s at the turning points, so a
#: slip episode spans ever fewer samples as the excess vanishes): 10 k, H = 3 stalls
#: at 1.1066 rad/s with 256-1024 samples and completes with 2048; 100 k, H = 7 from
#: 2 rad/s finds no first point with 256, stalls at 1.436 with 1024-2048, completes
#: with 8192. Cost: up to 2^(GRID_DOUBLINGS + 1) - 1 times a curve, on failure only.
GRID_DOUBLINGS = 5
#: Finest AFT grid the doublings go to.
GRID_MAX = 16384


def _grid_limited(error, gaps) -> bool:
    """A failure that a finer AFT grid may remove (see GRID_DOUBLINGS)."""
    if gaps:
        return True
    return error is not None and ("step below minimum" in error or "before the first point" in error)


def _trace(prob, w0, w1, steps, max_points, progress):
    """First point and continuation on one grid: (branch, gaps, error or None, start, tol)."""
    tol = TOL_REL * max(prob.reference(w0), 1e-300)
    try:
        x0, start = _coarse_start(prob, w0, tol) or homotopy_start(prob, w0, tol)
    except HomotopyError as err:
        msg = f"continuation stopped before the first point: {err}"
        return Branch(status=str(err)), [], msg, None, tol
    on_point = None
    if progress is not None:
        def on_point(w):
            progress(min(100, round(100 * abs(w - w0) / abs(w1 - w0))), 100, "continuation")
    branch, gaps, error = _sweep(prob, x0, w0, w1, tol, steps, max_points, on_point)
    return branch, gaps, error, start, tol


#: Highest harmonic of the coarse start (:func:`_coarse_start`), and the Newton iterations
#: its correction at the full set may take (measured from H = 5 to 31: 0-26 where it
#: converges, on the stiff links of chain5 and chain3 with Levenberg-Marquardt steps;
#: chain3 at F = 2 N, k = 200 N/m, H >= 10 does not within 40, and the full start follows).
START_H = 5
COARSE_ITER = 30


def _coarse_start(prob, w0: float, tol: float):
    """(x, info) of the first point found at the harmonics of ``prob`` up to START_H
    (:func:`start.homotopy_start` there), padded with zeros and corrected by Newton at all
    of them; None when ``prob`` has no more harmonics than that, or either step fails (the
    caller starts at the full set then). The start's homotopy costs about as many steps
    at any H (measured on chain5 at H = 31: 30 points, 0.75 s CPU, 9 % of the curve), so
    they are taken where an evaluation is cheap."""
    from .accuracy import pad
    from .newton import NewtonError, newton

    hs = tuple(h for h in prob.basis.harmonics if h <= START_H)
    if not hs or len(hs) == len(prob.basis.harmonics):
        return None
    low = type(prob)(prob.model, hs, prob.basis.n_t, isinstance(prob.residual, CondensedResidual))
    try:
        x, info = homotopy_start(low, w0, TOL_REL * max(low.reference(w0), 1e-300))
        res = newton(lambda z: prob(z, w0)[:2], pad(x, low.basis, prob.basis), tol, COARSE_ITER,
                     factor=prob.factorize)
    except (HomotopyError, NewtonError):
        return None
    return res.x, {**info, "method": f"{info['method']} at H <= {START_H}, then Newton at H = {prob.basis.H}"}


#: Restarts allowed per curve after a stalled corrector (:func:`_sweep`).
MAX_RESTARTS = 100
#: Frequency jumps tried for a restart, as fractions of the range: the smallest
#: that gives a first point by :func:`start.homotopy_start` is taken.
RESTART_JUMPS = (1e-3, 4e-3, 1.6e-2)


def _sweep(prob, x0, w0, w1, tol, steps, max_points, on_point=None):
    """Continuation from (x0, w0) to w1 with restarts: (Branch, gaps, error or None).

    When the corrector stalls ("step below minimum": on a stiff contact the residual
    is a staircase of AFT-sample kinks with local minima of |R|), the curve is
    restarted a small jump further by the start strategies (Newton, excitation and
    contact-stiffness homotopies), which do not depend on the previous point. The
    skipped interval is reported (``gaps``); a friction FRF is single-valued there,
    so no branch is lost, but a fold inside a gap would be (the status names it).
    """
    merged, gaps = Branch(), []
    sign = 1.0 if w1 > w0 else -1.0
    for _ in range(MAX_RESTARTS + 1):
        try:
            br = continuation(prob, x0, w0, w1, tol, ds_max=steps[0], tolerance=steps[1],
                              max_points=max_points - len(merged.lam), on_point=on_point,
                              rtol=TOL_REL, lam_step=LAM_STEP)
            error = None
        except ContinuationError as err:
            br, error = err.branch, str(err)
        _extend(merged, br)
        if error is None:
            merged.status = "complete"
            return merged, gaps, None
        if "step below minimum" not in error:
            return merged, gaps, error
        w_last = merged.lam[-1] if merged.lam else w0
        for jump in RESTART_JUMPS:
            w_try = w_last + sign * jump * abs(w1 - w0)
            if sign * (w_try - w1) > 0:
                w_try = w1
            try:
                x0, _ = homotopy_start(prob, w_try, tol)
            except HomotopyError:
                continue
            gaps.append((w_last, w_try))
            w0 = w_try
            break
        else:
            return merged, gaps, error + "; no restart within " + f"{RESTART_JUMPS[-1]:g} of the range"
        if w0 == w1:
            _extend(merged, Branch(x=[x0], lam=[w1], iterations=[0]))
            merged.status = "complete"
            return merged, gaps, None
    return merged, gaps, f"more than {MAX_RESTARTS} restarts"


def _extend(merged, br):
    n = len(br.x)
    for x, w, it, d, t in zip(br.x, br.lam, br.iterations, br.det_sign or [0.0] * n,
                              br.tangent or [None] * n):
        merged.append(x, w, it, d, t)


def _collect(prob: FRFProblem, branch, t0) -> FRFResult:
    om = np.asarray(branch.lam)
    resp = np.array([prob.response(x, w) for x, w in zip(branch.x, om)]).reshape(len(om), prob.basis.nb)
    b = prob.basis
    h1 = b.magnitude(resp.T, 1) if 1 in b.harmonics else np.full(len(om), np.nan)
    amp = np.array([b.peak_abs(r) for r in resp])
    i = int(np.argmax(amp)) if len(amp) else 0
    return FRFResult(om, amp, np.asarray(h1), resp, list(branch.x), int(sum(branch.iterations)),
                     prob.evaluations, time.perf_counter() - t0, b.harmonics, b.n_t, problem=prob,
                     peak_omega=float(om[i]) if len(om) else float("nan"),
                     peak_amplitude=float(amp[i]) if len(amp) else float("nan"),
                     peak_amplitude_h1=float(h1[i]) if len(amp) else float("nan"),
                     peak_solution=branch.x[i] if len(amp) else None,
                     status=branch.status)


def _stability(prob: FRFProblem, branch, mode, anchors=()):
    """Hill stability per branch point (list of bool) and the number of Hill checks, or
    (None, 0) when not computed (``mode`` as :func:`compute_frf`'s ``stability``)."""
    from .residual import FullResidual
    from .stability import along_branch, is_stable

    lin = prob.model.linear
    if mode in (False, None, "off") or lin.M is None or lin.K is None:
        return None, 0
    full = prob.residual if isinstance(prob.residual, FullResidual) else None
    size = prob.basis.nb * prob.model.n
    if mode == "auto" and size > STABILITY_AUTO_MAX:
        return None, 0
    if full is None:
        full = FullResidual(prob.model, prob.basis)
    V = full.viscous_operator()
    V = V if np.any(V) else None

    def check(i):
        x, w = branch.x[i], branch.lam[i]
        X = prob.residual.displacements(x, w).ravel() if full is not prob.residual else x
        _, J, _ = full(X, w)
        return is_stable(J, lin, prob.basis, w, V)[0]
    n = len(branch.lam)
    if mode == "all":
        return [check(i) for i in range(n)], n
    det = branch.det_sign if len(branch.det_sign) == n else [0.0] * n
    return along_branch(n, det, check, anchors)
