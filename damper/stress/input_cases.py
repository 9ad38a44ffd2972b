"""The input stage's cases: bad inputs over every subcommand and file type, and the cache's duties.

A case is a ``damper`` command line (``{fx}``: the fixtures folder of
:mod:`.input_fixtures`) run in a folder of its own whose cache is ``.damper_cache``
there, and the outcome it must have:

* ``clear_error`` (most cases): exit code 2 or 3, no traceback, the last line of
  standard error the command's one-line message, no warning printed twice, and no
  file created, changed or removed (in the case's folder, its cache, the fixtures);
* ``converged``: exit code 0 and the case's ``check`` (e.g. a user's file in the cache
  folder untouched, exactly one warning for a corrupt entry);
* ``interrupted``: SIGINT once the text ``interrupt_on`` shows on standard error: exit
  code 130, one line saying where, no output folder.

``files`` are created in the case's folder first (a user's folder next to the cache),
``pre`` commands run before (they must succeed) and ``mutate`` then edits the folder
(truncate or swap cache entries).
"""
from __future__ import annotations

import shlex
from dataclasses import dataclass, field

SDOF = "--model sdof --mass 1 --stiffness 1 --damping 0.01 --contact-stiffness 1 --slip-force 0.05 --force 0.05"
SPHERE = "--body sphere --radius 0.01"
NPZ = "--model {fx}/m_good.npz --elements {fx}/el_good.toml"
KN_SMALL = "normal --body sphere --radius 0.01 --model halfspace --force 100 --grid 5 --json"


@dataclass
class InputCase:
    """One command and the outcome it must have (module docstring)."""

    group: str
    name: str
    argv: list[str]
    expect: str = "clear_error"
    files: dict = field(default_factory=dict)
    pre: list = field(default_factory=list)
    mutate: str | None = None
    keep: tuple = ()
    check: str | None = None
    interrupt_on: str | None = None
    timeout: float = 30.0


def _case(group: str, name: str, cmd: str, **kw) -> InputCase:
    return InputCase(group, name, shlex.split(cmd), **kw)


def _table(group: str, rows: list[tuple[str, str]], prefix: str = "") -> list[InputCase]:
    return [_case(group, name, f"{prefix} {cmd}".strip()) for name, cmd in rows]


def _cli() -> list[InputCase]:
    return _table("cli", [
        ("no subcommand", ""), ("unknown subcommand", "frobnicate"), ("frf without options", "frf"),
        ("run without a scene", "run"), ("unknown option", "loop --curve {fx}/curve.json --amplitude 1e-6 --wobble"),
        ("an integer option given 1.5", "upd mistuning --seed 1.5"),
        ("a negative number as a value", "fmu --curve {fx}/curve.json -o d.fmu --k-n -5e7"),
        ("an unknown option of a subcommand without arguments", "bench --no-such-option"),
    ]) + [_case("cli", "--version", "--version", expect="converged", check="version")]


def _normal() -> list[InputCase]:
    return _table("normal", [
        ("force -1", f"{SPHERE} --force -1"), ("force 0", f"{SPHERE} --force 0"),
        ("force nan", f"{SPHERE} --force nan"), ("force inf", f"{SPHERE} --force inf"),
        ("approach -1e-6", f"{SPHERE} --approach=-1e-6"), ("force and approach", f"{SPHERE} --force 1 --approach 1e-6"),
        ("radius 0", "--body sphere --radius 0 --force 100"),
        ("radius 1e308", "--body sphere --radius 1e308 --force 200"), ("E 1e308", f"{SPHERE} --force 200 --E 1e308"),
        ("radius -0.01", "--body sphere --radius=-0.01 --force 1"),
        ("sphere without radius", "--body sphere --force 100"),
        ("radius and diameter", "--body sphere --radius 0.01 --diameter 0.02 --force 100"),
        ("E negative", f"{SPHERE} --force 100 --E=-2e11"), ("nu 0.5", f"{SPHERE} --force 100 --nu 0.5"),
        ("nu -1.5", f"{SPHERE} --force 100 --nu=-1.5"),
        ("nu2 0.49 (the FE hexahedra lock)", f"{SPHERE} --force 100 --nu2 0.49 --grid 5 --json"),
        ("grid 2", f"{SPHERE} --force 100 --grid 2"),
        ("grid 100000", f"{SPHERE} --force 100 --grid 100000"),
        ("grid 1e3 (not an integer)", f"{SPHERE} --force 1 --grid 1e3"),
        ("force 1e12 (Hertz radius > R)", f"{SPHERE} --force 1e12"),
        ("eccentricity on a sphere", f"{SPHERE} --force 100 --eccentricity 1e-4"),
        ("force 1e-300 (Hertz radius below round-off)", f"{SPHERE} --force 1e-300 --grid 5"),
        ("approach 5e-324", f"{SPHERE} --approach 5e-324 --grid 5"),
        ("approach 1 (Hertz radius > R)", f"{SPHERE} --approach 1 --grid 5"),
        ("cylinder approach 5e-324", "--body cylinder --radius 2.5e-3 --length 1.2e-3 --approach 5e-324 --grid 5"),
        ("flat approach 1", "--body flat --width 1.2e-3 --length 5e-3 --approach 1 --grid 5"),
        ("flat force 1e12", "--body flat --width 1.2e-3 --length 5e-3 --force 1e12 --grid 5"),
        ("flat approach 5e-324 (a subnormal force)", "--body flat --width 1.2e-3 --length 5e-3 --approach 5e-324"),
        ("radius 1e-300 (divided by zero)", "--body sphere --radius 1e-300 --force 100 --grid 5"),
        ("cylinder length 1e-300", "--body cylinder --radius 2.5e-3 --length 1e-300 --force 100 --grid 5"),
        ("flat height 0 (not the default height)",
         "--body flat --width 1.2e-3 --length 5e-3 --force 100 --grid 5 --height 0 --json"),
        ("flat height 1e-300", "--body flat --width 1.2e-3 --length 5e-3 --force 100 --grid 5 --height 1e-300"),
        ("E2 2e5 against a steel sphere (the default design zone 164 m wide)",
         f"{SPHERE} --force 0.05 --grid 5 --E2 2e5 --json"),
        ("E 1e-300 (an infinite contact radius)", f"{SPHERE} --force 100 --grid 5 --E 1e-300"),
        ("eccentricity with approach", "--body flat --width 1.2e-3 --length 5e-3 --approach 1e-6 --eccentricity 1e-4"),
        ("eccentricity off the face", "--body flat --width 1.2e-3 --length 5e-3 --force 100 --eccentricity 1e-3"),
        ("curve 1e6 points", f"{SPHERE} --force 100 --curve 1000000"), ("curve -1", f"{SPHERE} --force 100 --curve=-1"),
        ("curve 1 (a normal curve to 5 % of the load)",
         f"{SPHERE} --force 100 --grid 5 --curve 1 --normal-curve n.json"),
        ("length on a sphere", f"{SPHERE} --force 100 --length 1e-3"),
        ("cylinder without length", "--body cylinder --radius 2.5e-3 --force 100"),
        ("p-design 0", f"{SPHERE} --force 100 --p-design 0"), ("body cube", "--body cube --radius 0.01 --force 1"),
        ("--out an existing folder", f"{SPHERE} --force 100 --out {{fx}}"),
        ("--out ending in / (a folder; the file was written as res)", f"{SPHERE} --force 100 --grid 5 --out res/"),
        ("--out below a file", f"{SPHERE} --force 100 --out {{fx}}/a_file/r.json"),
        ("--plot a file", f"{SPHERE} --force 100 --plot {{fx}}/a_file"),
        ("--normal-curve an existing folder", f"{SPHERE} --force 100 --normal-curve {{fx}}"),
        ("--cache-dir a file", f"{SPHERE} --force 100 --cache-dir {{fx}}/a_file"),
        ("stiffness without nodes", "--body sphere --force 100 --stiffness {fx}/m_good.npz {fx}/m_good.npz"),
        ("stiffness with radius", f"{SPHERE} --force 100 --stiffness {{fx}}/m_good.npz {{fx}}/m_good.npz "
                                  "--nodes {fx}/m_good.npz {fx}/m_good.npz"),
        ("imported flat blocks (a flat punch: contact over every node)", "--body sphere --force 100 --no-cache "
         "--stiffness {fx}/byo_K1.npz {fx}/byo_K2.npz --nodes {fx}/byo_n1.npz {fx}/byo_n2.npz"),
        ("stiffness files not matrices", "--body sphere --force 100 --stiffness {fx}/binary.bin {fx}/binary.bin "
                                         "--nodes {fx}/binary.bin {fx}/binary.bin"),
    ], "normal") + [_case("normal", "--cache-dir a folder of the user's",
                          f"normal {SPHERE} --force 100 --model halfspace --grid 5 --cache-dir proj",
                          files={"proj/matrices.npz": "user data\n"})]


def _tangential() -> list[InputCase]:
    base = f"tangential {SPHERE} --force 200 --model bem --grid 11"
    return _table("tangential", [
        ("mu 0", f"{base} --mu 0"), ("mu -0.5", f"{base} --mu=-0.5"), ("mu nan", f"{base} --mu nan"),
        ("mu 1e300", f"{base} --mu 1e300"), ("mu 101", f"{base} --mu 101"), ("mu missing", base),
        ("tol 0", f"{base} --mu 0.5 --tol 0"), ("tol 1e-12", f"{base} --mu 0.5 --tol 1e-12"),
        ("tol 0.6", f"{base} --mu 0.5 --tol 0.6"),
        ("tangential force above mu N", f"{base} --mu 0.5 --tangential-force 150"),
        ("loop amplitude -1", f"{base} --mu 0.5 --loop-amplitude=-1"),
        ("loop amplitude nan", f"{base} --mu 0.5 --loop-amplitude nan"),
        ("loop amplitude 1e300 (hung)", f"{base} --mu 0.5 --loop-amplitude 1e300"),
        ("loop amplitude 1e-18 (below the solve's tolerance: T 0 N)",
         f"{base} --mu 0.5 --loop-amplitude 1e-18 --json"),
        ("flat, approach, eccentricity", "tangential --body flat --width 1.2e-3 --length 5e-3 --approach 1e-6 "
                                         "--mu 0.5 --eccentricity 1e-4"),
        ("eccentricity on a sphere", f"{base} --mu 0.5 --eccentricity 1e-4"),
        ("--out an existing folder", f"{base} --mu 0.5 --out {{fx}}"),
        ("--out below a file", f"{base} --mu 0.5 --out {{fx}}/a_file/c.json"),
        ("--plot a file", f"{base} --mu 0.5 --plot {{fx}}/a_file"), ("model fem", f"{base} --mu 0.5 --model fem"),
        ("force 0", f"tangential {SPHERE} --force 0 --mu 0.5"),
        ("grid 100000", f"tangential {SPHERE} --force 200 --mu 0.5 --grid 100000"),
        ("width on a sphere", f"{base} --mu 0.5 --width 1e-3"),
        ("approach 1 (Hertz radius > R)", f"tangential {SPHERE} --approach 1 --mu 0.5 --model bem --grid 11"),
    ])


def _loop() -> list[InputCase]:
    a = "--amplitude 2e-6"
    rows = [(f"curve {kind}", f"--curve {{fx}}/curve_{kind}.json {a}") for kind in
            ("binary", "trunc", "empty", "list", "nan", "decreasing", "convex", "one", "negT", "dip", "steep")]
    return _table("loop", rows + [
        ("curve missing", f"--curve {{fx}}/nowhere.json {a}"), ("curve is a folder", f"--curve {{fx}} {a}"),
        ("amplitude 1e10", "--curve {fx}/curve.json --amplitude 1e10"),
        ("amplitude 1e30", "--curve {fx}/curve.json --amplitude 1e30"),
        ("amplitude 0", "--curve {fx}/curve.json --amplitude 0"),
        ("amplitude -1", "--curve {fx}/curve.json --amplitude=-1"),
        ("amplitude nan", "--curve {fx}/curve.json --amplitude nan"),
        ("amplitude inf", "--curve {fx}/curve.json --amplitude inf"),
        ("force amplitude = mu N", "--curve {fx}/curve.json --force-amplitude 100"),
        ("force amplitude 1e9", "--curve {fx}/curve.json --force-amplitude 1e9"),
        ("amplitude and force amplitude", f"--curve {{fx}}/curve.json {a} --force-amplitude 10"),
        ("no amplitude", "--curve {fx}/curve.json"),
        ("samples 1e9", f"--curve {{fx}}/curve.json {a} --samples 1000000000"),
        ("samples 3", f"--curve {{fx}}/curve.json {a} --samples 3"),
        ("N 0", f"--curve {{fx}}/curve.json {a} --N 0"), ("N nan", f"--curve {{fx}}/curve.json {a} --N nan"),
        ("N 1e300 and scale 1e300 (overflowed)", f"--curve {{fx}}/curve.json {a} --N 1e300 --scale 1e300"),
        ("N 1e-300", f"--curve {{fx}}/curve.json {a} --N 1e-300"),
        ("scale 1e300", f"--curve {{fx}}/curve.json {a} --scale 1e300"),
        ("scale 0", f"--curve {{fx}}/curve.json {a} --scale 0"),
        ("scale -1", f"--curve {{fx}}/curve.json {a} --scale=-1"),
        ("--plot a file", f"--curve {{fx}}/curve.json {a} --plot {{fx}}/a_file"),
        ("fit bogus", f"--curve {{fx}}/curve.json {a} --fit bogus"),
    ], "loop")


def _fmu() -> list[InputCase]:
    return _table("fmu", [
        ("curve binary", "--curve {fx}/curve_binary.json -o d.fmu"), ("curve missing", "--curve {fx}/no.json -o d.fmu"),
        ("curve convex", "--curve {fx}/curve_convex.json -o d.fmu"), ("no output", "--curve {fx}/curve.json"),
        *[(f"curve {kind}", f"--curve {{fx}}/curve_{kind}.json -o d.fmu --json")
          for kind in ("empty", "one", "nan", "dip", "decreasing", "steep")],
        ("-o an existing folder", "--curve {fx}/curve.json -o {fx}"),
        ("-o below a file", "--curve {fx}/curve.json -o {fx}/a_file/d.fmu"),
        ("n-ref 0", "--curve {fx}/curve.json -o d.fmu --n-ref 0"),
        ("n-ref nan", "--curve {fx}/curve.json -o d.fmu --n-ref nan"),
        ("fmi version 4", "--curve {fx}/curve.json -o d.fmu --fmi-version 4"),
        ("curve without N", "--curve {fx}/curve_noN.json -o d.fmu"),
        ("point: k-n 0", "--curve {fx}/curve.json -o d.fmu --k-n 0"),
        ("point: k-n nan", "--curve {fx}/curve.json -o d.fmu --k-n nan"),
        ("point: preload -1", "--curve {fx}/curve.json -o d.fmu --k-n 1e8 --preload=-1"),
        ("point: preload without a normal law", "--curve {fx}/curve.json -o d.fmu --preload 100"),
        ("point: normal curve binary", "--curve {fx}/curve.json -o d.fmu --normal {fx}/binary.bin"),
        ("point: normal curve missing", "--curve {fx}/curve.json -o d.fmu --normal {fx}/nowhere.json"),
        ("point: normal curve is a virgin curve", "--curve {fx}/curve.json -o d.fmu --normal {fx}/curve.json"),
        ("point: k-n and normal", "--curve {fx}/curve.json -o d.fmu --k-n 1e8 --normal {fx}/curve.json"),
        ("n-ref 1e-320", "--curve {fx}/curve.json -o d.fmu --n-ref 1e-320"),
        ("n-ref 1e308", "--curve {fx}/curve.json -o d.fmu --n-ref 1e308"),
        ("point: k-n 1e-300", "--curve {fx}/curve.json -o d.fmu --k-n 1e-300"),
        ("point: k-n -5e7", "--curve {fx}/curve.json -o d.fmu --k-n -5e7"),
        ("point: preload 1e12", "--curve {fx}/curve.json -o d.fmu --k-n 1e8 --preload 1e12"),
        ("point: preload beyond the normal curve",
         "--curve {fx}/curve.json -o d.fmu --normal {fx}/normal_120.json --preload 1e7"),
    ], "fmu")


def _frf() -> list[InputCase]:
    o = "--omega 0.9 1.3"
    rows = [
        ("omega 1 1e300", f"{SDOF} --harmonics 1 --omega 1 1e300"), ("omega 0 1", f"{SDOF} --omega 0 1"),
        ("omega -1 1", f"{SDOF} --omega -1 1"), ("omega 1 1", f"{SDOF} --omega 1 1"),
        ("omega nan 1", f"{SDOF} --omega nan 1"),
        ("omega 1e-300 1e-299", f"{SDOF} --omega 1e-300 1e-299"), ("harmonics 0", f"{SDOF} {o} --harmonics 0"),
        ("harmonics 100000", f"{SDOF} {o} --harmonics 100000"), ("harmonics odd:0", f"{SDOF} {o} --harmonics odd:0"),
        ("harmonics abc", f"{SDOF} {o} --harmonics abc"), ("harmonics even:3", f"{SDOF} {o} --harmonics even:3"),
        ("samples -1", f"{SDOF} {o} --samples=-1"), ("samples 1e8", f"{SDOF} {o} --samples 100000000"),
        ("samples 3 at H 7 (aliasing)", f"{SDOF} {o} --harmonics 7 --samples 3"),
        ("max-step 0", f"{SDOF} {o} --max-step 0"), ("max-step nan", f"{SDOF} {o} --max-step nan"),
        ("max-step 1e-300 (more points than --max-points)", f"{SDOF} {o} --max-step 1e-300"),
        ("max-points 1", f"{SDOF} {o} --max-points 1"), ("max-points 1e8", f"{SDOF} {o} --max-points 100000000"),
        ("mass 0", SDOF.replace("--mass 1", "--mass 0") + f" {o}"),
        ("mass nan", SDOF.replace("--mass 1", "--mass nan") + f" {o}"),
        ("damping -1", SDOF.replace("--damping 0.01", "--damping=-1") + f" {o}"),
        ("contact stiffness 0", SDOF.replace("--contact-stiffness 1", "--contact-stiffness 0") + f" {o}"),
        ("slip force -1", SDOF.replace("--slip-force 0.05", "--slip-force=-1") + f" {o}"),
        ("force 1e200", SDOF.replace("--force 0.05", "--force 1e200") + f" {o}"),
        ("stiffness 1e300", SDOF.replace("--stiffness 1", "--stiffness 1e300") + f" {o}"),
        ("damping 0, slip force 0 (an undamped linear resonance)",
         SDOF.replace("--damping 0.01", "--damping 0").replace("--slip-force 0.05", "--slip-force 0")
         + " --omega 0.9 1.6 --json"),
        ("damping 0, slip force 0.01 (friction cannot bound the resonance)",
         SDOF.replace("--damping 0.01", "--damping 0").replace("--slip-force 0.05", "--slip-force 0.01")
         + " --omega 0.9 1.6"),
        ("mass 1e-160 (natural frequency 1e80 rad/s)", SDOF.replace("--mass 1", "--mass 1e-160") + f" {o}"),
        ("sdof with --elements", f"{SDOF} {o} --elements {{fx}}/el_good.toml"),
        ("sdof with --force-scale", f"{SDOF} {o} --force-scale 2"),
        ("sdof response DOF 3", f"{SDOF} {o} --response-dof 3"),
        ("npz with --mass", f"{NPZ} --mass 5 --omega 100 300"),
        ("npz without --elements", "--model {fx}/m_good.npz --omega 100 300"),
        ("npz missing", "--model {fx}/nowhere.npz --elements {fx}/el_good.toml --omega 100 300"),
        ("model SDOF (not sdof, no such file)", "--model SDOF --omega 1 2 --json"),
        ("npz response DOF 99", f"{NPZ} --response-dof 99 --omega 100 300"),
        ("npz force-scale inf", f"{NPZ} --force-scale inf --omega 100 300"),
        ("--out an existing folder", f"{SDOF} {o} --out {{fx}}"),
        ("--out below a file", f"{SDOF} {o} --out {{fx}}/a_file/f.json"),
        ("--plot a file", f"{SDOF} {o} --plot {{fx}}/a_file"),
        ("accuracy 0", f"{SDOF} {o} --accuracy 0"), ("accuracy 0.5", f"{SDOF} {o} --accuracy 0.5"),
        ("accuracy 1e-7", f"{SDOF} {o} --accuracy 1e-7"), ("accuracy nan", f"{SDOF} {o} --accuracy nan"),
        ("accuracy -0.01", f"{SDOF} {o} --accuracy=-0.01"),
    ]
    for m in ("nan", "negM", "asym", "shape", "noforce", "forcelen", "cnan", "text", "empty", "nokeys", "trunc",
              "complex", "negC", "negK", "0x0", "Mhuge", "Mtiny"):
        rows.append((f"npz {m}", f"--model {{fx}}/m_{m}.npz --elements {{fx}}/el_good.toml --omega 100 300"))
    for e in ("wobble", "scael", "top", "badtoml", "binary", "none", "dof9", "nok", "type", "path", "negk",
              "dofstr", "same", "contact"):
        rows.append((f"elements {e}", f"--model {{fx}}/m_good.npz --elements {{fx}}/el_{e}.toml --omega 100 300"))
    return _table("frf", rows, "frf")


def _backbone() -> list[InputCase]:
    a = "--amplitude 1e-3 10"
    return _table("backbone", [
        ("amplitude 0 1", f"{SDOF} --amplitude 0 1"), ("amplitude 1 1", f"{SDOF} --amplitude 1 1"),
        ("amplitude nan", f"{SDOF} --amplitude nan 1"), ("harmonics 100000", f"{SDOF} {a} --harmonics 100000"),
        ("samples -1", f"{SDOF} {a} --samples=-1"), ("mode -1", f"{SDOF} {a} --mode=-1"),
        ("mode 5 of one DOF", f"{SDOF} {a} --mode 5"),
        ("accuracy 0.5", f"{SDOF} {a} --accuracy 0.5"), ("accuracy 1e-7", f"{SDOF} {a} --accuracy 1e-7"),
        ("npz M = -I", "--model {fx}/m_negM.npz --elements {fx}/el_good.toml " + a),
        ("npz C negative definite", "--model {fx}/m_negC.npz --elements {fx}/el_good.toml " + a),
        ("--out an existing folder", f"{SDOF} {a} --out {{fx}}"),
        ("sdof with --elements", f"{SDOF} {a} --elements {{fx}}/el_good.toml"),
        ("npz complex K", "--model {fx}/m_complex.npz --elements {fx}/el_good.toml " + a),
        ("amplitude 1e-3 1e300 (NaN in the element)", f"{SDOF} --amplitude 1e-3 1e300"),
        ("amplitude 1e-3 1e-300 (decreasing)", f"{SDOF} --amplitude 1e-3 1e-300"),
    ], "backbone")


def _upd() -> list[InputCase]:
    return _table("upd", [
        ("frf harmonics 100000", "frf --harmonics 100000"), ("frf points 1e8", "frf --points 100000000"),
        ("frf harmonics 0", "frf --harmonics 0"), ("frf points 2", "frf --points 2"),
        ("frf band 0 100", "frf --band 0 100"), ("frf band 500 400", "frf --band 500 400"),
        ("frf band nan 1", "frf --band nan 1"),
        ("frf band 1e-300 1", "frf --band 1e-300 1"), ("frf band 1 1e300", "frf --band 1 1e300"),
        ("frf cf -1", "frf --cf=-1"), ("frf f0 nan", "frf --f0 nan"),
        ("frf cf 1e300 (overflowed: exit 3)", "frf --cf 1e300 --points 5"),
        ("frf geometry contacts at CF 1e-300", "frf --contacts geometry --cf 1e-300 --points 5"),
        ("frf f0 1e300 (overflowed: exit 3)", "frf --f0 1e300 --points 5"),
        ("frf f0 1e-160 (the energy per cycle underflowed: divided by zero)",
         "frf --f0 1e-160 --points 3 --harmonics 1 --json"),
        ("mistuning cf 1e-160 f0 1e-160 (underflowed)", "mistuning --cf 1e-160 --f0 1e-160 --samples 1"),
        ("frf --plot a file", "frf --plot {fx}/a_file"),
        ("frf accuracy 0.6", "frf --accuracy 0.6"), ("frf accuracy nan", "frf --accuracy nan"),
        ("frf surface nodes 3", "frf --contacts surface --surface-nodes 3"),
        ("frf surface nodes 1e6", "frf --contacts surface --surface-nodes 1000000"),
        ("frf surface with stuck limits", "frf --contacts surface --damper stuck"),
        ("frf surface with accuracy", "frf --contacts surface --accuracy 0.01"),
        ("frf surface with check-steady-state (point contacts only)", "frf --contacts surface --check-steady-state"),
        ("frf surface nodes without surface contacts", "frf --surface-nodes 7"),
        ("frf surface with an axial platform DOF (not planar)", "frf --contacts surface --config {fx}/upd_axial.toml"),
        ("frf surface cf 1e6 (a cylinder contact beyond Hertz)", "frf --contacts surface --cf 1e6 --json"),
        ("frf surface with mu 0 (no virgin curve to condense)", "frf --contacts surface --config {fx}/upd_mu0.toml"),
        ("frf surface nodes H 50 (its dense Jacobian was killed for memory)",
         "frf --contacts surface --surface-model nodes --harmonics 50"),
        ("frf surface nodes 41 (4048 nodes)",
         "frf --contacts surface --surface-model nodes --surface-nodes 41 --harmonics 1"),
        ("frf surface H 19 (8775 unknowns)", "frf --contacts surface --surface-model nodes --harmonics 19 --json"),
        ("frf surface model without surface contacts", "frf --surface-model nodes"),
        ("frf surface model with geometry contacts", "frf --contacts geometry --surface-model condensed --json"),
        ("frf surface model unknown", "frf --contacts surface --surface-model lumped"),
        ("frf cf 1e-3 (a damper without load)", "frf --cf 1e-3 --points 5"),
        ("optimize cf-range 1e-3 10 (a damper without load)", "optimize --cf-range 1e-3 10 --points 3"),
        ("mistuning cf 1e-3 (a damper without load)", "mistuning --cf 1e-3 --samples 1"),
        ("config missing", "modes --config {fx}/nowhere.toml"),
        ("config binary", "modes --config {fx}/upd_binary.toml"),
        ("config unknown key", "modes --config {fx}/upd_unknown.toml"),
        ("config bad TOML", "modes --config {fx}/upd_badtoml.toml"),
        ("config unknown section", "modes --config {fx}/upd_section.toml"),
        ("optimize cf-range 1 1e300 (overflowed: exit 3)", "optimize --cf-range 1 1e300 --points 3"),
        ("optimize cf-range 0 10", "optimize --cf-range 0 10"), ("optimize cf-range 10 1", "optimize --cf-range 10 1"),
        ("optimize points 1e6", "optimize --points 1000000"), ("optimize grid 1e6", "optimize --grid 1000000"),
        ("optimize harmonics 1000", "optimize --harmonics 1000"),
        ("optimize workers 0", "optimize --workers 0"), ("optimize workers 10000", "optimize --workers 10000"),
        ("optimize accuracy 0.5", "optimize --accuracy 0.5"),
        ("optimize accuracy 1e-7", "optimize --accuracy 1e-7"),
        ("no action", ""),
        ("mistuning std -0.01", "mistuning --std=-0.01"), ("mistuning std nan", "mistuning --std nan"),
        ("mistuning std 0.6", "mistuning --std 0.6 --samples 50"),
        ("mistuning std 0 until-ci (identical tuned samples)", "mistuning --std 0 --until-ci 0.01"),
        ("mistuning std 0 samples 3 (identical tuned samples)", "mistuning --std 0 --samples 3 --blades 4 "
         "--engine-order 1 --harmonics 1"),
        ("mistuning std 0 at the default samples", "mistuning --std 0"),
        ("mistuning samples 0", "mistuning --samples 0"), ("mistuning samples 1e5", "mistuning --samples 100000"),
        ("mistuning blades 1e5", "mistuning --blades 100000"),
        ("mistuning engine order -1 (named as a config key)", "mistuning --engine-order=-1 --damper free --serial"),
        ("mistuning blades 2 without an engine order (UPD-24's is 6)", "mistuning --blades 2 --serial"),
        ("mistuning factor -1", "mistuning --blades 4 --engine-order 1 --factors 1 -1 1 1"),
        ("mistuning factor nan", "mistuning --blades 4 --engine-order 1 --factors 1 nan 1 1"),
        ("mistuning 3 factors for 4 blades", "mistuning --blades 4 --engine-order 1 --factors 1 1 1"),
        ("mistuning factor 1e-300", "mistuning --blades 4 --engine-order 1 --factors 1 1e-300 1 1"),
        ("mistuning factor 1e308", "mistuning --blades 4 --engine-order 1 --factors 1 1e308 1 1"),
        ("mistuning frequency factor 3", "mistuning --blades 4 --engine-order 1 --kind frequency --factors 1 3 1 1"),
        ("mistuning uniform frequency std 0.5",
         "mistuning --kind frequency --distribution uniform --std 0.5 --samples 2"),
        ("mistuning unreachable scheduler", "mistuning --scheduler tcp://127.0.0.1:9 --samples 2"),
        ("mistuning scheduler '' (a silent local cluster)", "mistuning --scheduler '' --samples 2 --damper free"),
        ("mistuning workers and serial", "mistuning --workers 2 --serial"),
        ("mistuning --plot a file", "mistuning --plot {fx}/a_file"),
        ("mistuning --cache-dir a file (refused only after the samples)",
         "mistuning --damper free --samples 1 --serial --cache-dir {fx}/a_file"),
        ("mistuning until-ci 0", "mistuning --until-ci 0"), ("mistuning until-ci nan", "mistuning --until-ci nan"),
        ("mistuning until-ci inf", "mistuning --until-ci inf"),
        ("mistuning until-ci 1e300", "mistuning --until-ci 1e300"),
        ("mistuning until-ci -1", "mistuning --until-ci=-1"),
        ("mistuning until-ci with factors", "mistuning --blades 4 --engine-order 1 --factors 1 1 1 1 --until-ci 0.01"),
        ("mistuning solver bogus", "mistuning --solver bogus"),
        ("mistuning band cutting off the tuned peak (426 Hz)",
         "mistuning --damper free --band 380 424 --samples 2 --serial"),
        ("mistuning worst band cutting off the tuned peak (426 Hz)", "mistuning --worst --damper free --band 380 424"),
        ("mistuning worst max-evaluations 0", "mistuning --worst --std 0.02 --max-evaluations 0"),
        ("mistuning worst max-evaluations 1e4", "mistuning --worst --std 0.02 --max-evaluations 10000"),
        ("mistuning max-evaluations with a linear worst", "mistuning --worst --damper free --max-evaluations 5"),
        ("mistuning max-evaluations without worst", "mistuning --max-evaluations 5"),
        ("mistuning accuracy 0.6", "mistuning --accuracy 0.6"),
        ("mistuning accuracy 1e-7", "mistuning --accuracy 1e-7"),
        ("mistuning accuracy with a linear damper", "mistuning --damper free --accuracy 0.01"),
        ("mistuning worst bound 0.9", "mistuning --worst --damper free --bound 0.9"),
        ("mistuning worst bound nan", "mistuning --worst --damper free --bound nan"),
        ("mistuning bound without worst", "mistuning --bound 0.1"),
        ("mistuning worst with factors", "mistuning --worst --damper free --blades 4 --engine-order 1 "
         "--factors 1 1 1 1"),
        ("mistuning worst --out a folder", "mistuning --worst --damper free --out {fx}"),
        ("mistuning worst --out ending in / (a folder)", "mistuning --worst --damper free --out worst/"),
        # /proc: the write failed only after the search
        ("mistuning worst --out in a folder that takes no writes",
         "mistuning --worst --damper free --out /proc/damper_worst.json"),
        ("optimize surface with accuracy (fixed H)", "optimize --contacts surface --accuracy 0.01"),
        ("optimize surface with grid (Brent's peak search)", "optimize --contacts surface --grid 20 --json"),
        ("optimize surface with workers (one walk)", "optimize --contacts surface --workers 2"),
        ("optimize surface model nodes", "optimize --contacts surface --surface-model nodes"),
        ("optimize surface nodes 3", "optimize --contacts surface --surface-nodes 3"),
        ("optimize surface points 41 (a peak search of minutes each)", "optimize --contacts surface --points 41"),
        ("optimize surface nodes without surface contacts", "optimize --surface-nodes 7"),
        ("optimize surface with an axial platform DOF (not planar)",
         "optimize --contacts surface --config {fx}/upd_axial.toml"),
        ("optimize surface with mu 0 (no virgin curve to condense)",
         "optimize --contacts surface --config {fx}/upd_mu0.toml --json"),
    ], "upd")


def _system() -> list[InputCase]:
    return _table("system", [
        ("system cf -1", "system --cf=-1 -o r.ssp"),
        ("system cf 1e300", "system --cf 1e300 -o r.ssp"),
        ("system frequency 1e300", "system --frequency-hz 1e300 -o r.ssp"),
        ("system geometry contacts at CF 1e-300 (hung)", "system --contacts geometry --cf 1e-300 -o r.ssp"),
        ("system f0 nan", "system --f0 nan -o r.ssp"),
        ("system f0 1e-160 (underflowed)", "system --f0 1e-160 -o r.ssp"),
        ("system cf 1e-3 (a damper without load)", "system --cf 1e-3 -o r.ssp --json"),
        ("system -o an existing folder", "system -o {fx}"), ("system -o below a file", "system -o {fx}/a_file/r.ssp"),
        ("system config missing", "system --config {fx}/nowhere.toml -o r.ssp"),
        ("system frequency -1", "system --frequency-hz=-1 -o r.ssp"),
        ("cosim archive missing", "cosim {fx}/nowhere.ssp --frequency-hz 400"),
        ("cosim archive binary", "cosim {fx}/binary.bin --frequency-hz 400"),
        ("cosim a text file", "cosim {fx}/a_file --frequency-hz 400"),
        ("cosim an FMU missing from the archive", "cosim {fx}/ring_nofmu.ssp --frequency-hz 400 --json"),
    ]) + [_case("system", name, f"cosim r.ssp {cmd}", pre=[shlex.split("system --cf 120 --f0 30 -o r.ssp")],
                timeout=120.0) for name, cmd in (
        ("cosim frequency 1e-300", "--frequency-hz 1e-300"),
        ("cosim tol 10 (settled after 5 periods, 15 % off)", "--frequency-hz 448 --tol 10 --json"),
        ("cosim periods 1e12", "--frequency-hz 448 --periods 1000000000000"),
        ("cosim 1.2e8 steps", "--frequency-hz 448 --periods 50000"),
        ("cosim a diverging coupling (--force, 13 x the step limit)",
         "--frequency-hz 448 --step 1e-4 --periods 20 --force --json"))]


def _run() -> list[InputCase]:
    rows = [(f"scene {n[2:-5]}", f"{{fx}}/{n}") for n in (
        "s_loopamp.toml", "s_grid.toml", "s_grid2.toml", "s_forces.toml", "s_forceneg.toml", "s_harm.toml",
        "s_harm0.toml", "s_accuracy.toml", "s_samples.toml", "s_mu0.toml", "s_mubig.toml", "s_munan.toml",
        "s_fmax.toml",
        "s_fhuge.toml", "s_zone.toml", "s_hertz.toml", "s_unknown.toml", "s_ckey.toml", "s_want.toml",
        "s_elcontact.toml", "s_fmi.toml", "s_body.toml", "s_both.toml", "s_nu.toml", "s_type.toml", "s_dofs.toml",
        "s_mnan.toml", "s_mtext.toml", "s_mneg.toml", "s_mmissing.toml", "s_dofsame.toml", "s_toml.toml",
        "s_empty.toml", "s_binary.toml", "s_bbmode.toml", "s_bbamp.toml", "s_updpoints.toml", "s_updharm.toml",
        "s_updcfg.toml", "s_updbad.toml", "s_nocontact.toml", "s_bbacc.toml", "s_updacc.toml",
        "s_mtacc.toml", "s_mtacclin.toml", "s_kbhuge.toml", "s_zetahuge.toml", "s_fbig.toml", "s_fmintiny.toml",
        "s_step.toml", "s_bbk.toml", "s_bbf.toml", "s_bbamphuge.toml", "s_updcflow.toml", "s_mtcflow.toml",
        "s_mtci.toml", "s_mtband.toml", "s_mtblades.toml", "s_contactpath.toml",
        "s_dupkey.toml", "s_duptable.toml", "s_cfrone.toml", "s_wantempty.toml", "s_fmiempty.toml",
        "s_ufnodes.toml", "s_ufmodel.toml", "s_ufnodes4.toml", "s_ufnodes42.toml", "s_ufunknowns.toml",
        "s_ufacc.toml", "s_ufband.toml", "s_ufcflow.toml", "s_ufolsurf.toml", "s_ufnoupd.toml",
        "s_ufaxial.toml", "s_ufmu0.toml", "s_flatbig.toml", "s_uff0tiny.toml", "s_ufolsurfnodes.toml",
        "s_ufolsurfpts.toml", "s_ufolsurfgrid.toml", "s_ufolsurfcfhi.toml", "s_ufolsurfaxial.toml")]
    rows += [("dry run: loop amplitude 400", "{fx}/s_loopamp.toml --dry-run"),
             ("dry run: element DOF 7", "{fx}/s_dofs.toml --dry-run"),
             ("dry run: matrices with NaN", "{fx}/s_mnan.toml --dry-run"),
             ("dry run: grid 100000", "{fx}/s_grid.toml --dry-run"),
             ("scene missing", "{fx}/nowhere.toml"), ("scene is a folder", "{fx}"),
             ("--out an existing file", "{fx}/s_ok.toml --out {fx}/a_file"),
             ("--out below a file", "{fx}/s_ok.toml --out {fx}/a_file/out"),
             ("--force no such stage", "{fx}/s_ok.toml --force nosuch"),
             ("--cache-max-mb 0", "{fx}/s_ok.toml --cache-max-mb 0"),
             ("--cache-max-mb nan", "{fx}/s_ok.toml --cache-max-mb nan"),
             ("--no-cache with --cache-dir", "{fx}/s_ok.toml --no-cache --cache-dir c"),
             ("--cache-dir a file", "{fx}/s_ok.toml --cache-dir {fx}/a_file")]
    cases = _table("run", rows, "run")
    cases.append(_case("run", "--out the folder of the scene's [upd] config", "run s.toml --out res",
                       files={"s.toml": 'want = ["mistuning"]\n[upd]\nconfig = "res/upd.toml"\n'
                                        '[mistuning]\nsamples = 1\ndamper = "free"\n',
                              "res/upd.toml": "# the bundled UPD-24\n"}))
    cases.append(_case("run", "the default output folder holds the scene (out/<its name>/)", "run out/s/s.toml",
                       files={"out/s/s.toml": 'want = ["upd_frf"]\n[upd]\npoints = 3\nharmonics = 1\n'}))
    cases.append(_case("run", "--cache-dir a folder of the user's (eviction)",
                       "run {fx}/s_kn_small.toml --cache-dir proj --cache-max-mb 1 --out out",
                       files={"proj/user_data.npz": "user data\n"}))
    return cases


def _sweep() -> list[InputCase]:
    s = "sweep {fx}/s_ok.toml"
    p = "--param element.loop_force_amplitude"
    return _table("sweep", [
        ("a variant above mu N", f"{s} {p} --values 40 100 --serial"),
        ("range NUM 1e9", f"{s} --param contact.damper.mu --range 0.3 0.6 1000000000 --serial"),
        ("range NUM 0", f"{s} --param contact.damper.mu --range 0.3 0.6 0 --serial"),
        ("range not numbers", f"{s} --param contact.damper.mu --range a b c --serial"),
        ("range nan", f"{s} --param contact.damper.mu --range nan 1 3 --serial"),
        ("values without param", f"{s} --values 1 2 --serial"), ("param without values", f"{s} {p} --serial"),
        ("a value given twice", f"{s} {p} --values 30 30 --serial --json"),
        ("range of one value three times", f"{s} {p} --range 30 30 3 --serial"),
        ("a second range for one param", f"{s} {p} --values 30 --range 10 20 3 --serial"),
        ("unknown param", f"{s} --param contact.damper.colour --values 1 --serial"),
        ("a value of the wrong type", f"{s} {p} --values high --serial"),
        ("workers 0", f"{s} {p} --values 30 --workers 0"), ("workers 10000", f"{s} {p} --values 30 --workers 10000"),
        ("zip unequal", f"{s} {p} --values 30 35 --param contact.damper.mu --values 0.5 --zip --serial"),
        ("grid of 1e12 variants", s + "".join(f" --param {k} --range 1 2 1000" for k in
                                              ("contact.damper.force", "element.loop_force_amplitude",
                                               "excitation.forces", "sweep.f_max")) + " --serial"),
        ("--out an existing file", f"{s} {p} --values 30 --out {{fx}}/a_file --serial"),
        ("scene binary", "sweep {fx}/s_binary.toml --param contact.damper.mu --values 0.5 --serial"),
    ])


def _cache_and_rest() -> list[InputCase]:
    cases = _table("cache", [
        ("info --cache-max-mb -1", "cache info --cache-max-mb=-1"),
        ("info --cache-max-mb 1e300", "cache info --cache-max-mb 1e300"),
        ("info --cache-max-mb 1e-300", "cache info --cache-max-mb 1e-300 --json"),
        ("clear a file", "cache clear --cache-dir {fx}/a_file"),
        ("action bogus", "cache bogus"),
    ])
    cases.append(_case("cache", "clear a folder of the user's", "cache clear --cache-dir proj",
                       files={"proj/matrices.npz": "user data\n", "proj/notes.txt": "keep me\n"}))
    cases += _table("study", [("workers 0", "study cylinders --quick --workers 0"),
                              ("workers 10000", "study cylinders --quick --workers 10000"),
                              ("--plot a file", "study eccentric --quick --plot {fx}/a_file"),
                              ("unknown study", "study nosuch")])
    cases += _table("bench", [("--out a file", "bench --quick --stage element --out {fx}/a_file"),
                              ("unknown stage", "bench --quick --stage nosuch"),
                              ("empty stage name", "bench --quick --stage ''"),
                              # /proc: writable by its permission bits for root, yet no folder can be made
                              ("--out in a folder that takes no writes", "bench --quick --stage element "
                               "--out /proc/damper_bench")])
    cases += _table("stress", [("--out a file", "stress --quick --stage loop --out {fx}/a_file"),
                               ("unknown stage", "stress --stage nosuch"),
                               ("--out in a folder that takes no writes", "stress --quick --stage loop "
                                "--out /proc/damper_stress")])
    return cases


def _duties() -> list[InputCase]:
    """Not bad inputs: what the cache and the runner must do right (converged or interrupted)."""
    return [
        _case("cache", "clear keeps a user's file in the cache folder", "cache clear", pre=[shlex.split(KN_SMALL)],
              mutate="add_user_file", keep=(".damper_cache/notes.txt",), expect="converged", check="no_entries"),
        _case("cache", "an empty entry is a miss, one warning", KN_SMALL, pre=[shlex.split(KN_SMALL)],
              mutate="truncate_entries", expect="converged", check="one_warning:is unreadable"),
        _case("cache", "an entry copied over another key is a miss", KN_SMALL.replace("--grid 5", "--grid 7"),
              pre=[shlex.split(KN_SMALL), shlex.split(KN_SMALL.replace("--grid 5", "--grid 7"))],
              mutate="swap_entries", expect="converged", check="one_warning:holds another result"),
        _case("cache", "run --no-cache writes no cache", "run {fx}/s_kn_small.toml --no-cache --out out",
              expect="converged", check="no_cache_folder"),
        _case("run", "Ctrl-C during a cold run", "run {fx}/s_kn.toml --out ok", expect="interrupted",
              interrupt_on="condense", timeout=120.0),
    ]


def _typed() -> list[InputCase]:
    """Files well-formed as JSON / TOML that the typed file models refuse (input_fixtures.typed_files)."""
    cases = []
    for kind in ("mutrue", "Tstr", "wobble", "plateau", "huge"):
        cases += _table("loop", [(f"curve {kind}", f"--curve {{fx}}/curve_{kind}.json --amplitude 2e-6")], "loop")
        cases += _table("fmu", [(f"curve {kind}", f"--curve {{fx}}/curve_{kind}.json -o d.fmu")], "fmu")
    for kind in ("wobble", "Nstr", "steep"):
        cases += _table("fmu", [(f"point: normal curve {kind}",
                                 f"--curve {{fx}}/curve.json -o d.fmu --normal {{fx}}/normal_{kind}.json")], "fmu")
    for kind in ("mutrue", "mdstr", "band3", "bandnan", "blades"):
        cases += _table("upd", [(f"config {kind}", f"frf --config {{fx}}/upd_{kind}.toml --points 5")], "upd")
    cases += _table("upd", [("modes config blades 1e8", "modes --config {fx}/upd_blades.toml")], "upd")
    cases += _table("system", [("system config blades 1e8", "system --config {fx}/upd_blades.toml -o r.ssp")])
    from .input_fixtures import forged_ring_infos

    cases += _table("system", [(f"cosim forged system.json: {name}",
                                f"cosim {{fx}}/ring_{name}.ssp --frequency-hz 448 --periods 2")
                               for name in forged_ring_infos()])
    return cases


def all_cases() -> list[InputCase]:
    """Every input case, grouped by subcommand (the files themselves: :mod:`.file_cases`)."""
    return (_cli() + _normal() + _tangential() + _loop() + _fmu() + _frf() + _backbone() + _upd() + _system() + _run()
            + _sweep() + _cache_and_rest() + _duties() + _typed())
