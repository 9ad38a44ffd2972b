"""The ring archive (damper system) in libcosim and fmpy's SSP reader, the runner
(damper cosim) and their refusals."""
import importlib.util
import json
import sys
import zipfile

import numpy as np
import pytest
from failure_output import no_result
from upd_system_loads import CF, F0

from damper.cli import main
from damper.cosim import read_info, run
from harmonic_balance.bladed_disk.timeint import march_ring

#: The tests that run a co-simulation; the others (the archive, fmpy's reader, the
#: refusals, the message when libcosim is missing) run without it.
needs_libcosim = pytest.mark.skipif(importlib.util.find_spec("libcosimpy") is None,
                                    reason="libcosimpy (PyPI) is a test dependency")
#: The modules the runner imports, hidden to act as a machine without libcosim.
LIBCOSIM_MODULES = ("libcosimpy", "libcosimpy.CosimExecution", "libcosimpy.CosimEnums",
                    "libcosimpy.CosimLogging", "libcosimpy.CosimObserver")

#: The co-simulation against the ring time integration after the same 3 periods from the
#: same prestress (both march the same ODE; measured -4e-4 at the default step).
TRANSIENT_RTOL = 2e-3
#: Energy over the last period closed by the coupling (measured 1e-5 in the transient).
BALANCE_RTOL = 1e-3


def test_archive_structure_and_fmpy_reader(ring_ssp):
    """SSP 1.0: the SSD validates against fmpy's copy of the SSP schemas; 2 N_r components,
    every connector wired once; both FMUs pass fmpy validation."""
    from fmpy.ssp.ssd import read_ssd
    from fmpy.validation import validate_fmu

    info = read_info(ring_ssp)
    nr = info["ring_blades"]
    assert nr == 4  # N_b / gcd(N_b, EO) = 24 / 6
    ssd = read_ssd(str(ring_ssp), validate=True)
    names = [e.name for e in ssd.system.elements]
    assert names == [f"blade{j}" for j in range(nr)] + [f"damper{j}" for j in range(nr)]
    ends = [(c.endElement, c.endConnector) for c in ssd.system.connections]
    assert len(ends) == len(set(ends))  # no input driven twice
    inputs = {(e.name, c.name) for e in ssd.system.elements for c in e.connectors
              if c.kind == "input"}
    assert set(ends) == inputs  # and none left open
    with zipfile.ZipFile(ring_ssp) as zf:
        for name in ("blade.fmu", "damper.fmu"):
            zf.extract(f"resources/{name}", ring_ssp.parent / "x")
            assert validate_fmu(str(ring_ssp.parent / "x" / "resources" / name)) == []


def test_fmpy_ssp_simulation_runs(ring_ssp):
    """fmpy's own SSP master runs the archive (a few steps; it starts every connector
    at 0 instead of the start values, so only that it runs is checked)."""
    from fmpy.ssp.simulation import simulate_ssp

    rows = simulate_ssp(str(ring_ssp), stop_time=5e-6, step_size=1e-6)
    assert len(rows) >= 5 and np.all(np.isfinite(rows["blade0.q_u_a"]))
    assert np.all(np.isfinite(rows["damper0.F_left_x"]))


@needs_libcosim
def test_libcosim_transient_matches_the_ring_time_integration(ring_ssp, sector):
    """Three periods from the prestress at rest: the co-simulated first harmonic of every
    blade's u_a against the central-difference march of the same ring."""
    f = 448.25
    r = run(ring_ssp, f, 3, tol=0.0)
    ti = march_ring(sector, [2 * np.pi * f], cf=CF, f0=F0, max_periods=3)
    assert r["periods"] == 3 and not r["settled"]
    assert np.array(r["amplitude_blades"]) == pytest.approx(ti["amplitude_blades"][0],
                                                            rel=TRANSIENT_RTOL)
    assert abs(r["energy"]["relative_residual"]) < BALANCE_RTOL
    assert r["step"] <= r["step_limit"] / 8 * (1 + 1e-9)


def _cli(argv, capsys):
    code = main(argv)
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def _hide_libcosim(monkeypatch):
    for name in LIBCOSIM_MODULES:
        monkeypatch.setitem(sys.modules, name, None)  # import fails as if not installed


@needs_libcosim
def test_cli_json(ring_ssp, capsys):
    code, out, _ = _cli(["cosim", str(ring_ssp), "--frequency-hz", "440", "--periods", "1",
                         "--tol", "0", "--json"], capsys)
    r = json.loads(out)
    assert code == 0 and r["periods"] == 1 and r["amplitude"] > 0
    for k in ("amplitude", "periods", "step", "energy", "wall_time_s", "settled"):
        assert k in r


def test_cli_refusals_come_before_the_engine(ring_ssp, tmp_path, capsys, monkeypatch):
    """Bad input is refused (exit 2, what to change) whether or not libcosim is installed."""
    _hide_libcosim(monkeypatch)
    # a step above the coupling limit: refused unless --force
    code, _, err = _cli(["cosim", str(ring_ssp), "--frequency-hz", "440", "--step", "1e-5"], capsys)
    assert code == 2 and "coupling limit" in err and "--force" in err
    for bad in (["--frequency-hz", "0"], ["--frequency-hz", "440", "--periods", "0"],
                ["--frequency-hz", "nan"], ["--frequency-hz", "440", "--step", "-1"]):
        code, _, err = _cli(["cosim", str(ring_ssp), *bad], capsys)
        assert code == 2 and "error" in err
    code, _, err = _cli(["cosim", str(tmp_path / "none.ssp"), "--frequency-hz", "440"], capsys)
    assert code == 2
    (tmp_path / "other.ssp").write_bytes(b"not a zip")
    code, _, err = _cli(["cosim", str(tmp_path / "other.ssp"), "--frequency-hz", "440"], capsys)
    assert code == 2 and "damper system" in err


def test_engine_missing_is_a_clear_refusal(ring_ssp, monkeypatch, capsys):
    _hide_libcosim(monkeypatch)
    code, out, err = _cli(["cosim", str(ring_ssp), "--frequency-hz", "440", "--json"], capsys)
    assert code == 2 and "libcosim" in err and "pip install libcosimpy" in err and no_result(out, err, 2)


def _config(tmp_path, blade: str) -> str:
    path = tmp_path / "upd.toml"
    path.write_text(f"[blade]\n{blade}\n")
    return str(path)


@pytest.mark.parametrize("blade, message", [
    ('left = ["u_p", "nope"]', "nope"),                 # an unknown DOF role
    ("m_p = 0.0", "m_p"),                                # no mass on the platform: M not SPD
])
def test_system_refuses_bad_configs_without_writing(tmp_path, capsys, blade, message):
    out = tmp_path / "ring.ssp"
    code, _, err = _cli(["system", "--config", _config(tmp_path, blade), "-o", str(out)], capsys)
    assert code == 2 and message in err and not out.exists()


def test_system_refuses_bad_loads_and_writes_json(tmp_path, capsys):
    out = tmp_path / "ring.ssp"
    for bad in (["--cf", "-1"], ["--f0", "0"], ["--cf", "nan"], ["--frequency-hz", "-3"]):
        code, _, err = _cli(["system", *bad, "-o", str(out)], capsys)
        assert code == 2 and not out.exists()
    code, text, _ = _cli(["system", "--cf", "60", "-o", str(out), "--json"], capsys)
    info = json.loads(text)
    assert code == 0 and out.exists() and info["cf"] == 60 and info["ring_blades"] == 4
    assert info["default_step"] == pytest.approx(info["step_limit"] / 8)


@pytest.mark.slow
@needs_libcosim
def test_settled_peak_against_hb_and_ring_time_integration(ring_ssp, sector):
    """CF 120 N at the HB (H = 7) peak frequency, settled to 1e-4: within 0.3 % of the ring
    time integration of the same ODE (measured +0.08 %) and within 2 % of the HB H = 7
    (measured -1.7 %: the HB's truncation, the ring TI is 1.8 % below it too)."""
    from harmonic_balance.bladed_disk.hb import SectorHB
    from harmonic_balance.bladed_disk.solve import frf

    hb = SectorHB(sector, 7, cf=CF, f0=F0)
    c = frf(hb, 2 * np.pi * np.linspace(440.0, 456.0, 9))
    f = c.peak_omega / (2 * np.pi)
    r = run(ring_ssp, f, 200)
    ti = march_ring(sector, [c.peak_omega], cf=CF, f0=F0, max_periods=300, tol=1e-5)
    assert r["settled"]
    assert r["amplitude"] == pytest.approx(ti["amplitude"][0], rel=3e-3)
    assert r["amplitude"] == pytest.approx(c.peak_amplitude, rel=0.02)
    assert abs(r["energy"]["relative_residual"]) < 0.01
    assert np.array(r["phase_steps"]) == pytest.approx(np.full(4, sector.cfg.phi), abs=1e-4)


def test_system_refuses_an_axial_platform_dof(tmp_path, sector, capsys):
    """A bring-your-own blade whose platform points name an axial DOF (left/right = [u, v,
    w]): the damper FMU slips in the plane only, so damper system refuses it."""
    from harmonic_balance.bladed_disk.blade import blade_arrays

    arr = blade_arrays(sector.blade)
    n = arr["M"].shape[0]
    grow = lambda A, d: np.pad(A, ((0, 1), (0, 1))) + np.diag([0.0] * n + [d])  # noqa: E731
    arr.update(M=grow(arr["M"], 0.1), K=grow(arr["K"], 8e5), K_next=grow(arr["K_next"], 0.0),
               dofs=np.append(arr["dofs"], "w_p"), left=np.array(["u_p", "v_p", "w_p"]),
               right=np.array(["u_p", "v_p", "w_p"]))
    np.savez(tmp_path / "axial.npz", **arr)
    out = tmp_path / "ring.ssp"
    code, _, err = _cli(["system", "--config", _config(tmp_path, 'file = "axial.npz"'), "-o",
                         str(out)], capsys)
    assert code == 2 and "axial" in err and not out.exists()
