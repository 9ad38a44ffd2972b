"""Loads outside what a mesh represents: refused with the limit, or flagged in the text output."""
import re

import pytest

from contact_core import bodies, hertz
from contact_core import spec as spec_module
from contact_core.spec import ContactSpec
from damper.cli import main as damper


@pytest.mark.parametrize("args", [["--radius", "0.01", "--force", "1e6"],
                                  ["--radius", "1e-5", "--force", "200"]])
def test_sphere_load_beyond_the_body_is_refused_with_the_limit(args, capsys):
    assert damper(["normal", "--body", "sphere", "--grid", "5", "--no-cache", *args]) == 2
    err = capsys.readouterr().err
    assert "beyond what the contact model represents" in err and "Traceback" not in err
    f_max = float(re.search(r"use a force of at most ([0-9.e+-]+) N for this sphere", err).group(1))
    R = float(args[1])
    a = hertz.sphere(f_max, R, hertz.contact_modulus(200e9, 0.3, 200e9, 0.3))["a"]
    assert a == pytest.approx(bodies.MAX_CONTACT_SHARE * R, rel=1e-3)  # the limit is the stated share


def test_the_largest_finite_force_names_a_finite_contact_radius(capsys):
    """a^3 = 3 F R / (4 E*) overflows at F = 1e308: the message still names a number."""
    assert damper(["normal", "--body", "sphere", "--radius", "0.01", "--force", "1e308",
                   "--grid", "5", "--no-cache"]) == 2
    err = capsys.readouterr().err
    assert "beyond what the contact model represents" in err and "inf" not in err
    a = float(re.search(r"contact radius of ([0-9.e+-]+) m", err).group(1))
    R, Es = 0.01, hertz.contact_modulus(200e9, 0.3, 200e9, 0.3)
    assert a == pytest.approx((0.75 * R / Es) ** (1 / 3) * 1e308 ** (1 / 3), rel=0.05)  # 2 digits printed


@pytest.mark.parametrize("argv, words", [
    (["--body", "sphere", "--radius", "1e308"], "radius = 1e+308 m is above the limit"),   # Hertz overflowed
    (["--body", "cylinder", "--radius", "2.5e-3", "--length", "1e308"], "length = 1e+308 m is above"),
    (["--body", "flat", "--width", "1e308", "--length", "5e-3"], "width = 1e+308 m is above"),
    (["--body", "sphere", "--radius", "0.01", "--E", "1e308"], "E1 = 1e+308 Pa is above the limit"),
])
def test_a_size_or_modulus_beyond_any_contact_is_refused(argv, words, capsys):
    assert damper(["normal", *argv, "--force", "200", "--grid", "5", "--no-cache"]) == 2
    err = capsys.readouterr().err
    assert words in err and len(err.splitlines()) == 1


def test_the_largest_size_and_modulus_are_accepted():
    ContactSpec(body="sphere", radius=bodies.MAX_SIZE, E1=spec_module.MAX_MODULUS, grid=5)


def test_cylinder_load_beyond_the_body_is_refused():
    with pytest.raises(ValueError, match="at most .* N for this cylinder"):
        ContactSpec(body="cylinder", radius=2.5e-3, length=1.2e-3, load_hint=1e5)


def test_load_at_the_limit_meshes():
    """The largest accepted load still gives a valid mesh of the real half-sphere."""
    from contact_core import assembly, mesh

    R = 0.01
    Es = hertz.contact_modulus(200e9, 0.3, 200e9, 0.3)
    F = 4 * Es * (bodies.MAX_CONTACT_SHARE * R) ** 3 / (3 * R)
    b1, _, _ = mesh.build(ContactSpec(body="sphere", radius=R, grid=7, load_hint=F))
    assert assembly.stiffness(b1.p, b1.t, 200e9, 0.3).shape[0] == 3 * b1.p.shape[1]


def test_under_resolved_contact_is_flagged_in_the_text_output(capsys):
    """An explicit design pressure far too high for the load: the warning is printed."""
    assert damper(["normal", "--body", "sphere", "--radius", "0.01", "--force", "1e-6", "--grid", "5",
                   "--model", "halfspace", "--no-cache", "--p-design", "2e9"]) == 0
    assert "warning: under-resolved" in capsys.readouterr().out


#: A 1e-6 N load on the 10 mm sphere, zone sized from the Hertz contact of 3x
#: the load, 13 nodes per side: contact radius -0.78 % against Hertz (measured;
#: 45x Hertz with the design-pressure zone).
TINY_LOAD_RTOL = 0.012


@pytest.mark.slow  # > 2 s: outside the `-m "not slow"` inner loop
def test_default_zone_follows_a_tiny_load(capsys):
    import json

    assert damper(["normal", "--body", "sphere", "--radius", "0.01", "--force", "1e-6", "--grid", "13",
                   "--model", "halfspace", "--no-cache", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert not out["under_resolved"]
    assert abs(out["hertz"]["error_size"]) < TINY_LOAD_RTOL


#: Sphere of 10 mm at 100 N, halfspace model, grid 9, nu = MAX_FE_NU on both bodies:
#: approach -3.0 % against Hertz (measured; -1.3 % at nu 0.3, -64 % at nu 0.4999 where
#: the hexahedra lock). The bound must keep the locking error at the mesh error's size.
LOCKING_RTOL = 0.05


def test_fe_bodies_refuse_a_poisson_ratio_where_hexahedra_lock():
    from contact_core import condense

    spec = ContactSpec(body="sphere", radius=0.01, model="halfspace", grid=5, nu2=condense.MAX_FE_NU + 0.01)
    with pytest.raises(ValueError, match="hexahedra lock"):
        condense.condense(spec, cache=False)


def test_the_largest_fe_poisson_ratio_keeps_the_approach_near_hertz():
    from contact_core import api, condense

    nu = condense.MAX_FE_NU
    spec = ContactSpec(body="sphere", radius=0.01, model="halfspace", grid=9, nu1=nu, nu2=nu, load_hint=100.0)
    sol = api.solve(condense.condense(spec, cache=False), force=100.0)
    ref = hertz.sphere(100.0, 0.01, hertz.contact_modulus(200e9, nu, 200e9, nu))
    assert sol.q[0] == pytest.approx(ref["approach"], rel=LOCKING_RTOL)


def test_a_design_pressure_too_high_for_soft_materials_names_the_largest_accepted(capsys):
    """A plane 1e6 times softer than the steel sphere: the default 2000 MPa zone is 164 m wide."""
    assert damper(["normal", "--body", "sphere", "--radius", "0.01", "--E2", "2e5", "--force", "0.05",
                   "--grid", "5", "--no-cache"]) == 2
    err = capsys.readouterr().err
    p_max = float(re.search(r"--p-design of at most ([0-9.e+-]+) Pa", err).group(1))
    spec = ContactSpec(body="sphere", radius=0.01, E2=2e5, grid=5, p_design=p_max)
    assert spec.zone()[0] / spec.zone_margin == pytest.approx(bodies.MAX_CONTACT_SHARE * 0.01, rel=1e-2)


@pytest.mark.parametrize("force, words", [(1e9, "give at most"), (1e-300, "give at least")])
def test_a_scene_flat_face_load_outside_the_strain_bounds_is_refused_at_its_key(force, words):
    """The bound is the library's (FlatFace.check_load), so a scene meets it as the CLI does:
    before, a scene's 1e9 N on a 1.2 mm face printed an approach of 6 m as a result."""
    from damper.scene import SceneError, parse_scene

    text = (f'want = ["k_n"]\n[contact.damper]\nbody = "flat"\nwidth = 1.2e-3\nlength = 1.2e-3\n'
            f"force = {force!r}\ngrid = 7\n")
    with pytest.raises(SceneError) as info:
        parse_scene(text, "flat.toml")
    msg = str(info.value)
    assert "flat.toml:2: contact.damper: a force of" in msg and words in msg
    spec = ContactSpec(body="flat", width=1.2e-3, length=1.2e-3)
    bound = float(re.search(r"give at (?:most|least) ([0-9.e+-]+) N", msg).group(1))
    strain = bodies.MAX_CONTACT_STRAIN if force > 1 else bodies.MIN_CONTACT_STRAIN
    assert bound == pytest.approx(strain * spec.Estar * 1.2e-3 ** 2, rel=1e-3)  # 4 digits printed
