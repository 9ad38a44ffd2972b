"""Upper bounds of every size a user can type, each with the reason for it.

A size above its bound is refused before any work (exit 2) with a message that names
the bound and what the size would cost; nothing in the toolkit then runs for hours or
fills the memory because of one extra digit. The costs quoted were measured with
``damper`` on the 2-core development machine (``/usr/bin/time``, revision c58d443):
the sdof forced response (``damper frf --model sdof ... --omega 0.9 1.3``) took 2.9 s
at H = 11, 6.8 s at H = 31 and 27 s at H = 61 (time ~ H^2); ``damper upd frf`` (200
points) 1.5 s at H = 7 and 6.6 s at H = 15; ``damper loop`` 3.6 s and 0.24 GB at 1e6
samples.
"""
from __future__ import annotations

import math
import os

#: Highest harmonic of a forced response or backbone: ~H^2 time, H = 61 takes 27 s for
#: one DOF, so H = 200 is several minutes (and more per extra nonlinear DOF).
MAX_HARMONICS = 200
#: Highest harmonic of the bladed-disk sector (``damper upd``): ~H^2 time, H = 15 takes
#: 6.6 s for 200 points, H = 50 over a minute.
MAX_UPD_HARMONICS = 50
#: AFT samples per period: the DFT matrices hold n_t (2H + 1) numbers each, 0.2 GB at
#: 65536 x 401.
MAX_AFT_SAMPLES = 65536
#: Continuation points of a curve: each is a Newton solve (5-50 ms for one DOF at H <= 7,
#: seconds for large models), so 20000 points is minutes to hours.
MAX_CURVE_POINTS = 20000
#: Samples per cycle of ``damper loop``: 1e6 samples take ~4 s and 0.24 GB (and 40 MB of JSON).
MAX_LOOP_SAMPLES = 1_000_000
#: Frequency points of ``damper upd frf``: ~7 ms each at H = 7, 10000 points ~1 min or more.
MAX_UPD_POINTS = 10000
#: Load (CF) values of ``damper upd optimize`` / a scene's [upd] points: each is a whole
#: forced response (seconds), 200 values is minutes.
MAX_LOAD_POINTS = 200
#: Frequency points per curve of the load optimisation before its peak refinement.
MAX_UPD_GRID = 2000
#: Points of the F-approach curve of ``damper normal --curve``: one normal solve each.
MAX_APPROACH_POINTS = 1000
#: Samples of a mistuning study: each is a curve of the whole ring (~20 s CPU at 24
#: blades, H = 7; ~4 s in a linear limit, every local peak refined), so 10000 samples is days of CPU.
MAX_MISTUNING_SAMPLES = 10000
#: Blades of a mistuned ring: its prestress statics use dense matrices ((7 N_b)^2 numbers,
#: 190 MB for three at 400 blades) and a curve costs ~0.4 s CPU per blade at H = 7.
MAX_RING_BLADES = 400
RING_BLADES_WHY = ("the ring's statics are dense ((7 N_b)^2 numbers per matrix) and a curve costs "
                   "~0.4 s CPU per blade")
#: Variants of a sweep: each is one scene run (seconds to minutes).
MAX_SWEEP_VARIANTS = 1000
#: Forced-response levels of a scene (``excitation.forces``): one curve each.
MAX_FORCE_LEVELS = 100
#: Angular frequency [rad/s]: far above any structural mode a blade model holds
#: (1e9 rad/s is 160 MHz), and omega^2 M must stay far from floating-point overflow.
MAX_OMEGA = 1e9
#: Smallest angular frequency [rad/s] of a frequency range: 1e-6 rad/s is a period of 72
#: days, a static load for any blade; far below, omega^2 M underflows against K and the
#: stability and accuracy checks divide by zero (1e-300 rad/s printed two warnings).
MIN_OMEGA = 1e-6
#: Friction coefficient: dry contacts have mu below a few; beyond 100 the input is a typo.
MAX_MU = 100.0
#: Largest magnitude of a model parameter typed on the command line (mass, stiffness,
#: force, ...): the harmonic balance squares forces and displacements (residual norms,
#: omega^2 M), which overflows double precision above ~1e154.
MAX_MAGNITUDE = 1e100
#: Smallest load [N] of the UPD models (``upd frf|mistuning --cf/--f0``, ``system``, a scene's
#: ``[upd]``): the energy per cycle is a force times a displacement of that size, which
#: underflows to zero below ~1e-154 (``upd frf --f0 1e-160`` divided by zero in the energy
#: balance): the mirror of :data:`MAX_MAGNITUDE`.
MIN_LOAD = 1e-100
#: Largest damping ratio of a structure's mode (a scene's ``structure.zeta``): 1 is critical
#: damping, a blade's structural damping is below 1 %; 1e300 overflowed the Rayleigh
#: matrix beta K into NaN.
MAX_DAMPING_RATIO = 10.0
DAMPING_RATIO_WHY = "1 is critical damping (a blade's structural damping is below 1 %)"
#: Smallest normal load [N] of a friction element (``fmu --n-ref``, ``--preload``): the
#: slip limits scale with N / N_ref, which overflows far below (N_ref = 1e-320 fails at
#: the FMU's start); contacts of friction dampers carry mN to MN.
MIN_NORMAL_LOAD = 1e-6
#: Largest normal load [N] of a friction element (``fmu --n-ref``, ``--preload``): far
#: above, N / N_ref underflows (N_ref = 1e308 gives F = 0).
MAX_NORMAL_LOAD = 1e9
#: Range of ``damper loop --scale``, a factor on every slip force (a change of mu): at
#: --N 1e300 --scale 1e300 the slip forces overflowed (a JSON "out of range float" error).
MIN_FRICTION_SCALE = 1e-6
MAX_FRICTION_SCALE = 1e6
#: Smallest penalty normal stiffness [N/m] (``fmu --k-n``): at 1e3 N/m a 200 N preload is
#: a 0.2 m penetration; far below, the start penetration N / k_n overflows (k_n = 1e-300
#: fails at the start).
MIN_PENALTY_STIFFNESS = 1e3
#: Largest penalty normal stiffness [N/m] (``fmu --k-n``): at 1e15 N/m a 1 N load is a
#: penetration of 1e-15 m, below an atom.
MAX_PENALTY_STIFFNESS = 1e15
#: Steps a period of ``damper cosim``: the time-series buffer holds two periods of every
#: blade's response (1e6 steps: 16 MB a blade), and the default step gives ~2500.
MAX_COSIM_STEPS_PER_PERIOD = 1_000_000
#: Periods of ``damper cosim --periods``: a friction-damped ring settles in tens to a few
#: hundred periods; at the default step a period costs ~0.7 s (UPD-24 ring of 4 blades,
#: 2428 steps of ~0.3 ms), so 100000 periods is most of a day.
MAX_COSIM_PERIODS = 100_000
#: Communication steps of one ``damper cosim`` run (periods x steps a period): ~0.3 ms
#: each on the 2-core machine, so 5e7 steps is about four hours.
MAX_COSIM_STEPS = 50_000_000
#: Smallest curve step tolerance of ``damper tangential --tol`` (fraction of mu N): the
#: number of curve points grows as tol^-1/2, ~30 times the default's (1e-3) at 1e-6.
MIN_CURVE_TOL = 1e-6
#: Largest hysteresis-loop amplitude of ``damper tangential --loop-amplitude`` in gross-slip
#: displacements: the loop's points grow as the amplitude (sphere, bem 11: 882 points at
#: 10, 78752 at 1000; 1e5 did not end in two minutes, 1e300 hung).
MAX_LOOP_SLIPS = 100.0
#: Smallest loop amplitude, in gross-slip displacements: the tangential solve converges to
#: 1e-11 of its displacement scale (``contact_core.tangential.SOLVE_TOL``), so much smaller
#: motions are below its tolerance (1e-18 m on the 10 mm sphere, 3e-13 gross slips, gave a
#: force amplitude of exactly 0 N); 1e-6 keeps five orders of margin and is a linear loop.
MIN_LOOP_SLIPS = 1e-6
#: Largest cache size limit [MiB] (``--cache-max-mb``, ``$DAMPER_CACHE_MAX_MB``): 2^30 MiB
#: is 1 PiB, more than any disk the cache lives on (1e300 MiB printed a 300-digit limit).
MAX_CACHE_MB = 2.0**30
#: Largest ``--until-ci`` half-width of a mistuning study's 0.95 quantile: the amplification
#: lies between 1 and the Whitehead bound (1.5 at 4 blades, 2.9 at 24), so an interval wider
#: than +-1 says nothing of it (1e300 was accepted and never reached with few samples).
MAX_UNTIL_CI = 1.0
#: Least centrifugal load of an underplatform damper per newton of EO force (friction
#: damper). Below it the damper carries almost no normal load: its contacts open over more
#: than 99 % of the period, it rattles, and it damps through its contact dashpots (beta_c k,
#: acting in every contact state), not by friction. That limit is not the damper removed:
#: on UPD-24 (f0 = 30 N, H = 7, 41 points) the peak is 2.38e-3 m (within 0.05 %) for every
#: CF from 1 N down to 1e-8 N, the dashpots taking 86 % of the work and friction < 1e-5 of
#: it (the ring's time integration agrees to 9e-6 at 1e-4 N), against 1.7e-2 m with
#: ``--damper free``. The sector's start solve at 400 Hz fails often just below the floor
#: (10 of 18 loads from 1e-3 to 0.03 N; 2 of 14 from 0.03 to 1 N, none of 6 below 1e-3 N;
#: each 0.4-2 s CPU): the floor refuses loads whose answer is the floor's own, reached
#: through a start that often fails.
MIN_CF_PER_F0 = 1e-3
#: Unknowns of the sector's harmonic balance with contact surfaces (``upd frf --contacts
#: surface``: (n_dof + node DOFs) (2H + 1)): its Jacobian is dense and a solve holds about
#: eight matrices of that size (peak memory measured 0.71 GB at 3195 unknowns, 1.4 GB at
#: 4899: 5 nodes per side, H 7 and 11), so 8000 unknowns is ~4 GB; H 50 at 5 nodes per side
#: (21,513 unknowns) was killed for want of memory.
MAX_SURFACE_UNKNOWNS = 8000
SURFACE_UNKNOWNS_WHY = ("the sector's Jacobian is dense and a solve holds ~8 matrices of unknowns^2 "
                        "numbers (4899 unknowns: 1.4 GB; 8000: ~4 GB)")
#: Worker processes per core (``--workers``): each worker holds its own copy of the model.
WORKERS_PER_CORE = 4


def max_workers() -> int:
    """Largest ``--workers``: :data:`WORKERS_PER_CORE` per core of this machine."""
    return WORKERS_PER_CORE * (os.cpu_count() or 1)


def check_load(name: str, value) -> None:
    """A load option [N] (``--cf``, ``--f0``) unset or finite in [:data:`MIN_LOAD`,
    :data:`MAX_MAGNITUDE`], else ValueError naming ``name``."""
    if value is None:
        return
    if not (math.isfinite(value) and MIN_LOAD <= value <= MAX_MAGNITUDE):
        raise ValueError(f"{name} must be finite and in [{MIN_LOAD:g}, {MAX_MAGNITUDE:g}] N, got {value:g} "
                         "(the energies per cycle underflow or the residual overflows beyond)")


def check_size(name: str, value, low: int, high: int, why: str) -> int:
    """``value`` as an int in [low, high], else ValueError naming ``name``, the bound and ``why``."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"{name} must be an integer, got {value!r}")
    if value < low:
        raise ValueError(f"{name} must be >= {low}, got {value}")
    if value > high:
        raise ValueError(f"{name} = {value} is above the limit {high}: {why}")
    return value


def check_harmonics(name: str, spec, high: int = MAX_HARMONICS) -> None:
    """A harmonics option (``H``, ``odd:H``, ``all:H``): H in 1..high, checked before any work."""
    text = str(spec).strip()
    kind, _, num = text.partition(":")
    if not num:
        kind, num = "all", kind
    if kind not in ("odd", "all"):
        raise ValueError(f"{name} {spec!r}: use H, odd:H or all:H (H an integer >= 1)")
    try:
        H = int(num)
    except ValueError:
        raise ValueError(f"{name} {spec!r}: use H, odd:H or all:H (H an integer >= 1)") from None
    check_size(name, H, 1, high, harmonics_why(high))


def harmonics_why(high: int) -> str:
    """Why the highest harmonic is bounded (the message of :func:`check_harmonics`)."""
    if high == MAX_UPD_HARMONICS:
        return "the sector's harmonic balance grows as H^2 (H = 15: 7 s for 200 points; H = 50: minutes)"
    return "the harmonic balance grows as H^2 or faster (one DOF: H = 61 takes 27 s; H = 200: minutes)"


def check_range(name: str, value: float, low: float, high: float, unit: str, why: str) -> float:
    """``value`` finite in [low, high] (``low`` > 0), else ValueError naming ``name``, the
    range and ``why``."""
    u = f" {unit}" if unit else ""
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be finite and > 0{u}, got {value:g}")
    if not low <= value <= high:
        raise ValueError(f"{name} {value:g}{u} is outside [{low:g}, {high:g}]{u}: {why}")
    return value


def check_omega_range(name: str, lo: float, hi: float, unit: str = "rad/s", scale: float = 1.0) -> None:
    """A frequency range: finite, positive, different, in [MIN_OMEGA, MAX_OMEGA] (``scale``: to rad/s)."""
    for v in (lo, hi):
        if not math.isfinite(v) or v <= 0:
            raise ValueError(f"{name} {lo:g} {hi:g}: both ends must be positive finite numbers [{unit}]")
    if lo == hi:
        raise ValueError(f"{name} {lo:g} {hi:g}: the ends must differ")
    bottom = MIN_OMEGA / scale
    if min(lo, hi) < bottom:
        raise ValueError(f"{name} {lo:g} {hi:g}: below the limit {bottom:.3g} {unit} (1e-6 rad/s, a period of "
                         "72 days: a static load; the dynamics underflow further down)")
    top = MAX_OMEGA / scale
    if max(lo, hi) > top:
        raise ValueError(f"{name} {lo:g} {hi:g}: above the limit {top:.3g} {unit} (1e9 rad/s, 160 MHz: "
                         "far above any structural mode, and omega^2 M must not overflow)")


def check_workers(name: str, n) -> None:
    """A worker count: 1 .. :func:`max_workers`."""
    check_size(name, n, 1, max_workers(), f"{WORKERS_PER_CORE} per core of this machine "
               f"({os.cpu_count()} cores); each worker is a process with its own copy of the model")


def cache_bytes(name: str, mb) -> int:
    """A cache size limit ``mb`` [MiB] as bytes: at least one byte, at most
    :data:`MAX_CACHE_MB`, else ValueError naming ``name``."""
    if not (isinstance(mb, (int, float)) and math.isfinite(mb) and mb > 0):
        raise ValueError(f"{name} must be a positive finite number of MiB, got {mb!r}")
    if mb > MAX_CACHE_MB:
        raise ValueError(f"{name} {mb:g} MiB is above the limit {MAX_CACHE_MB:g} MiB (1 PiB, more than "
                         "any disk): give a size in MiB, e.g. 4096")
    size = int(mb * 2**20)
    if size < 1:
        raise ValueError(f"{name} {mb:g} MiB is less than one byte: give a size in MiB, e.g. 4096")
    return size


def check_cf_floor(name: str, cf, f0, config, hint: str = "or --damper free for the blades without a damper") -> None:
    """A centrifugal load ``cf`` [N] at least :data:`MIN_CF_PER_F0` times the EO force
    (``f0``, default the UPD model ``config``'s), else ValueError naming ``name``."""
    if cf is None or not math.isfinite(cf) or cf <= 0:   # (refused by the value checks)
        return
    if f0 is None:
        from harmonic_balance.bladed_disk.config import load_config

        f0 = load_config(config).f0
    if cf < MIN_CF_PER_F0 * f0:
        raise ValueError(f"{name} {cf:g} N is below {MIN_CF_PER_F0:g} x the EO force ({f0:g} N): the damper "
                         "carries almost no load, rattles and damps through its contact dashpots alone (a response "
                         "that no longer changes with the load, and not that of the blades without a damper), and "
                         f"the sector's solve often finds no start there; give a CF of at least "
                         f"{MIN_CF_PER_F0 * f0:g} N (the same rattling response), {hint}")
