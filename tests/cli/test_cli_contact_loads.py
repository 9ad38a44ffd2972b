"""Contact loads the mesh cannot represent are refused before any work with the bound, and
an approach-controlled sphere gets a zone sized for its contact, as a force-controlled one
does (Hertz as the independent reference)."""
import json
import re

import pytest

from contact_core import bodies, hertz
from contact_core.bodies import MAX_CONTACT_STRAIN
from damper.cli import main as damper

R = 0.01
ESTAR = hertz.contact_modulus(200e9, 0.3, 200e9, 0.3)
SPHERE = ["normal", "--body", "sphere", "--radius", str(R), "--grid", "5", "--model", "halfspace", "--no-cache"]
FLAT = ["normal", "--body", "flat", "--width", "1.2e-3", "--length", "5e-3", "--grid", "5", "--no-cache"]
#: The stated bounds are printed to 3-4 digits.
PRINTED = 1e-3
#: The halfspace solution on 5 nodes per side against Hertz, for a contact sized by its
#: own load: measured 6.7 % (force at an approach of 1e-12 m on R = 10 mm; 0.9 % on 11
#: nodes), against a factor 270 with the design pressure's zone.
COARSE_GRID = 0.1


def _refused(argv, capsys) -> str:
    assert damper(argv) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    return err


def test_sphere_force_below_the_resolved_contact_is_refused_with_the_smallest_force(capsys):
    err = _refused([*SPHERE, "--force", "1e-300"], capsys)
    f_min = float(re.search(r"at least ([0-9.e+-]+) N", err).group(1))
    assert hertz.sphere(f_min, R, ESTAR)["a"] == pytest.approx(bodies.MIN_CONTACT_SHARE * R, rel=PRINTED)


@pytest.mark.parametrize("approach", ["5e-324", "1e-14", "1"])
def test_sphere_approach_outside_the_contact_model_is_refused_with_the_range(approach, capsys):
    err = _refused([*SPHERE, "--approach", approach], capsys)
    lo, hi = (float(v) for v in re.search(r"approach in \[([0-9.e+-]+), ([0-9.e+-]+)\] m", err).groups())
    assert lo == pytest.approx((bodies.MIN_CONTACT_SHARE * R) ** 2 / R, rel=PRINTED)   # d = a^2 / R
    assert hi == pytest.approx((bodies.MAX_CONTACT_SHARE * R) ** 2 / R, rel=PRINTED)


def test_tiny_sphere_approach_gives_the_hertz_force(capsys):
    """At 1e-12 m the design pressure's zone held the contact in one node: the force came
    out 270 times Hertz's; the zone is now sized from the approach's Hertz contact."""
    assert damper([*SPHERE, "--approach", "1e-12", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    a = (R * 1e-12) ** 0.5
    f_hertz = 4.0 * ESTAR * a**3 / (3.0 * R)
    assert out["force"] == pytest.approx(f_hertz, rel=COARSE_GRID)


def test_cylinder_approach_below_round_off_is_refused(capsys):
    _refused(["normal", "--body", "cylinder", "--radius", "2.5e-3", "--length", "1.2e-3", "--grid", "5",
              "--no-cache", "--approach", "5e-324"], capsys)


@pytest.mark.parametrize("load", [["--approach", "1"], ["--force", "1e12"]])
def test_flat_face_load_beyond_small_strain_is_refused_with_the_bound(load, capsys):
    err = _refused([*FLAT, *load], capsys)
    assert f"{MAX_CONTACT_STRAIN:g}" in err and "give at most" in err


@pytest.mark.parametrize("load", [["--approach", "5e-324"], ["--force", "1e-300"]])
def test_flat_face_load_below_double_precision_is_refused_with_the_bound(load, capsys):
    """5e-324 m gave a force 1.9 times k_n times the approach (subnormal numbers)."""
    from contact_core.bodies import MIN_CONTACT_STRAIN

    err = _refused([*FLAT, *load], capsys)
    assert f"{MIN_CONTACT_STRAIN:g}" in err and "give at least" in err


#: Gross-slip displacement of the bem model on 11 nodes against Mindlin's closed form
#: (3 mu N / (16 G* a)): measured 0.1 %.
MINDLIN_BEM11 = 0.02


def test_loop_amplitude_far_beyond_gross_slip_is_refused_with_the_bound(capsys):
    """1e300 m marched for ever (the loop's points grow as the amplitude)."""
    from damper.limits import MAX_LOOP_SLIPS

    err = _refused(["tangential", "--body", "sphere", "--radius", str(R), "--force", "200", "--mu", "0.5",
                    "--model", "bem", "--grid", "11", "--no-cache", "--loop-amplitude", "1e300"], capsys)
    u_gross, bound = (float(v) for v in re.search(r"displacement ([0-9.e+-]+) m.*at most ([0-9.e+-]+) m",
                                                   err).groups())
    ref = bodies.Sphere().tangential_reference(_steel_sphere(), 200.0, 0.5)["mindlin"]["u_slip"]
    assert u_gross == pytest.approx(ref, rel=MINDLIN_BEM11)
    assert bound == pytest.approx(MAX_LOOP_SLIPS * u_gross, rel=PRINTED)


TANGENTIAL_BEM = ["tangential", "--body", "sphere", "--radius", str(R), "--force", "200", "--mu", "0.5",
                  "--model", "bem", "--grid", "11", "--no-cache"]
#: A loop far below the first slip of any node is the stuck line T = k_t u: round-off only.
STUCK_LINE = 1e-9


def test_loop_amplitude_below_the_solve_tolerance_is_refused_with_the_bound(capsys):
    """1e-18 m printed a force amplitude of exactly 0 N (the motion was below the solve's tolerance)."""
    from damper.limits import MIN_LOOP_SLIPS

    err = _refused([*TANGENTIAL_BEM, "--loop-amplitude", "1e-18"], capsys)
    u_gross, bound = (float(v) for v in re.search(r"displacement ([0-9.e+-]+) m.*at least ([0-9.e+-]+) m",
                                                   err).groups())
    assert bound == pytest.approx(MIN_LOOP_SLIPS * u_gross, rel=PRINTED)


def test_the_smallest_loop_amplitude_follows_the_stuck_line(capsys):
    from damper.limits import MIN_LOOP_SLIPS

    u_slip = bodies.Sphere().tangential_reference(_steel_sphere(), 200.0, 0.5)["mindlin"]["u_slip"]
    a = 1.1 * MIN_LOOP_SLIPS * u_slip  # u_slip of the bem model is within MINDLIN_BEM11 of Mindlin's
    assert damper([*TANGENTIAL_BEM, "--loop-amplitude", f"{a:.6g}", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["loop"]["T_amplitude"] == pytest.approx(out["k_t"] * float(f"{a:.6g}"), rel=STUCK_LINE)


def _steel_sphere():
    from contact_core.spec import ContactSpec

    return ContactSpec(body="sphere", radius=R, grid=11)


@pytest.mark.parametrize("geometry, words", [
    (["--body", "sphere", "--radius", "1e-300"], "radius = 1e-300 m is below the limit"),   # ZeroDivisionError
    (["--body", "cylinder", "--radius", "2.5e-3", "--length", "1e-300"], "length = 1e-300 m is below the limit"),
    (["--body", "sphere", "--radius", "0.01", "--E", "1e-300"], "E1 = 1e-300 Pa is below the limit"),
])
def test_a_size_or_modulus_below_any_contact_is_refused(geometry, words, capsys):
    assert words in _refused(["normal", *geometry, "--force", "100", "--grid", "5", "--no-cache"], capsys)
