"""Mistuning study of a UPD bladed disk: Monte Carlo samples as cached tasks on Dask.

A study draws every mistuning pattern first (``harmonic_balance.bladed_disk.mistuning``:
seeded per sample, so a resumed or extended study draws the same patterns) and refuses
a bad one before any work. The tuned sector's peak on the band is the reference (the
sector's harmonic balance, or its linear limit for ``damper = "free" | "stuck"``). A
sample is the full ring's forced response (``ring_hb`` with ``ring_fast`` or
``ring_solve``, or the linear ring) and every blade's peak; a task is a chunk of samples
solved with one :class:`SampleModel` (:func:`run_chunk`). Each sample's result is stored in the shared cache
(:class:`damper.cache.Store`) under a key of the model, the solver settings, the
pattern and the code version, so an interrupted study computes only the samples it has
not stored. A sample whose solve fails is reported with its message (not cached: a
later run tries it again), the study goes on. ``until_ci`` stops the study after the
first chunk (in index order) at which the 0.95 quantile's interval
(:mod:`damper.mistuning_stats`) is narrow enough.

Symbols: N_b blades; a_j the peak first-harmonic amplitude of blade j's response DOF;
amplification = max_j a_j / a_tuned; sigma_f the standard deviation of the blade
frequencies (std / 2 for stiffness factors, std for frequency factors).

Band: ``band_hz``, else around the tuned peak f_t (found on the config's
``load.band_hz``): from f_t (1 - w) to f_t (1 + w), with the damper up to the tuned
stuck linear peak f_stuck (1 + w) when that is higher (mistuning can move a blade's
peak up to the stuck one: measured on four blades), w = :data:`BAND_MARGIN` +
:data:`BAND_SIGMAS` sigma_f, each end kept within the frequencies a blade's factor can
reach (0.5 ... 2 times the tuned ones, :func:`default_band`). Below the tuned peak the
friction-damped peaks do not move much, and far below it the dampers are stuck and slow to solve (``ring_solve``). A
sample whose largest peak lies at an end of the default band is solved again on the band
widened there by w, at most :data:`BAND_WIDENINGS` times (its ``band_hz`` in the result);
at an end of a given band, or past the widenings, it fails (the peak is outside).
"""
from __future__ import annotations

import hashlib
import json
import os
import time
from dataclasses import asdict, dataclass, replace

import numpy as np

from damper import mistuning_stats
from damper.cache import Store, make_key
from damper.provenance import code_version

#: Part of every sample's key (bump when a sample's result format or meaning changes:
#: 2, the full solver's grid resolves every blade's peak; 3, a peak at the default band's
#: end is searched on the band widened there).
VERSION = 3
#: Modules a sample runs (their source hash is part of the key).
MODULES = ("harmonic_balance", "fmu_src")
#: Quantiles of the amplification factor reported.
QUANTILES = (0.05, 0.25, 0.5, 0.75, 0.95)
#: Default band margin: BAND_MARGIN + BAND_SIGMAS sigma_f beyond the tuned peaks (module
#: docstring; a blade's frequency scatters by sigma_f).
BAND_MARGIN, BAND_SIGMAS = 0.02, 3.0
#: Times the default band is widened by its margin at the end where a pattern's largest
#: peak lies (:func:`_solve_sample`) before the sample fails.
BAND_WIDENINGS = 2
DAMPERS = ("nonlinear", "free", "stuck")
#: Chunks: a worker solves a chunk of samples with one model (:class:`SampleModel`).
#: About CHUNKS_PER_WORKER chunks per worker balance the load (a chunk's samples differ
#: in cost) while each worker builds its model a few times only; MAX_CHUNK bounds the work
#: an interruption loses. With ``until_ci`` the chunks have CHUNK_UNTIL_CI samples and the
#: interval is checked after each, in index order.
CHUNKS_PER_WORKER, MAX_CHUNK, CHUNK_UNTIL_CI = 4, 100, 20


class AllSamplesFailed(RuntimeError):
    """Every sample's solve failed; ``summary`` is the study's JSON with each sample's error
    (statistics None)."""

    def __init__(self, message: str, summary: dict):
        super().__init__(message)
        self.summary = summary
#: Ring solvers: ``fast`` (``ring_fast``: adaptive continuation, Hermite peaks) and
#: ``full`` (``ring_solve``: every point of the grid solved; the reference).
SOLVERS = ("fast", "full")


@dataclass
class Study:
    """What a mistuning study computes (SI units; frequencies in Hz).

    ``factors`` (one pattern, N_b values) replaces the random draw; ``kind`` says whether
    they (or the drawn ones) are stiffness or frequency factors. ``accuracy`` (relative, on
    the peak amplitude) chooses H on the tuned sector (from ``harmonics``, by the truncation
    estimate of :mod:`harmonic_balance.bladed_disk.accuracy`); every sample then runs at that H.
    """

    config: str | None = None
    blades: int | None = None
    engine_order: int | None = None
    std: float = 0.02
    samples: int = 20
    seed: int = 1
    kind: str = "stiffness"
    distribution: str = "normal"
    factors: list | None = None
    damper: str = "nonlinear"
    cf: float | None = None
    f0: float | None = None
    harmonics: int = 7
    band_hz: list | None = None
    points: int = 41
    until_ci: float | None = None
    solver: str = "fast"
    accuracy: float | None = None

    def load(self):
        """The validated UPD config with ``blades`` / ``engine_order`` applied (ValueError)."""
        from harmonic_balance.bladed_disk.config import load_config

        cfg = load_config(self.config)
        changes = {}
        if self.blades is not None:
            changes["disk__blades"] = self.blades
            if (self.engine_order is None and isinstance(self.blades, int) and self.blades >= 2
                    and cfg.engine_order > self.blades // 2):
                raise ValueError(f"blades {self.blades} with the model's engine order {cfg.engine_order} "
                                 f"(above blades/2 = {self.blades // 2}): give the engine order too, "
                                 f"0 .. {self.blades // 2}")
        if self.engine_order is not None:
            changes["disk__engine_order"] = self.engine_order
        return cfg.with_values(**changes) if changes else cfg

    def check(self) -> None:
        """ValueError naming the first unusable setting (sizes bounded: :mod:`damper.limits`)."""
        from damper import limits

        if self.damper not in DAMPERS:
            raise ValueError(f"damper must be one of {DAMPERS}, got {self.damper!r}")
        if self.accuracy is not None:
            from harmonic_balance.accuracy import check_accuracy

            check_accuracy(self.accuracy)
            if self.damper != "nonlinear":
                raise ValueError(f"accuracy goes with the nonlinear damper: the linear limit "
                                 f"{self.damper!r} has no harmonic truncation (drop the accuracy)")
        if self.solver not in SOLVERS:
            raise ValueError(f"solver must be one of {SOLVERS}, got {self.solver!r}")
        for name in ("cf", "f0"):
            v = getattr(self, name)
            if v is not None and not (np.isfinite(v) and 0 < v <= limits.MAX_MAGNITUDE):
                raise ValueError(f"{name} must be finite, > 0 and at most {limits.MAX_MAGNITUDE:g} N, got {v}")
        limits.check_size("harmonics", self.harmonics, 1, limits.MAX_UPD_HARMONICS,
                          limits.harmonics_why(limits.MAX_UPD_HARMONICS))
        limits.check_size("points", self.points, 3, limits.MAX_UPD_POINTS, "each point is a harmonic-"
                          "balance solve of the whole ring (~0.2 s at 24 blades, H = 7)")
        if self.blades is not None:
            limits.check_size("blades", self.blades, 2, limits.MAX_RING_BLADES, limits.RING_BLADES_WHY)
        if self.damper == "nonlinear":
            limits.check_cf_floor("cf", self.cf, self.f0, self.config, "or damper free for the blades "
                                  "without a damper")
        if self.until_ci is not None:
            if self.factors is not None:
                raise ValueError("--until-ci needs random samples (--std/--samples), not --factors")
            if not (isinstance(self.until_ci, (int, float)) and np.isfinite(self.until_ci)
                    and self.until_ci > 0):
                raise ValueError(f"until-ci half-width must be finite and > 0, got {self.until_ci}"
                                 " (the amplification's 0.95 quantile to +- this, e.g. 0.01)")
            if self.until_ci > limits.MAX_UNTIL_CI:
                raise ValueError(f"until-ci half-width {self.until_ci:g} is above {limits.MAX_UNTIL_CI:g}: the "
                                 "amplification lies between 1 and the Whitehead bound (a few), so a wider "
                                 "interval says nothing of it; give e.g. 0.01")
        if self.factors is None:
            limits.check_size("samples", self.samples, 1, limits.MAX_MISTUNING_SAMPLES,
                              "each sample is a ring curve (~20 s CPU at 24 blades, H = 7)")
            limits.check_size("seed", self.seed, 0, 2**63 - 1, "a 64-bit seed")
            self._check_zero_std()
        if self.band_hz is not None:
            limits.check_omega_range("band", *self.band_hz, unit="Hz", scale=2 * np.pi)
            if not self.band_hz[0] < self.band_hz[1]:
                raise ValueError(f"band {self.band_hz[0]:g} {self.band_hz[1]:g}: give LO < HI [Hz]")

    def _check_zero_std(self) -> None:
        """A zero std draws the tuned pattern (all factors 1) for every sample: more than one
        sample, or sampling until an interval closes (~80 identical rings), repeats one
        result, so only one sample (the tuned disk as a check) is run."""
        if self.std != 0:
            return
        if self.until_ci is not None:
            raise ValueError("--until-ci with --std 0: every sample is the tuned disk, so the interval closes "
                             "only after ~80 identical samples; give --std > 0 (e.g. 0.02), or drop --until-ci "
                             "and give --samples 1 for the tuned disk")
        if self.samples > 1:
            raise ValueError(f"--std 0 with {self.samples} samples: every sample is the tuned disk (all factors "
                             "1), the same result each time; give --std > 0 (e.g. 0.02), or --samples 1 for "
                             "the tuned disk")

    def patterns(self, n_blades: int) -> list[np.ndarray]:
        """Stiffness factors of every sample (all drawn and checked before any work)."""
        from harmonic_balance.bladed_disk.mistuning import KINDS, check_factors, draw_factors

        if self.factors is not None:
            if self.kind not in KINDS:
                raise ValueError(f"mistuning kind must be one of {KINDS}, got {self.kind!r}")
            return [check_factors(self.factors, n_blades, "factors", self.kind)]
        return [draw_factors(n_blades, self.std, self.seed, i, self.kind, self.distribution)
                for i in range(self.samples)]

    def sigma_f(self) -> float:
        """Standard deviation of the blade frequencies implied by the scatter."""
        if self.factors is not None:
            f = np.asarray(self.factors, float)
            return float(np.std(np.sqrt(f) if self.kind == "stiffness" else f))
        return self.std / 2.0 if self.kind == "stiffness" else self.std


def study_from_scene(data: dict) -> Study:
    """The Study of a validated scene's [mistuning] table (the model from [upd].config)."""
    m = dict(data["mistuning"])
    if "band" in m:
        m["band_hz"] = m.pop("band")
    return Study(config=(data.get("upd") or {}).get("config"), **m)


def fingerprint(cfg) -> str:
    """Hash of a UPD config's numbers and its blade's matrices (a blade file enters by content)."""
    from harmonic_balance.bladed_disk.blade import MATRICES

    h = hashlib.sha256(json.dumps(cfg.data, sort_keys=True, default=str).encode())
    b = cfg.blade()
    for name in MATRICES:
        A = getattr(b, name)
        h.update(name.encode() + (b"-" if A is None else np.ascontiguousarray(A, float).tobytes()))
    h.update(json.dumps([b.dofs, b.left, b.right, b.forced, b.response], default=str).encode())
    return h.hexdigest()[:24]


def tuned_reference(study: Study, cfg) -> dict:
    """Tuned sector's peak [m] and frequency [Hz], the study's band [Hz], the harmonics of
    every sample (``harmonics``: the study's, or the H its ``accuracy`` chose on the tuned
    sector) and the tuned peak's truncation estimate (None for a linear limit)."""
    from harmonic_balance.bladed_disk.hb import SectorHB
    from harmonic_balance.bladed_disk.mistuning import tuned_linear_peak
    from harmonic_balance.bladed_disk.sector import Sector
    from harmonic_balance.bladed_disk.solve import frf

    sector = Sector(cfg)
    search = study.band_hz or cfg["load.band_hz"]
    om = 2 * np.pi * np.linspace(search[0], search[1], max(study.points, 41))
    rec, H = None, study.harmonics  # a linear limit has no harmonic truncation
    if study.damper == "nonlinear" and study.accuracy is not None:
        hb, c, rec = _tuned_to_accuracy(study, sector, om)
        w, a, H = c.peak_omega, c.peak_amplitude, hb.H
    elif study.damper == "nonlinear":
        hb = SectorHB(sector, study.harmonics, cf=study.cf, f0=study.f0)
        c = frf(hb, om)
        w, a = c.peak_omega, c.peak_amplitude
        rec = _tuned_truncation(hb, c)
    else:
        w, a = tuned_linear_peak(sector, om, study.damper, study.f0)
    check_tuned_inside(w, om, study.band_hz is not None)
    rattle = None
    if study.damper == "nonlinear" and c.peak_x is not None:   # the reference's own damper rattling
        from damper.upd_checks import rattle_warning

        rattle = rattle_warning(hb.contact_summary(c.peak_x)["lift_off"], hb.f0, hb.cf, hb.H,
                                " (the tuned sector's peak, every amplification's reference)")
    margin = BAND_MARGIN + BAND_SIGMAS * study.sigma_f()
    if study.band_hz is not None:
        band = list(study.band_hz)
    else:
        f_t = w / (2 * np.pi)
        hi = f_t if study.damper != "nonlinear" else max(
            f_t, tuned_linear_peak(sector, om, "stuck", study.f0)[0] / (2 * np.pi))
        band = default_band(f_t, hi, margin)
    return {"tuned_peak": float(a), "tuned_frequency_hz": float(w / (2 * np.pi)), "band_hz": band,
            "harmonics": int(H), "truncation_error": rec, "lift_off_warning": rattle}


def check_tuned_inside(w: float, om: np.ndarray, given: bool) -> None:
    """ValueError when the tuned peak (at ``w`` [rad/s]) lies at an end of its search grid
    ``om`` [rad/s]: the band's end is not the tuned peak, and every amplification divides by
    it (``given``: the band is the user's, else the model's ``load.band_hz``)."""
    if _at_end(w, om):
        where = "the given band" if given else "the model's load.band_hz"
        raise ValueError(f"the tuned peak lies at the end {w / 2 / np.pi:.6g} Hz of {where} {om[0] / 2 / np.pi:g} "
                         f"... {om[-1] / 2 / np.pi:g} Hz: the reference of every amplification must be a peak "
                         "inside it; give a band around the tuned resonance")


def _tuned_truncation(hb, curve) -> dict:
    """Truncation-error estimate of the tuned sector's peak at the study's H (the
    reference every amplification divides by): how accurate that H is for a peak."""
    from damper import limits
    from harmonic_balance.bladed_disk.accuracy import truncation_error

    rec = truncation_error(hb, curve, limits.MAX_UPD_HARMONICS)
    rec["at"] = "the tuned sector's peak (the study's reference)"
    return rec


def _tuned_to_accuracy(study: Study, sector, om):
    """(hb, curve, record) of the tuned sector raised in H from the study's ``harmonics``
    until its peak's estimate is below ``accuracy`` (:func:`frf_to_accuracy`): the H every
    sample then uses. The ring's peaks converge in H like the sector's (the same contacts),
    and the amplification divides by the tuned peak at the same H."""
    from damper import limits
    from harmonic_balance.bladed_disk.accuracy import frf_to_accuracy

    hb, c, rec = frf_to_accuracy(sector, om, study.accuracy, study.harmonics,
                                 limits.MAX_UPD_HARMONICS, cf=study.cf, f0=study.f0)
    rec["at"] = "the tuned sector's peak (the study's reference; its H used for every sample)"
    return hb, c, rec


def default_band(f_low: float, f_high: float, margin: float) -> list:
    """[f_low (1 - margin), f_high (1 + margin)] [Hz], each end kept within BAND_MARGIN
    beyond the frequencies a blade can reach (factors sqrt(KAPPA_MIN) ... sqrt(KAPPA_MAX)
    of the tuned ones), so a large scatter never gives a band below zero."""
    from harmonic_balance.bladed_disk.mistuning import KAPPA_MAX, KAPPA_MIN

    lo = max(1.0 - margin, KAPPA_MIN ** 0.5 * (1.0 - BAND_MARGIN))
    hi = min(1.0 + margin, KAPPA_MAX ** 0.5 * (1.0 + BAND_MARGIN))
    return [f_low * lo, f_high * hi]


def sample_key(study: Study, fp: str, band: list, kappa) -> str:
    """Cache key of one sample: model, solver settings, band, pattern, code version."""
    settings = {k: v for k, v in asdict(study).items()
                if k in ("damper", "cf", "f0", "harmonics", "points", "solver")}
    return make_key("mistuning_sample", VERSION, fp, settings, [float(b) for b in band],
                    [float(k) for k in kappa], code_version(MODULES))


class SampleModel:
    """What the samples of one chunk share, built once in the worker: the sector, the
    band's grid, and the linear ring family (:class:`LinearRingFamily`, the tuned matrices)
    or the tuned sector's harmonic balance (the starts of every ring solve).

    The full solver's grid has ``points``, or more where the tuned ring's narrowest
    half-power width on the band asks for them (:func:`.ring_solve.resolving_points`; the
    solver then refines it around every blade's peaks)."""

    def __init__(self, study: Study, band, f_tuned: float):
        from harmonic_balance.bladed_disk.mistuning import LinearRingFamily
        from harmonic_balance.bladed_disk.sector import Sector

        self.study, self.f_tuned = study, f_tuned
        self.sector = Sector(study.load())
        self.margin = BAND_MARGIN + BAND_SIGMAS * study.sigma_f()   # a widening of the band
        self.om = self.grid(2 * np.pi * band[0], 2 * np.pi * band[1])
        self.family = (LinearRingFamily(self.sector, study.damper, study.f0)
                       if study.damper != "nonlinear" else None)
        self.tuned = None       # the tuned SectorHB, from the first ring (its H, CF, F0, mu, n_t)

    def grid(self, lo: float, hi: float) -> np.ndarray:
        """The frequency grid [rad/s] of the band [lo, hi] [rad/s]: ``points``, or more where
        the full solver's resolution asks (:func:`.ring_solve.resolving_points`)."""
        from harmonic_balance.bladed_disk.ring_solve import resolving_points

        n = self.study.points
        if self.study.damper == "nonlinear" and self.study.solver == "full":
            n = resolving_points(self.sector, lo, hi, n)
        return np.linspace(lo, hi, n)


def run_chunk(task: dict) -> dict:
    """A chunk of samples (runs in a Dask worker or in this process) with one
    :class:`SampleModel`: each sample's cached result, or its ring's per-blade peaks
    computed and stored; a failed solve is that sample's ``error``.

    ``task``: ``study``, ``band_hz``, ``tuned_frequency_hz``, ``folder``, ``max_bytes``
    and ``items`` (each ``index``, ``kappa``, ``key``). Returns ``results`` (in the
    items' order) and the chunk's ``cpu_s`` (this process's CPU time) and ``wall_s``.
    """
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    c0, t0 = time.process_time(), time.perf_counter()
    store = Store(task["folder"], task["max_bytes"])
    model, results = None, []
    for item in task["items"]:
        hit = store.get(item["key"])
        if hit is not None:
            results.append(hit[1]["data"] | {"cached": True, "index": item["index"]})
            continue
        if model is None:   # a chunk read wholly from the cache builds nothing
            model = SampleModel(Study(**task["study"]), task["band_hz"], task["tuned_frequency_hz"])
        results.append(_run_one(model, store, item))
    if model is not None:
        store.evict()       # once per chunk: each check lists the whole cache folder
    return {"results": results, "cpu_s": time.process_time() - c0, "wall_s": time.perf_counter() - t0}


def _run_one(model: SampleModel, store: Store, item: dict) -> dict:
    """One sample of a chunk: solved and stored, or its error (not stored)."""
    t0 = time.perf_counter()
    try:
        out = _solve_sample(model, item["kappa"])
    except (RuntimeError, ValueError, ArithmeticError, np.linalg.LinAlgError) as err:
        # a diverged solve (the C core refuses a non-finite iterate: a ValueError); the
        # model itself was checked by the study's tuned reference before any sample.
        model.tuned = None   # rebuilt for the next sample: nothing of a failed solve carries over
        return {"index": item["index"], "error": f"{type(err).__name__}: {err}", "cached": False,
                "time_s": time.perf_counter() - t0}
    out |= {"index": item["index"], "error": None, "time_s": time.perf_counter() - t0}
    store.put(item["key"], {}, {"data": out}, evict=False)
    return out | {"cached": False}


def run_sample(task: dict) -> dict:
    """One sample as a chunk of one (``task`` holds ``index``, ``kappa``, ``key`` besides the
    chunk's settings); its result row."""
    item = {k: task[k] for k in ("index", "kappa", "key")}
    return run_chunk({k: v for k, v in task.items() if k not in item} | {"items": [item]})["results"][0]


def _solve_sample(model: SampleModel, kappa) -> dict:
    """Per-blade peaks [m] and frequencies [Hz] of one pattern, and the band [Hz] they were
    searched on (raises on solver failure).

    On the default band a pattern whose largest peak lies at an end of it is solved again
    on the band widened at that end by the study's margin w (relative), at most
    :data:`BAND_WIDENINGS` times: a resonance just beyond the band (on UPD-24 at std 0.02,
    3 patterns in 60 peak at ~503 Hz, above the default band's 502.6 Hz). A user's band is
    kept: such a pattern fails with a message."""
    band, spent = [model.om[0], model.om[-1]], 0
    for widened in range(BAND_WIDENINGS + 1):
        om = model.om if not widened else model.grid(*band)
        out, w = _solve_on(model, kappa, om)
        spent += out["evaluations"]   # the narrower bands' solves count too
        if not _at_end(w, om):
            return out | {"band_hz": [float(band[0] / 2 / np.pi), float(band[1] / 2 / np.pi)],
                          "band_widened": widened, "evaluations": spent}
        if model.study.band_hz is not None or widened == BAND_WIDENINGS:
            break
        m = 1.0 + model.margin
        band = [band[0] / m, band[1]] if abs(w - band[0]) < abs(w - band[1]) else [band[0], band[1] * m]
    _inside(w, om)   # raises: the largest peak at the band's end


def _solve_on(model: SampleModel, kappa, om: np.ndarray) -> tuple[dict, float]:
    """One pattern's per-blade peaks on the grid ``om`` [rad/s] (its ends for the fast
    solver), and the largest peak's angular frequency [rad/s]."""
    from harmonic_balance.bladed_disk.hb import SectorHB
    from harmonic_balance.bladed_disk.ring_fast import fast_ring_frf
    from harmonic_balance.bladed_disk.ring_hb import MistunedRingHB
    from harmonic_balance.bladed_disk.ring_solve import ring_frf

    study = model.study
    if model.family is not None:
        lin = model.family.ring(kappa)
        peaks, w = lin.peaks(om)
        return ({"peak_per_blade": peaks.tolist(), "peak_frequency_per_blade_hz": (w / 2 / np.pi).tolist(),
                 "evaluations": lin.solves, "truncated": []}, float(w[peaks.argmax()]))
    ring = MistunedRingHB(model.sector, kappa, study.harmonics, cf=study.cf, f0=study.f0)
    if model.tuned is None:   # as RingSolver builds it: the ring's H, loads, mu and time grid
        model.tuned = SectorHB(ring.sector, ring.H, cf=ring.cf, f0=ring.f0, mu=ring.mu,
                               n_t=ring.basis.n_t)
    start = 2 * np.pi * model.f_tuned
    if study.solver == "fast":
        c = fast_ring_frf(ring, (om[0], om[-1]), model.tuned, start_omega=start)
    else:
        c = ring_frf(ring, om, model.tuned, start_omega=start)
    return ({"peak_per_blade": c.peak_per_blade.tolist(),
             "peak_frequency_per_blade_hz": (c.peak_omega_per_blade / 2 / np.pi).tolist(),
             "worst_blade": int(c.worst), "evaluations": c.evaluations, "truncated": c.extra["truncated"]},
            float(c.peak_omega))


def _at_end(w: float, om: np.ndarray) -> bool:
    """Whether ``w`` [rad/s] lies at an end of the band ``om`` (:func:`damper.upd_checks.at_band_end`)."""
    from damper.upd_checks import at_band_end

    return at_band_end(w, om[0], om[-1])


def _inside(w: float, om: np.ndarray) -> None:
    """RuntimeError when the largest peak (at w [rad/s]) lies at an end of the band ``om``."""
    if _at_end(w, om):
        raise RuntimeError(f"the largest blade peak lies at the band's end {w / 2 / np.pi:.6g} Hz "
                           "(the peak is outside the band): give a wider --band")


def run_study(study: Study, store: Store, scheduler: str | None = None, workers: int | None = None,
              serial: bool = False, echo=print) -> dict:
    """Run (or resume) the study in chunks; the JSON-able summary (module docstring)."""
    t0 = time.perf_counter()
    study.check()
    cfg = study.load()
    kappas = study.patterns(cfg.blades)           # every bad pattern refused before any work
    from damper.tasks import executor

    info = {}
    submit, gather, close = executor(scheduler, workers, serial, info)  # an unreachable scheduler: now
    try:
        ref = tuned_reference(study, cfg)
        if study.accuracy is not None:   # H chosen for the accuracy: every sample at it
            echo(f"mistuning: H = {ref['harmonics']} for the accuracy {study.accuracy:g} (tuned "
                 f"sector, harmonics tried {ref['truncation_error']['accuracy']['H_sequence']})")
            study = replace(study, harmonics=ref["harmonics"])
        fp = fingerprint(cfg)
        common = {"study": asdict(study), "band_hz": ref["band_hz"], "folder": str(store.folder),
                  "tuned_frequency_hz": ref["tuned_frequency_hz"], "max_bytes": store.max_bytes}
        items = [{"index": i, "kappa": k.tolist(), "key": sample_key(study, fp, ref["band_hz"], k)}
                 for i, k in enumerate(kappas)]
        done = sum(store.contains(t["key"]) for t in items)
        n_workers = info.get("workers", 1)
        where = ("this process" if serial else scheduler
                 or f"a local Dask cluster ({n_workers} workers)")
        size = chunk_size(len(items), n_workers, study.until_ci)
        echo(f"mistuning: {len(items)} samples of {cfg.blades} blades, {done} in the cache, on {where}, "
             f"in chunks of {size}" + (f", until the 0.95 quantile is known to +-{study.until_ci:g}"
                                       if study.until_ci else ""))
        run = _run_chunks(common, items, size, submit, gather, 1 if serial else 2 * n_workers,
                          study.until_ci, ref["tuned_peak"], echo)
    finally:
        close()
    n = len(run["results"])
    run["efficiency"] |= {"workers": n_workers}
    e = run["efficiency"]
    e["efficiency"] = e["cpu_s"] / (n_workers * max(e["wall_s"], 1e-9))   # (a study read from the cache: ~0)
    out = summarize(study, cfg, ref, kappas[:n], run["results"], time.perf_counter() - t0)
    out["efficiency"] = run["efficiency"]
    if study.until_ci is not None:
        out["until_ci"] = run["until_ci"]
    return out


def chunk_size(n_samples: int, n_workers: int, until_ci: float | None) -> int:
    """Samples per chunk: :data:`CHUNK_UNTIL_CI` when the study stops on its interval (the
    stopping sample count then does not depend on the workers), else about
    :data:`CHUNKS_PER_WORKER` chunks per worker (load balance) of at most :data:`MAX_CHUNK`."""
    if until_ci is not None:
        return min(CHUNK_UNTIL_CI, n_samples)
    return max(1, min(MAX_CHUNK, -(-n_samples // (CHUNKS_PER_WORKER * n_workers))))


def _run_chunks(common, items, size, submit, gather, window, until_ci, tuned_peak, echo) -> dict:
    """The chunks in index order, at most ``window`` in flight; with ``until_ci``, stops
    after the first chunk whose prefix of samples gives the 0.95 quantile's interval a
    half-width <= until_ci. Returns the prefix's ``results``, ``efficiency`` (the chunks'
    CPU time and the wall time of this phase) and ``until_ci``."""
    from collections import deque

    from damper.mistuning_stats import quantile_half_width

    chunks = [items[i:i + size] for i in range(0, len(items), size)]
    t0, cpu, results, gathered = time.perf_counter(), 0.0, [], 0
    pending, nxt, half = deque(), 0, float("inf")
    while pending or nxt < len(chunks):
        while nxt < len(chunks) and len(pending) < (window if until_ci else len(chunks)):
            pending.append(submit(run_chunk, common | {"items": chunks[nxt]}))
            nxt += 1
        r = gather([pending.popleft()])[0]
        cpu, gathered = cpu + r["cpu_s"], gathered + 1
        results += r["results"]
        if until_ci is None:
            continue
        amp = [max(s["peak_per_blade"]) / tuned_peak for s in results if s.get("error") is None]
        half = quantile_half_width(amp, 0.95) if amp else float("inf")
        if half <= until_ci:
            echo(f"mistuning: the 0.95 quantile's interval half-width {half:.4g} <= {until_ci:g} "
                 f"after {len(results)} samples")
            break
    wall = time.perf_counter() - t0
    return {"results": results,
            "efficiency": {"cpu_s": cpu, "wall_s": wall, "chunks": gathered, "chunk_size": size},
            "until_ci": {"half_width_target": until_ci, "half_width": None if half == float("inf") else half,
                         "samples_used": len(results), "reached": half <= (until_ci or 0.0)}}


def summarize(study: Study, cfg, ref: dict, kappas, results, time_s: float) -> dict:
    """The study's JSON: tuned reference, samples, statistics."""
    from harmonic_balance.accuracy import warning
    from harmonic_balance.bladed_disk.mistuning import frequency_factors, whitehead_bound

    a_t = ref["tuned_peak"]
    samples = []
    for k, r in sorted(zip(kappas, results), key=lambda p: p[1]["index"]):
        s = {"index": r["index"], "factors": k.tolist(),
             "frequency_factors": frequency_factors(k).tolist(), "error": r.get("error"),
             "cached": r.get("cached", False), "time_s": r.get("time_s")}
        if s["error"] is None:
            pk = np.asarray(r["peak_per_blade"])
            j = r.get("worst_blade")   # the solver's refined blade among equal peaks
            j = int(pk.argmax()) if j is None or pk[j] < pk.max() else int(j)
            s |= {"peak_per_blade": pk.tolist(), "amplification": float(pk[j] / a_t),
                  "worst_blade": j, "frequency_hz": r["peak_frequency_per_blade_hz"][j],
                  "peak_frequency_per_blade_hz": r["peak_frequency_per_blade_hz"],
                  "evaluations": r["evaluations"], "truncated": r["truncated"],
                  "band_hz": r.get("band_hz", ref["band_hz"]), "band_widened": r.get("band_widened", 0)}
        else:
            s |= {"peak_per_blade": None, "amplification": None, "frequency_hz": None}
        samples.append(s)
    amp = np.array([s["amplification"] for s in samples if s["error"] is None])
    out = {"blades": cfg.blades, "engine_order": cfg.engine_order, "damper": study.damper,
            "kind": study.kind, "distribution": study.distribution,
            "std": None if study.factors is not None else study.std, "seed": study.seed,
            "harmonics": study.harmonics, "accuracy": study.accuracy,
            "cf": study.cf or cfg.cf, "f0": study.f0 or cfg.f0,
            "band_hz": ref["band_hz"], "points": study.points, "solver": study.solver,
            "tuned_peak": a_t, "tuned_frequency_hz": ref["tuned_frequency_hz"],
            "truncation_error": ref.get("truncation_error"),
            "truncation_warning": warning(ref.get("truncation_error")),
            "lift_off_warning": ref.get("lift_off_warning"),
            "samples": samples, "failed": int(sum(s["error"] is not None for s in samples)),
            "widened": int(sum(bool(s.get("band_widened")) for s in samples)),
            "cached": int(sum(s["cached"] for s in samples)),
            "whitehead_bound": whitehead_bound(cfg.blades), "time_s": time_s}
    if amp.size == 0:
        raise AllSamplesFailed(f"every sample failed; the first: {samples[0]['error']}",
                               out | {"max_amplification": None, "mean_amplification": None,
                                      "std_amplification": None, "quantiles": None, "statistics": None})
    return out | {"max_amplification": float(amp.max()), "mean_amplification": float(amp.mean()),
                  "std_amplification": float(amp.std()) if amp.size > 1 else None,   # one sample: unknown, not 0
                  "quantiles": {f"{q:g}": float(np.quantile(amp, q)) for q in QUANTILES},
                  "statistics": mistuning_stats.summary(amp)}
