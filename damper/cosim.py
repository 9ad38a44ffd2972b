"""Run a ring SSP (``damper system``) in libcosim and read its steady state (``damper cosim``).

libcosim (through libcosimpy) loads the archive, steps every FMU with one fixed
communication step (integer nanoseconds; FMI 2 only) and exchanges the outputs after
each step (Jacobi). The step h is set so that a period T = 1 / F holds a whole number
n of steps: n = ceil(T / h_asked), h = round(T / n) ns (the period is then n h to
<= n / 2 ns).

Steady state. The response output of every blade (UPD-24: u_a) is sampled at each step;
after each period its first harmonic H1 is the least-squares fit of harmonics 0..
:data:`FIT_HARMONICS` to that period's samples at their times. The ring has settled when
the largest relative change of H1 over the blades from one period to the next, d_k,
and its geometric extrapolation d_k rho / (1 - rho), rho = d_k / d_(k-1) (the
remaining change of a transient decaying like rho^k; the ring time integration's rule,
:mod:`harmonic_balance.bladed_disk.timeint`), are both below ``tol``; at most
``periods`` periods run. ``amplitude`` is |H1| of blade 0.

Energy over the last period (differences of the FMUs' cumulative outputs):
excitation = sum of the blades' W_excitation; structural = sum of W_damping (each
blade's C) minus the neighbours' damping works (the blade-to-blade dashpots);
dampers = sum of W_friction + W_dashpots; stored = change of every FMU's energy and of
the ring's coupling energy U_c = sum_j q_j^T K_next q_(j+1) (from the blades' outputs;
it changes in a transient, not over a steady period). In an exact coupling excitation =
structural + dampers + stored; the residual is the coupling's inconsistency (the
neighbours' stiffness works differ from -dU_c, the work the dampers' forces do on the
blades from minus the platforms' work on the dampers) and the dampers' quadrature error.
"""
from __future__ import annotations

import contextlib
import ctypes
import json
import os
import re
import sys
import tempfile
import time
import zipfile
from pathlib import Path

import numpy as np

from contact_core.fileformat import parse
from contact_core.fileio import MAX_SSP_BYTES, check_regular_input, check_zip_members
from damper import limits
from damper.ring_info import RingInfo

#: Harmonics fitted to one period's samples (0..FIT_HARMONICS).
FIT_HARMONICS = 9
#: Default settling tolerance (relative change of the first harmonic, extrapolated).
SETTLE_TOL = 1e-4
#: Largest settling tolerance (open bound): a relative change of half the amplitude per
#: period is no settling (10 called a ring "settled" after 5 periods, 15 % below its
#: steady amplitude, as the harmonic balance's --accuracy is bounded below 0.5).
MAX_SETTLE_TOL = 0.5
#: Fewest periods before settling is tested (the start transient of the contacts).
MIN_PERIODS = 5
#: Fewest steps a period (the fit of the first harmonic needs samples of the period).
MIN_STEPS_PER_PERIOD = 2 * FIT_HARMONICS + 2
#: Most steps a period (:data:`damper.limits.MAX_COSIM_STEPS_PER_PERIOD`).
MAX_STEPS_PER_PERIOD = limits.MAX_COSIM_STEPS_PER_PERIOD
#: Largest growth of a blade's first harmonic from one period to the next once the start
#: transient is over (after MIN_PERIODS): a forced response from rest grows at most by
#: (k + 1) / k in period k + 1; an unstable coupling multiplies it by 1e4-1e6 a period
#: (measured: step 1e-4 s, 13 times the coupling limit, 1.7e97 m after 20 periods).
MAX_GROWTH = 2.0
#: Largest |relative residual| of the last period's energy balance: measured 6e-6 at the
#: default step (1/8 of the coupling limit), 0.47 at 0.95 of the limit, 1.2 at 1.4 times
#: it (amplitude 7 % off), 1e64 in a diverged run. Beyond, the balance misses more than
#: the excitation's whole work: the numbers are not a response of the ring.
MAX_ENERGY_RESIDUAL = 1.0
#: libcosim worker threads: eight small FMUs a step cost less on one thread than on a
#: pool (measured on the shared 2-core machine: 136 us a step with 1, 184 with 0, 488
#: with libcosim's default; tmp/speed run of the UPD-24 ring, 2000 steps).
WORKER_THREADS = 1


class EngineMissing(ValueError):
    """libcosim (libcosimpy) is not installed."""


def read_info(ssp) -> dict:
    """The archive's ``resources/system.json``, checked (:class:`damper.ring_info.RingInfo`);
    ValueError if it is not a ring archive or its description is malformed."""
    path = Path(ssp)
    if not path.exists():
        raise ValueError(f"{path}: no such SSP archive")
    check_regular_input(path, MAX_SSP_BYTES, "SSP archive")
    try:
        with zipfile.ZipFile(path) as zf:
            check_zip_members(zf, MAX_SSP_BYTES, f"SSP archive {path}")
            info = json.loads(zf.read("resources/system.json"))
    except (zipfile.BadZipFile, KeyError, json.JSONDecodeError, UnicodeDecodeError):
        raise ValueError(f"{path} is not a ring archive of `damper system` (no "
                         "resources/system.json): build one with damper system -o ring.ssp") from None
    if not isinstance(info, dict) or info.get("kind") != "damper-ring":
        raise ValueError(f"{path}: resources/system.json is not a damper-ring description")
    info = parse(RingInfo, info, f"{path}: resources/system.json").model_dump()
    if info["fmi_version"] != 2:
        raise ValueError(f"{path} holds FMI {info['fmi_version']} FMUs; libcosim runs FMI 2 "
                         "only (build it with damper system --fmi-version 2)")
    return info


def _check_members(path: Path) -> None:
    """ValueError naming an FMU that ``SystemStructure.ssd`` uses and the archive lacks
    (libcosim would only say that it cannot create the execution)."""
    with zipfile.ZipFile(path) as zf:
        names = set(zf.namelist())
        if "SystemStructure.ssd" not in names:
            raise ValueError(f"{path}: the archive has no SystemStructure.ssd: rebuild it with damper system")
        ssd = zf.read("SystemStructure.ssd").decode("utf-8", "replace")
    for source in sorted(set(re.findall(r'<ssd:Component\b[^>]*\bsource="([^"]+)"', ssd))):
        if source not in names:
            raise ValueError(f"{path}: SystemStructure.ssd uses {source}, which the archive does not hold: "
                             "rebuild it with damper system")


def _engine():
    try:
        from libcosimpy.CosimEnums import CosimVariableType
        from libcosimpy.CosimExecution import CosimExecution
        from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
        from libcosimpy.CosimObserver import CosimObserver
    except ImportError:
        raise EngineMissing("the co-simulation engine libcosim is not installed here: "
                            "pip install libcosimpy (Linux x86-64, FMI 2)") from None
    log_output_level(CosimLogLevel.WARNING)
    return CosimExecution, CosimObserver, CosimVariableType


def _unpack(ssp, step_ns: int, directory: Path) -> Path:
    """The archive unpacked into ``directory`` with the step and the worker threads in its
    SSD's fixed-step annotation (libcosim truncates the step to whole ns: written as
    step_ns + 1/2 ns)."""
    with zipfile.ZipFile(ssp) as zf:
        check_zip_members(zf, MAX_SSP_BYTES, f"SSP archive {ssp}")   # again: it may have changed
        zf.extractall(directory)
    ssd = directory / "SystemStructure.ssd"
    text, n = re.subn(r'<osp:FixedStepAlgorithm[^>]*/>',
                      f'<osp:FixedStepAlgorithm baseStepSize="{(step_ns + 0.5) * 1e-9!r}" '
                      f'numWorkerThreads="{WORKER_THREADS}"/>', ssd.read_text())
    if n != 1:
        raise ValueError(f"{ssp}: SystemStructure.ssd has no fixed-step annotation")
    ssd.write_text(text)
    return directory


def plan_step(info: dict, frequency_hz: float, step: float | None, force: bool) -> dict:
    """Steps per period n and the step [ns] for ``step`` (default: the archive's), checked
    against the coupling limit (ValueError above it unless ``force``)."""
    if not (np.isfinite(frequency_hz) and frequency_hz > 0):
        raise ValueError(f"--frequency-hz must be finite and > 0, got {frequency_hz}")
    if 2 * np.pi * frequency_hz > limits.MAX_OMEGA:
        raise ValueError(f"--frequency-hz {frequency_hz:g} is above the limit {limits.MAX_OMEGA / 2 / np.pi:.3g} Hz")
    h = info["default_step"] if step is None else float(step)
    if not (np.isfinite(h) and h > 0):
        raise ValueError(f"--step must be finite and > 0 s, got {step}")
    limit = info["step_limit"]
    if h > limit and not force:
        raise ValueError(f"--step {h:.4g} s is above the coupling limit {limit:.4g} s "
                         f"(2 / omega_max, omega_max = {info['omega_max']:.4g} rad/s: the damper "
                         "on its stuck contacts); the explicit coupling would be unstable. Use "
                         f"a smaller step (default {info['default_step']:.4g} s) or --force")
    T_ns = 1e9 / frequency_hz
    if T_ns < MIN_STEPS_PER_PERIOD:
        raise ValueError(f"--frequency-hz {frequency_hz:g}: a period of {T_ns:.3g} ns cannot hold "
                         f"{MIN_STEPS_PER_PERIOD} of libcosim's whole-ns steps")
    n_real = max(float(np.ceil(T_ns / (h * 1e9) - 1e-9)), MIN_STEPS_PER_PERIOD)  # may be huge or inf
    if not n_real <= MAX_STEPS_PER_PERIOD:
        raise ValueError(f"--step {h:.3g} s gives {n_real:.3g} steps a period at {frequency_hz:g} Hz (at "
                         f"most {MAX_STEPS_PER_PERIOD}: the response buffer holds two periods): use a "
                         "larger step or a higher frequency")
    n = int(n_real)
    h_ns = int(round(T_ns / n))
    if h_ns < 1:
        raise ValueError(f"--step {h} s is below libcosim's resolution (1 ns) at {frequency_hz} Hz")
    return {"steps_per_period": n, "step_ns": h_ns, "step": h_ns * 1e-9,
            "period_error": (n * h_ns - T_ns) / T_ns}


def first_harmonic(t: np.ndarray, x: np.ndarray, omega: float) -> complex:
    """H1 (cos - i sin convention, x ~ Re(H1 e^(i omega t))) by least squares on
    harmonics 0..FIT_HARMONICS at the sample times ``t`` [s]."""
    cols = [np.ones_like(t)]
    for k in range(1, FIT_HARMONICS + 1):
        cols += [np.cos(k * omega * t), np.sin(k * omega * t)]
    c, *_ = np.linalg.lstsq(np.column_stack(cols), x, rcond=None)
    return complex(c[1], -c[2])


class _Ring:
    """The loaded execution with the variables the runner reads."""

    def __init__(self, ssp, info, plan, frequency_hz):
        _engine()   # EngineMissing before any temporary folder
        self._tmp = tempfile.TemporaryDirectory(prefix="damper_cosim_")
        try:
            self._load(ssp, info, plan, frequency_hz)
        except BaseException:
            self.close()
            raise

    def close(self) -> None:
        """Remove the unpacked archive (also after an error, Ctrl-C or SIGTERM)."""
        self._tmp.cleanup()

    def _load(self, ssp, info, plan, frequency_hz) -> None:
        CosimExecution, CosimObserver, vt = _engine()
        root = _unpack(ssp, plan["step_ns"], Path(self._tmp.name))
        self.ex = CosimExecution.from_ssp_file(str(root))
        self.info, self.n = info, plan["steps_per_period"]
        self.idx = {name: self.ex.slave_index_from_instance_name(name)
                    for name in info["blades_components"] + info["damper_components"]}
        if any(i is None for i in self.idx.values()):
            raise ValueError(f"{ssp}: the archive lacks components {info['blades_components']}")
        self.vr = {name: {v.name.decode(): v.reference for v in self.ex.slave_variables(i)}
                   for name, i in self.idx.items()}
        for b in info["blades_components"]:
            self.ex.real_initial_value(self.idx[b], self.vr[b]["frequency"], float(frequency_hz))
        self.series = CosimObserver.create_time_series(buffer_size=2 * self.n + 16)
        self.last = CosimObserver.create_last_value()
        self.ex.add_observer(self.series)
        self.ex.add_observer(self.last)
        for b in info["blades_components"]:
            self.series.start_time_series(self.idx[b], self.vr[b][info["response"]], vt.REAL)

    def response(self, k: int) -> tuple[np.ndarray, np.ndarray]:
        """Times [s] (n,) and response samples (n_blades, n) of period k (1-based)."""
        xs, t = [], None
        for b in self.info["blades_components"]:
            times, _, vals = self.series.time_series_real_samples(
                self.idx[b], self.vr[b][self.info["response"]], (k - 1) * self.n + 1, self.n)
            if len(vals) != self.n:
                raise RuntimeError(f"libcosim returned {len(vals)} samples of a period, not {self.n}")
            xs.append(vals)
            t = np.asarray(times, dtype=float) * 1e-9
        return t, np.array(xs)

    def energies(self) -> dict:
        """Cumulative energies summed over the components [J]."""
        out = {}
        names = {"blade": ("W_excitation", "W_damping", "W_interface", "W_neighbours_stiffness",
                           "W_neighbours_damping", "energy"),
                 "damper": ("W_friction", "W_dashpots", "W_platforms", "energy")}
        for kind, comps in (("blade", self.info["blades_components"]),
                            ("damper", self.info["damper_components"])):
            for c in comps:
                vals = self.last.last_real_values(self.idx[c], [self.vr[c][v] for v in names[kind]])
                for v, x in zip(names[kind], vals):
                    out[f"{kind}_{v}"] = out.get(f"{kind}_{v}", 0.0) + x
        out["coupling_energy"] = self._coupling_energy()
        return out

    def _coupling_energy(self) -> float:
        """U_c = sum_j q_j^T K_next q_(j+1) over the ring [J] (module docstring)."""
        K = np.asarray(self.info.get("K_next_coupling") or [], dtype=float)
        if K.size == 0:
            return 0.0
        blades = self.info["blades_components"]
        q = [np.array(self.last.last_real_values(
            self.idx[b], [self.vr[b][f"q_{d}"] for d in self.info["coupling_dofs"]]))
            for b in blades]
        return float(sum(q[j] @ K @ q[(j + 1) % len(q)] for j in range(len(q))))


def energy_balance(e0: dict, e1: dict) -> dict:
    """The last period's energy terms [J] and the relative residual (module docstring)."""
    d = {k: e1[k] - e0[k] for k in e1}
    exc = d["blade_W_excitation"]
    structural = d["blade_W_damping"] - d["blade_W_neighbours_damping"]
    dampers = d["damper_W_friction"] + d["damper_W_dashpots"]
    stored = d["blade_energy"] + d["damper_energy"] + d["coupling_energy"]
    residual = exc - structural - dampers - stored
    return {"excitation": exc, "structural": structural, "damper_friction": d["damper_W_friction"],
            "damper_dashpots": d["damper_W_dashpots"], "stored_change": stored,
            "neighbours_mismatch": d["blade_W_neighbours_stiffness"] + d["coupling_energy"],
            "interface_mismatch": d["blade_W_interface"] + d["damper_W_platforms"],
            "residual": residual, "relative_residual": residual / exc if exc else None}


def _smaller_step(plan: dict, info: dict) -> str:
    return (f"the explicit coupling is unstable or inaccurate at the step {plan['step']:.3g} s: use a smaller "
            f"--step (the coupling limit is {info['step_limit']:.3g} s, the archive's default "
            f"{info['default_step']:.3g} s)")


def _check_growth(k: int, h1: np.ndarray, h1_prev, plan: dict, info: dict) -> None:
    """RuntimeError when period k's first harmonics are not finite or, after the start
    transient, grew by more than :data:`MAX_GROWTH` in one period (a diverging coupling)."""
    if not np.all(np.isfinite(h1)):
        raise RuntimeError(f"the co-simulation diverged in period {k} (not a number): {_smaller_step(plan, info)}")
    if h1_prev is None or k <= MIN_PERIODS:
        return
    growth = float(np.max(np.abs(h1) / np.maximum(np.abs(h1_prev), np.finfo(float).tiny)))
    if growth > MAX_GROWTH:
        raise RuntimeError(f"the co-simulation diverged in period {k}: the response grew {growth:.3g} times "
                           f"in one period (to {np.abs(h1).max():.3g} m): {_smaller_step(plan, info)}")


def _check_balance(balance: dict, plan: dict, info: dict) -> None:
    """RuntimeError when the last period's energy balance misses more than
    :data:`MAX_ENERGY_RESIDUAL` of the excitation's work."""
    rel = balance["relative_residual"]
    if rel is not None and not abs(rel) <= MAX_ENERGY_RESIDUAL:
        raise RuntimeError(f"the co-simulation's energy balance is off by {abs(rel):.3g} times the excitation's "
                           f"work over the last period (at most {MAX_ENERGY_RESIDUAL:g}): "
                           f"{_smaller_step(plan, info)}")


def _march(ring: _Ring, plan: dict, periods: int, tol: float, omega: float):
    """Step period by period until settled (module docstring) or ``periods`` ran;
    (k, h1, t, x, balance, deltas, est, settled) of the last period."""
    e_prev, h1_prev, deltas = ring.energies(), None, []
    settled, est = False, float("inf")
    for k in range(1, periods + 1):
        if not ring.ex.step(ring.n):
            raise RuntimeError(f"libcosim failed in period {k} (an FMU refused a step: see its message above)")
        t, x = ring.response(k)
        h1 = np.array([first_harmonic(t, xi, omega) for xi in x])
        e_now = ring.energies()
        balance = energy_balance(e_prev, e_now)
        e_prev = e_now
        _check_growth(k, h1, h1_prev, plan, ring.info)
        if h1_prev is not None:
            deltas.append(float(np.max(np.abs(h1 - h1_prev)) / np.max(np.abs(h1))))
            if len(deltas) >= 2:
                rho = min(max(deltas[-1] / max(deltas[-2], 1e-300), 0.0), 0.999)
                est = deltas[-1] * rho / (1.0 - rho)
                if k >= MIN_PERIODS and max(est, deltas[-1]) < tol:
                    settled = True
                    break
        h1_prev = h1
    return k, h1, t, x, balance, deltas, est, settled


@contextlib.contextmanager
def _stdout_to_stderr():
    """File descriptor 1 pointed at standard error inside (libcosim's C++ log sink writes to
    fd 1; Python's own stdout is flushed first and restored after)."""
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        os.dup2(2, 1)
        yield
    finally:
        try:
            ctypes.CDLL(None).fflush(None)  # C stdio buffers (std::cout syncs with them)
        except (OSError, AttributeError):
            pass
        os.dup2(saved, 1)
        os.close(saved)


def run(ssp, frequency_hz: float, periods: int, step: float | None = None, force: bool = False,
        tol: float = SETTLE_TOL, keep_last: bool = False) -> dict:
    """Co-simulate the ring of ``ssp`` at ``frequency_hz`` until settled (<= ``periods``).

    Returns
    -------
    dict: amplitude [m] (|H1| of blade 0's response), amplitude_blades, phase_steps [rad]
    (blade j+1 minus j: phi when the wave is tuned), periods, settled, settle_change,
    steps_per_period, step [s], step_limit [s], energy (:func:`energy_balance`),
    wall_time_s, wall_time_per_period_s; with ``keep_last`` the last period's times
    and response samples (last_t, last_response).

    Raises
    ------
    ValueError
        Not a ring archive, bad frequency / periods / step, a step above the coupling
        limit without ``force``, libcosim missing (:class:`EngineMissing`).
    RuntimeError
        libcosim failed to load or step the system, or the coupling diverged (a
        response growing more than :data:`MAX_GROWTH` times a period, or an energy
        balance off by more than :data:`MAX_ENERGY_RESIDUAL`).
    """
    info = read_info(ssp)
    _check_members(Path(ssp))
    limits.check_size("--periods", periods, 1, limits.MAX_COSIM_PERIODS,
                      "a ring settles in tens to hundreds of periods; a period costs ~0.7 s at the default step")
    if not (np.isfinite(tol) and 0 <= tol < MAX_SETTLE_TOL):
        raise ValueError(f"--tol must be a relative change per period in [0, {MAX_SETTLE_TOL:g}), got {tol:g} "
                         "(0 runs all --periods)")
    plan = plan_step(info, frequency_hz, step, force)
    if periods * plan["steps_per_period"] > limits.MAX_COSIM_STEPS:
        raise ValueError(f"--periods {periods} of {plan['steps_per_period']} steps is "
                         f"{periods * plan['steps_per_period']:.3g} steps, above the limit "
                         f"{limits.MAX_COSIM_STEPS:.0e} (~0.3 ms each: hours): fewer --periods or a larger --step")
    omega = 2 * np.pi * frequency_hz
    t0 = time.perf_counter()
    with _stdout_to_stderr():  # libcosim logs on stdout, which holds the --json object
        try:
            ring = _Ring(ssp, info, plan, frequency_hz)
        except AssertionError as err:  # libcosimpy reports failures with assert
            raise RuntimeError(f"libcosim could not load {ssp}: {err}") from None
        try:
            k, h1, t, x, balance, deltas, est, settled = _march(ring, plan, periods, tol, omega)
        finally:
            ring.close()   # the unpacked archive, also after an error, Ctrl-C or SIGTERM
    wall = time.perf_counter() - t0
    _check_balance(balance, plan, info)
    nr = len(h1)
    out = {"frequency_hz": frequency_hz, "amplitude": float(abs(h1[0])),
           "amplitude_blades": np.abs(h1).tolist(),
           "phase_steps": np.angle(h1[(np.arange(nr) + 1) % nr] / h1).tolist(),
           "interblade_phase": info["interblade_phase"], "periods": k, "settled": settled,
           "settle_change": deltas[-1] if deltas else None,
           "settle_estimate": est if np.isfinite(est) else None, "tol": tol,
           "steps_per_period": plan["steps_per_period"], "step": plan["step"],
           "step_limit": info["step_limit"], "period_error": plan["period_error"],
           "energy": balance, "wall_time_s": wall, "wall_time_per_period_s": wall / k,
           "cf": info["cf"], "f0": info["f0"], "response_dof": info["response_dof"]}
    if keep_last:
        out["last_t"], out["last_response"] = t, x[0]
    return out
