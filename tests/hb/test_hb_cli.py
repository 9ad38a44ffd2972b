"""``damper frf``: JSON interface, file models, exit codes."""
import json

import numpy as np
import pytest
from failure_output import no_result

from contact_core.curve import VirginCurve, write_curve
from damper.cli import main

SDOF = ["frf", "--model", "sdof", "--mass", "1", "--stiffness", "1", "--damping", "0.01",
        "--contact-stiffness", "1", "--slip-force", "0.05", "--force", "0.05"]
#: Describing-function peak of this oscillator (test_hb_frf.df_peak, which the exact-link
#: H = 1 peak meets to 7e-12), written to 10 digits; the CLI's peak agrees to 1.2e-11
#: (revision a12e5f1): 1e-9 covers the rounding of the written value and the solvers'
#: stopping points (as test_hb_frf.DF_PEAK_RTOL).
DF_PEAK, DF_RTOL = 0.2007561542, 1e-9
#: The same model through the CLI's file readers and built in Python: the same
#: computation, round-off only. Measured 7.1e-15 (a12e5f1); 140x for other platforms.
SAME_MODEL_RTOL = 1e-12


def run_json(capsys, argv):
    code = main(argv)
    return code, json.loads(capsys.readouterr().out)


def test_sdof_json_has_the_interface_fields(capsys):
    code, out = run_json(capsys, SDOF + ["--harmonics", "1", "--omega", "0.9", "1.3", "--json"])
    assert code == 0
    for key in ("omega", "amplitude", "amplitude_h1", "peak_omega", "peak_amplitude",
                "points", "newton_iterations", "time_s"):
        assert key in out
    assert len(out["omega"]) == len(out["amplitude"]) == out["points"]
    assert abs(out["peak_amplitude"] / DF_PEAK - 1) < DF_RTOL
    assert out["omega"][0] == 0.9 and out["omega"][-1] == 1.3


@pytest.mark.parametrize("bad", [["--mass", "-1"], ["--omega", "1", "1"], ["--harmonics", "odd:0"],
                                 ["--slip-force", "nan"], ["--tolerance", "0"],
                                 ["--tolerance", "nan", "--json"], ["--tolerance", "1"],
                                 ["--tolerance", "1e-9"], ["--max-step", "inf"],
                                 ["--max-step", "-1", "--json"]])
def test_bad_input_exits_2(capsys, bad):
    argv = SDOF + ["--omega", "0.9", "1.3"] + bad
    assert main(argv) == 2
    cap = capsys.readouterr()
    assert "error" in cap.err and no_result(cap.out, cap.err, 2)


def test_a_finer_tolerance_gives_more_points_and_the_same_peak(capsys):
    """--tolerance sizes the steps (more points when finer); the peak is refined either
    way (the same to the refinement's tolerance, 1e-6 in frequency: measured 1.7e-7 in
    frequency, 2.5e-11 in amplitude, which is flat at the peak)."""
    base = SDOF + ["--harmonics", "3", "--omega", "0.9", "1.3", "--json"]
    _, coarse = run_json(capsys, base)
    _, fine = run_json(capsys, base + ["--tolerance", "1e-4"])
    assert fine["points"] > coarse["points"]
    assert abs(fine["peak_amplitude"] / coarse["peak_amplitude"] - 1) < 1e-9
    assert fine["peak_refined"] and coarse["peak_refined"]


def test_unfinished_curve_exits_3_and_keeps_the_points(capsys):
    code = main(SDOF + ["--omega", "0.9", "1.3", "--max-points", "5", "--json"])
    cap = capsys.readouterr()
    assert code == 3 and "stopped at parameter" in cap.err
    assert "raise --max-points" in cap.err      # the hint names what lifts the limit
    out = json.loads(cap.out)
    assert out["points"] == 5 and out["status"].startswith("continuation stopped")


def write_two_dof(tmp_path):
    M = np.diag([1.0, 0.5])
    K = np.array([[2.0, -1.0], [-1.0, 1.5]])
    np.savez(tmp_path / "m.npz", M=M, K=K, C=0.01 * M + 0.005 * K, force=np.array([0.05, 0.0]))
    # concave virgin curve: slopes 0.8 then 0.3 then 0 -> sliders (0.5, 0.05) + (0.3, 0.03)
    write_curve(VirginCurve(u=[0.0, 0.1, 0.2], T=[0.0, 0.08, 0.11], N=1.0), tmp_path / "c.json")
    (tmp_path / "e.toml").write_text(
        '[[element]]\ndofs = [0, 1]\ntype = "curve"\npath = "c.json"\n\n'
        '[[element]]\ndofs = [1]\ntype = "sliders"\nk = [0.5, 0.3]\nfs = [0.05, 0.03]\n')


def test_npz_and_toml_model_equals_the_same_model_built_in_python(tmp_path, capsys):
    write_two_dof(tmp_path)
    code, out = run_json(capsys, ["frf", "--model", str(tmp_path / "m.npz"), "--elements",
                                  str(tmp_path / "e.toml"), "--harmonics", "odd:3",
                                  "--omega", "0.6", "2.0", "--json"])
    assert code == 0 and out["status"] == "complete"
    from fmu_src.element import IwanElement
    from harmonic_balance.aft import FrictionLink
    from harmonic_balance.frf import compute_frf
    from harmonic_balance.model import Model, load_matrices

    lin, forcing, resp = load_matrices(tmp_path / "m.npz")
    same = IwanElement.from_sliders([0.5, 0.3], [0.05, 0.03])
    model = Model(lin, [FrictionLink(same, 0, 1), FrictionLink(same, 1)], forcing, resp)
    ref = compute_frf(model, "odd:3", (0.6, 2.0))
    assert abs(out["peak_amplitude"] / ref.peak_amplitude - 1) < SAME_MODEL_RTOL
    assert abs(out["peak_omega"] / ref.peak_omega - 1) < SAME_MODEL_RTOL


@pytest.mark.parametrize("command", ["frf", "backbone"])
def test_a_complex_stiffness_is_refused_not_made_real(tmp_path, capsys, command):
    """K (1 + i eta), a loss factor: refused with what to give instead (real K and C), no
    ComplexWarning and no result from the real part alone."""
    write_two_dof(tmp_path)
    with np.load(tmp_path / "m.npz") as z:
        arrays = dict(z)
    np.savez(tmp_path / "m.npz", **(arrays | {"K": arrays["K"] * (1 + 0.02j)}))
    span = ["--omega", "0.6", "2.0"] if command == "frf" else ["--amplitude", "1e-3", "1"]
    code = main([command, "--model", str(tmp_path / "m.npz"), "--elements", str(tmp_path / "e.toml"),
                 *span, "--json"])
    cap = capsys.readouterr()
    assert code == 2 and no_result(cap.out, cap.err, 2)
    assert "K is complex" in cap.err and "damping as a real matrix C" in cap.err
    assert "ComplexWarning" not in cap.err and len(cap.err.splitlines()) == 1


def test_bad_elements_file_exits_2(tmp_path, capsys):
    write_two_dof(tmp_path)
    (tmp_path / "e.toml").write_text('[[element]]\ndofs = [0, 5]\nk = 1.0\nfs = 0.1\n')
    assert main(["frf", "--model", str(tmp_path / "m.npz"), "--elements",
                 str(tmp_path / "e.toml"), "--omega", "0.6", "2.0"]) == 2
    assert "DOF 5" in capsys.readouterr().err


def test_non_concave_curve_file_exits_2_with_the_reason(tmp_path, capsys):
    write_two_dof(tmp_path)
    write_curve(VirginCurve(u=[0.0, 0.1, 0.2], T=[0.0, 0.02, 0.11], N=1.0), tmp_path / "c.json")
    (tmp_path / "e.toml").write_text('[[element]]\ndofs = [0]\ntype = "curve"\npath = "c.json"\n')
    assert main(["frf", "--model", str(tmp_path / "m.npz"), "--elements",
                 str(tmp_path / "e.toml"), "--omega", "0.6", "2.0"]) == 2
    assert "concave" in capsys.readouterr().err


def test_long_curve_is_reduced_and_the_fit_error_printed(tmp_path, capsys):
    """A 2000-point concave curve (more slope changes than the C element holds)."""
    u = np.linspace(0.0, 1e-3, 2000)
    write_curve(VirginCurve(u=u, T=10 * (1 - np.exp(-u / 2e-4)), N=1.0), tmp_path / "c.json")
    np.savez(tmp_path / "m.npz", M=np.eye(1), K=1e5 * np.eye(1), C=10 * np.eye(1),
             force=np.array([5.0]))
    (tmp_path / "e.toml").write_text('[[element]]\ndofs = [0]\ntype = "curve"\npath = "c.json"\n')
    code = main(["frf", "--model", str(tmp_path / "m.npz"), "--elements", str(tmp_path / "e.toml"),
                 "--omega", "200", "500", "--json"])
    cap = capsys.readouterr()
    assert code == 0 and json.loads(cap.out)["status"] == "complete"
    assert "reduced" in cap.err and "fit" in cap.err


def test_stability_modes(capsys):
    """--stability all solves Hill at every point, auto where stability can change (the
    same flags here: a stable friction curve), off not at all."""
    base = SDOF + ["--harmonics", "3", "--omega", "0.9", "1.3", "--json"]
    _, auto = run_json(capsys, base)
    _, every = run_json(capsys, base + ["--stability", "all"])
    _, off = run_json(capsys, base + ["--stability", "off"])
    assert every["stability_checks"] == every["points"] == auto["points"]
    assert 2 <= auto["stability_checks"] < auto["points"] and auto["stable"] == every["stable"]
    assert off["stable"] is None and off["stability_checks"] == 0


def _two_dof_with(tmp_path, **changes):
    write_two_dof(tmp_path)
    with np.load(tmp_path / "m.npz") as z:
        arrays = dict(z)
    np.savez(tmp_path / "m.npz", **(arrays | {k: f(arrays) for k, f in changes.items()}))


@pytest.mark.parametrize("change, words", [
    ({"C": lambda a: -a["C"]}, "C must be positive semi-definite"),   # accepted: an unstable "steady state"
    ({"K": lambda a: -a["K"]}, "K must be positive semi-definite"),   # exit 3, "undamped resonance"
    ({"M": lambda a: 1e-300 * a["M"]}, "K over M"),                   # NaN inside the element
    ({"M": lambda a: 1e300 * a["M"]}, "M has an entry of magnitude"),  # overflow, exit 3
])
def test_a_matrix_that_is_no_structure_is_refused_with_what_is_wrong(tmp_path, capsys, change, words):
    _two_dof_with(tmp_path, **change)
    code = main(["frf", "--model", str(tmp_path / "m.npz"), "--elements", str(tmp_path / "e.toml"),
                 "--omega", "0.6", "2.0", "--json"])
    cap = capsys.readouterr()
    assert code == 2 and no_result(cap.out, cap.err, 2)
    assert words in cap.err and len(cap.err.splitlines()) == 1


def test_a_positive_semi_definite_damping_passes_the_structure_check():
    """C of rank one (a single dashpot) and K singular (a free body held by its elements): a structure."""
    from harmonic_balance.model import check_scales

    K = np.array([[1.0, -1.0], [-1.0, 1.0]])
    check_scales(np.eye(2), K, 0.01 * K)


@pytest.mark.parametrize("slip_force, bounded", [(0.01, False), (0.05, True)])
def test_an_undamped_resonance_that_friction_cannot_bound_is_a_failure_not_a_peak(capsys, slip_force, bounded):
    """No viscous damping: a Jenkins link bounds the resonance at omega = 1 rad/s only when its
    dissipation per cycle 4 fs a outgrows the excitation's work pi P a (Den Hartog), fs > pi P / 4
    = 0.039 N here. The unbounded one printed a peak of 1.4e5 m as a complete curve."""
    argv = [a for a in SDOF]
    argv[argv.index("--damping") + 1] = "0"
    argv[argv.index("--slip-force") + 1] = str(slip_force)
    assert (slip_force > np.pi * 0.05 / 4) == bounded
    code, out = run_json(capsys, argv + ["--harmonics", "3", "--omega", "0.9", "1.6", "--json"])
    assert code == (0 if bounded else 3)
    assert ("grow without bound" in out["status"]) != bounded


def test_a_peak_at_a_jumped_stretch_is_an_error_and_one_away_from_it_is_not():
    """The rule the CLI and the scene's frf stage share (harmonic_balance.frf.check_peak_traced):
    a peak within a gap's width of a stretch the continuation jumped is not a result."""
    from types import SimpleNamespace

    from harmonic_balance.frf import FRFError, check_peak_traced

    gap = (1.0, 1.1)
    for peak, raises in ((1.05, True), (1.19, True), (0.91, True), (1.25, False), (0.8, False)):
        result = SimpleNamespace(peak_omega=peak, extra={"gaps": [gap]}, status="complete")
        if raises:
            with pytest.raises(FRFError, match="grow without bound") as e:
                check_peak_traced(result)
            assert e.value.hint and "grow without bound" in result.status
        else:
            check_peak_traced(result)
            assert result.status == "complete"
    check_peak_traced(SimpleNamespace(peak_omega=1.05, extra={}, status="complete"))   # no gaps
