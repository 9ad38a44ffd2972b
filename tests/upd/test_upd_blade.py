"""Bring your own blade: UPD-24 written as a blade file (npz, Matrix Market) reproduces
the built-in; a general (non-symmetric) blade-to-blade coupling keeps the cyclic sector
equal to the ring; bad blade files are refused with the problem named (CLI exit 2)."""
import json

import numpy as np
import pytest
from failure_output import no_result

from damper.cli import main
from harmonic_balance.bladed_disk.blade import blade_arrays, write_mtx, write_npz
from harmonic_balance.bladed_disk.config import load_config
from harmonic_balance.bladed_disk.hb import SectorHB
from harmonic_balance.bladed_disk.ring import RingHB
from harmonic_balance.bladed_disk.sector import (
    Sector,
    linear_response,
    modal_response,
    natural_frequencies,
)
from harmonic_balance.bladed_disk.solve import frf, start_point
from harmonic_balance.bladed_disk.timeint import march_ring

#: Linear peak frequency against the natural frequency: the displacement peak lies ~zeta^2
#: = 4e-6 below it (0.2 % damping); measured 5.0e-6 (revision a12e5f1); as
#: test_upd_linear.PEAK_RTOL.
PEAK_RTOL = 2e-5

#: The same matrices through a file: npz is exact and mmwrite(precision=17) round-trips
#: a double exactly, so only the order of operations could differ: measured 0 (equal).
SAME_RTOL = 1e-13


def _toml(tmp_path, blade_keys: dict) -> str:
    lines = ["[blade]"] + [f"{k} = {json.dumps(v)}" for k, v in blade_keys.items()]
    path = tmp_path / "upd.toml"
    path.write_text("\n".join(lines) + "\n")
    return str(path)


@pytest.fixture(scope="module")
def builtin():
    return Sector(load_config())


@pytest.fixture(params=["npz", "mtx"])
def from_file(request, tmp_path, builtin):
    if request.param == "npz":
        write_npz(builtin.blade, tmp_path / "upd24.npz")
        return _toml(tmp_path, {"file": "upd24.npz"})
    keys = write_mtx(builtin.blade, tmp_path / "mtx")
    keys = {k: (f"mtx/{v}" if k in ("M", "K", "K_next") else v) for k, v in keys.items()}
    return _toml(tmp_path, keys)


def test_blade_file_reproduces_the_builtin(from_file, builtin):
    sector = Sector(load_config(from_file))
    assert sector.blade.source != "built-in" and sector.dof_names == builtin.dof_names
    for name in ("M", "K", "K_next"):
        assert np.array_equal(getattr(sector.blade, name), getattr(builtin.blade, name))
    w = 2 * np.pi * np.linspace(380, 520, 8)
    for damper in ("free", "stuck", "sliding"):
        a, b = linear_response(sector, w, damper), linear_response(builtin, w, damper)
        assert np.abs(a - b).max() <= SAME_RTOL * np.abs(b).max()
        assert natural_frequencies(sector, 6, damper) == pytest.approx(
            natural_frequencies(builtin, 6, damper), rel=SAME_RTOL)
    band = 2 * np.pi * np.linspace(425, 465, 12)
    ca, cb = frf(SectorHB(sector, 3), band), frf(SectorHB(builtin, 3), band)
    assert ca.peak_amplitude == pytest.approx(cb.peak_amplitude, rel=SAME_RTOL)
    assert ca.amplitude == pytest.approx(cb.amplitude, rel=SAME_RTOL)
    ta = march_ring(sector, [2 * np.pi * 450.0], max_periods=3)["amplitude"]
    tb = march_ring(builtin, [2 * np.pi * 450.0], max_periods=3)["amplitude"]
    assert ta == pytest.approx(tb, rel=SAME_RTOL)


def test_cli_runs_a_blade_file(from_file, capsys):
    assert main(["upd", "modes", "--config", from_file, "--json"]) == 0
    modes = json.loads(capsys.readouterr().out)
    assert main(["upd", "modes", "--json"]) == 0
    assert modes == json.loads(capsys.readouterr().out)
    assert main(["upd", "frf", "--config", from_file, "--damper", "stuck", "--json"]) == 0
    stuck = json.loads(capsys.readouterr().out)
    assert stuck["peak_frequency_hz"] == pytest.approx(modes["stuck_hz"][6][0], rel=PEAK_RTOL)
    assert stuck["response_dof"] == "u_a"


def _coupled_blade(builtin):
    """UPD-24 plus a spring k between u_p of blade j and u_r of blade j+1 (a non-symmetric
    K_next), explicit C = beta K and C_next = beta K_next + a non-symmetric dashpot."""
    arr = blade_arrays(builtin.blade)
    k, beta = 3e5, builtin.beta
    arr["K"] = arr["K"].copy()
    arr["K"][1, 1] += k
    arr["K"][0, 0] += k
    arr["K_next"] = arr["K_next"].copy()
    arr["K_next"][1, 0] -= k
    C_next = beta * arr["K_next"]
    C_next[2, 0] -= 1e-3  # dashpot v_p of j - u_r of j+1 [N s/m]
    C = beta * arr["K"]
    C[2, 2] += 1e-3
    C[0, 0] += 1e-3
    arr.update(C=C, C_next=C_next)
    return arr


def test_general_coupling_sector_equals_ring(tmp_path, builtin):
    """The cyclic coupling element with a non-symmetric K_next, C_next: the sector solution
    mapped to the 4-blade ring satisfies the ring's equations (no symmetry assumed there)."""
    np.savez(tmp_path / "b.npz", **_coupled_blade(builtin))
    sector = Sector(load_config(_toml(tmp_path, {"file": "b.npz"})))
    K6 = sector.K_struct(sector.cfg.phi)
    assert np.iscomplexobj(K6) and np.allclose(K6, K6.conj().T)
    # the complex Hermitian linear limits: direct solve == complex modal superposition
    w = 2 * np.pi * np.linspace(380, 520, 8)
    for damper in ("free", "stuck"):
        a, b = linear_response(sector, w, damper), modal_response(sector, w, damper)
        # as test_upd_linear.MODAL_RTOL (measured 2e-8 and 4e-7 there, 2e-12 here)
        assert np.abs(a - b).max() <= 1e-6 * np.abs(a).max()
    hb, rg = SectorHB(sector, 3, cf=60.0), RingHB(sector, 3, cf=60.0)
    w = 2 * np.pi * 440.0
    x = start_point(hb, w)
    xr = rg.from_sector(x)
    # the sector solution's Newton tolerance (solve.TOL_REL) bounds it; measured 5e-14
    assert np.linalg.norm(rg(xr, w, False)) < 1e-10 * np.linalg.norm(rg.Fext)
    # and the coupling changed the answer (the test can fail)
    assert hb.amplitude_h1(x) != pytest.approx(SectorHB(builtin, 3, cf=60.0).amplitude_h1(
        start_point(SectorHB(builtin, 3, cf=60.0), w)), rel=1e-3)


def _bad_arrays(builtin, case):
    arr = blade_arrays(builtin.blade)
    arr = {k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in arr.items()}
    if case == "nonsymmetric M":
        arr["M"][0, 1] = 1e-3
    elif case == "indefinite M":
        arr["M"][2, 2] = -0.02
    elif case == "indefinite K":
        arr["K"][3, 3] = -1e6
    elif case == "wrong shape":
        arr["K"] = arr["K"][:3, :3]
    elif case == "unknown DOF":
        arr["left"] = np.array(["u_p", "w_p"])
    elif case == "NaN":
        arr["K_next"][0, 0] = np.nan
    elif case == "missing K":
        del arr["K"]
    elif case == "complex K":  # a loss factor: hysteretic damping is not modelled
        arr["K"] = arr["K"] * (1 + 0.01j)
    return arr


BAD = {"nonsymmetric M": "M is not symmetric", "indefinite M": "M is not positive definite",
       "indefinite K": "K \\+ K_next \\+ K_next\\^T is indefinite", "wrong shape": "K has shape",
       "unknown DOF": "unknown DOF 'w_p'", "NaN": "K_next has NaN", "missing K": "M and K",
       "complex K": "K is complex"}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_blade_file_is_refused(case, tmp_path, builtin, capsys):
    np.savez(tmp_path / "bad.npz", **_bad_arrays(builtin, case))
    cfg = _toml(tmp_path, {"file": "bad.npz"})
    with pytest.raises(ValueError, match=BAD[case]):
        load_config(cfg)
    assert main(["upd", "frf", "--config", cfg, "--json"]) == 2
    cap = capsys.readouterr()
    assert "bad.npz" in cap.err and "Traceback" not in cap.err and no_result(cap.out, cap.err, 2)


@pytest.mark.parametrize("keys, match", [
    ({"file": "missing.npz"}, "cannot read"),
    ({"M": "M.mtx"}, "needs both M and K"),
    ({"file": "b.npz", "K": "K.mtx"}, "either file"),
    ({"forced": "nope"}, "unknown DOF 'nope'"),
    ({"left": ["u_p"]}, "left must name 2"),
    ({"file": 3}, "blade.file: must be a valid string, got an integer 3"),
    ({"left": "u_p"}, "blade.left: must be a valid list, got a string 'u_p'"),
])
def test_bad_blade_section_is_refused(keys, match, tmp_path, capsys):
    cfg = _toml(tmp_path, keys)
    with pytest.raises(ValueError, match=match):
        load_config(cfg)
    assert main(["upd", "modes", "--config", cfg]) == 2
    assert "Traceback" not in capsys.readouterr().err


def test_roles_from_the_toml_override_the_file(tmp_path, builtin):
    write_npz(builtin.blade, tmp_path / "b.npz")
    sector = Sector(load_config(_toml(tmp_path, {"file": "b.npz", "response": "u_p"})))
    assert (sector.forced, sector.response) == (3, 1)
