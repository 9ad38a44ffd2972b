"""Scene files: the bundled examples validate; malformed scenes fail before any work,
naming the key and the file line, and write nothing."""
from pathlib import Path

import pytest

from damper.cli import main as damper
from damper.scene import SceneError, load_scene, parse_scene
from damper.scene.lines import key_lines

ROOT = Path(__file__).resolve().parents[2]
SMALL = (Path(__file__).parent / "small_scene.toml").read_text()


def test_example_scenes_validate():
    for path in sorted((ROOT / "examples" / "scenes").glob("*.toml")):
        scene = load_scene(path)
        assert scene.want and len(scene.hash()) == 16
    default = load_scene(ROOT / "examples" / "scenes" / "default.toml")
    assert default.data["contact"]["damper"]["radius"] == 2.5e-3          # from diameter
    assert default.data["contact"]["sphere"]["want"] == ["k_n", "pressure_map"]
    assert default.data["contact"]["damper"]["want"] == ["virgin_curve", "k_t"]
    assert load_scene(ROOT / "examples" / "scenes" / "kn_only.toml").data["contact"]["damper"]["want"] == ["k_n"]


def test_hash_ignores_comments_and_layout():
    a = parse_scene(SMALL)
    b = parse_scene("# a comment\n" + SMALL.replace("mu = 0.5", "mu   =   0.5   # friction"))
    assert a.hash() == b.hash()
    assert parse_scene(SMALL.replace("mu = 0.5", "mu = 0.6")).hash() != a.hash()


def _line(text: str, needle: str) -> int:
    return next(i for i, line in enumerate(text.splitlines(), start=1) if needle in line)


@pytest.mark.parametrize("edit, key, line_of, words", [
    (("mu = 0.5", "mu = 0.5\nfriction = 0.3"), "contact.damper.friction", "friction = 0.3", "unknown key"),
    (("grid = 7", 'grid = "fine"'), "contact.damper.grid", 'grid = "fine"', "must be an integer"),
    (("grid = 7", "grid = 7.5"), "contact.damper.grid", "grid = 7.5", "must be an integer"),
    (("diameter = 5.0e-3\n", ""), "contact.damper.radius", "[contact.damper]", "needs 'radius' or 'diameter'"),
    (("mu = 0.5\n", ""), "contact.damper.mu", "[contact.damper]", "needed for virgin_curve"),
    (("[structure]", "[structure_x]"), "structure_x", "[structure_x]", "unknown key"),
    (("zeta = 0.002", "zeta = -0.1"), "structure.zeta", "zeta = -0.1", "must be >= 0"),
    (('"report"]', '"report", "k_x"]'), "want", "want =", "unknown result 'k_x'"),
    (('contact = "damper"', 'contact = "other"'), "element.contact", 'contact = "other"', "no contact named"),
    (("f_max = 1300.0", "f_max = 800.0"), "sweep.f_max", "f_max = 800.0", "must be > f_min"),
    (("forces = [30.0]", "forces = [30.0, -1]"), "excitation.forces", "forces =", "item 1: must be > 0"),
    (("f_max = 1300.0", "f_max = 1300.0\naccuracy = 0.6"), "sweep.accuracy", "accuracy = 0.6", "must be < 0.5"),
    # a contact's name is a folder of the results: "../" in it wrote outside the output folder
    (("[contact.damper]", '[contact."../../../x"]'), "contact.../../../x", '[contact."../../../x"]',
     "use 1 to 64 letters, digits"),
    (("[contact.damper]", '[contact."a.b"]'), "contact.a.b", '[contact."a.b"]', "use 1 to 64 letters, digits"),
])
def test_malformed_scene_names_key_and_line(edit, key, line_of, words):
    text = SMALL.replace(*edit)
    assert text != SMALL
    with pytest.raises(SceneError) as err:
        parse_scene(text, "bad.toml")
    msg = str(err.value)
    assert f"bad.toml:{_line(text, line_of)}: {key}: " in msg, msg
    assert words in msg, msg


def test_wanted_result_without_its_input():
    text = "\n".join(line for line in SMALL.splitlines()
                     if not line.startswith(("[structure]", "m_", "k_", "zeta")))
    with pytest.raises(SceneError, match=r"structure: missing: needed for frf"):
        parse_scene(text, "bad.toml")


def test_not_toml_names_the_line():
    with pytest.raises(SceneError, match=r"line 3"):
        parse_scene('want = ["k_n"]\n[contact.a]\nbody = \n', "bad.toml")


def test_cli_refuses_a_bad_scene_before_any_work(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(SMALL.replace("grid = 7", "grid = 7\nmesh = 3"))
    out = tmp_path / "out"
    cache = tmp_path / "cache"
    assert damper(["run", str(bad), "--out", str(out), "--cache-dir", str(cache)]) == 2
    err = capsys.readouterr().err
    assert f"{bad}:{_line(bad.read_text(), 'mesh = 3')}: contact.damper.mesh: unknown key" in err
    assert "Traceback" not in err
    assert not out.exists() and not cache.exists()      # nothing written, nothing computed
    assert damper(["run", str(tmp_path / "missing.toml"), "--json"]) == 2


def test_key_lines_of_nested_tables_and_multiline_arrays():
    text = 'want = [\n  "k_n",\n]\n[contact.a]\nbody = "sphere"\n\n[contact.b]\n"force" = 3\n'
    lines = key_lines(text)
    assert lines[("want",)] == 1 and lines[("contact", "a", "body")] == 5
    assert lines[("contact", "b")] == 7 and lines[("contact", "b", "force")] == 8


def test_overrides_are_checked_like_the_file():
    s = parse_scene(SMALL, overrides={"contact.damper.mu": 0.4})
    assert s.data["contact"]["damper"]["mu"] == 0.4
    with pytest.raises(SceneError, match="element.loop_force_amplitude: 40 N is not below the gross-slip force"):
        parse_scene(SMALL, overrides={"contact.damper.mu": 0.3})      # mu N = 36 N
    with pytest.raises(SceneError, match="contact.damper.mu: must be a number"):
        parse_scene(SMALL, overrides={"contact.damper.mu": "high"})
    with pytest.raises(SceneError, match="not a scene parameter"):
        parse_scene(SMALL, overrides={"contact.damper.colour": 1})


def test_an_under_resolved_normal_contact_is_flagged_in_the_scene_lines(tmp_path):
    """A cylinder's contact across fewer than MIN_NODES_ACROSS grid spacings (1e-12 N: the FE
    half-width is the grid's, orders above 2D Hertz) prints the warning the CLI prints."""
    from contact_core.bodies import MIN_NODES_ACROSS
    from damper.cache import Store
    from damper.run.runner import run_scene

    text = ('want = ["k_n"]\n[contact.damper]\nbody = "cylinder"\ndiameter = 5.0e-3\nlength = 1.2e-3\n'
            "force = 1e-12\ngrid = 7\n")
    rec = run_scene(parse_scene(text), Store(tmp_path / "cache"), tmp_path / "out", echo=lambda text: None)
    stage = rec.plan["normal:damper"]
    result = rec.results["normal:damper"]
    assert result.data["under_resolved"]
    lines = stage.kind.lines(stage, result)
    assert any(f"under-resolved: the contact spans fewer than {MIN_NODES_ACROSS}" in ln for ln in lines)
