"""The scene file's schema: every table, key, type, default and rule, in one place.

A scene (TOML, SI units) is one analysis a user asks for::

    want = ["virgin_curve", "k_t", "loop", "fmu", "frf", "report"]

    [contact.damper]           # one table per contact pair, any name
    body = "cylinder"          # sphere | cylinder | flat
    diameter = 5.0e-3          # sphere/cylinder: radius or diameter [m]
    length = 1.2e-3            # cylinder, flat [m]
    force = 120.0              # normal load [N] (constant normal force)
    mu = 0.5                   # needed for virgin_curve, k_t and what follows
    grid = 21
    # want = ["k_n"]           # optional: this contact's results (default: the scene's)

    [element]                  # the friction element (loop, fmu, frf)
    contact = "damper"         # whose virgin curve it is built from
    loop_force_amplitude = 40.0
    fmi_versions = [2, 3]

    [structure]                # the forced response (frf)
    model = "two_dof"          # the bundled 2-DOF blade-damper model (m_tip, m_platform,
    ...                        # k_blade, k_disk, zeta), or "matrices" (matrices = "file.npz",
                               # element_dofs = [a] or [a, b])
    [excitation]
    forces = [10.0, 20.0]      # tip force amplitudes [N], one curve each
    [sweep]
    f_min = 880.0              # [Hz]
    f_max = 1300.0
    harmonics = 5

Each field is a :class:`Field`; :data:`RESULTS` names the results ``want`` may
hold, with the stage kind that produces each and whether it belongs to a contact.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from contact_core.spec import MAX_GRID
from damper import limits
from damper.upd_surface import SURFACE_MODELS
from harmonic_balance.surface import MAX_NODES, MIN_NODES


@dataclass(frozen=True)
class Field:
    """One key: its type ("float", "int", "str", "bool", "list[str]", "list[float]",
    "list[int]"), whether it is required, its default, allowed values, bounds (``gt``:
    strictly greater; ``le``: the upper bound of a size, with ``why`` it is bounded) and
    its documentation."""

    type: str
    doc: str
    required: bool = False
    default: object = None
    choices: tuple = ()
    gt: float | None = None
    ge: float | None = None
    lt: float | None = None
    le: float | None = None
    why: str = ""


#: Results a scene may want: name -> (producing stage kind, per contact?, doc).
#: The blade-damper results join here with their stage kinds.
RESULTS = {
    "k_n": ("normal", True, "normal contact stiffness dN/d(approach), Hertz comparison"),
    "pressure_map": ("normal", True, "contact pressure map and area plots"),
    "virgin_curve": ("tangential", True, "virgin curve T(u) to gross slip (curve file)"),
    "k_t": ("tangential", True, "initial tangential stiffness and stick/slip maps"),
    "loop": ("loop", False, "steady hysteresis loop and energy per cycle of the element"),
    "fmu": ("fmu", False, "the friction element as FMI 2.0/3.0 FMUs, validated and run"),
    "frf": ("frf", False, "forced response of the structure by harmonic balance"),
    "backbone": ("backbone", False, "nonlinear mode of the structure with the element (EPMC): "
                 "frequency and damping ratio vs modal amplitude"),
    "optimal_load": ("optimal_load", False, "UPD bladed-disk sector: peak response against the "
                     "damper's centrifugal load CF and the optimal CF"),
    "upd_frf": ("upd_frf", False, "UPD bladed-disk sector: forced response of the EO excitation at one "
                "CF (as `damper upd frf`), with point or surface contacts"),
    "mistuning": ("mistuning", False, "UPD bladed disk: Monte Carlo of mistuning patterns on the "
                  "full ring, every blade's peak and the amplification over the tuned peak"),
    "report": ("report", False, "one-page HTML report of the run"),
}
#: Results planned but not built yet: a scene that wants one is refused
#: with this reason instead of an "unknown result".
PLANNED: dict = {}

BODY_SIZES = {"sphere": (("radius", "diameter"),), "cylinder": (("radius", "diameter"), ("length",)),
              "flat": (("width",), ("length",))}

CONTACT = {
    "body": Field("str", "sphere, cylinder or flat face on a plane", required=True,
                  choices=tuple(BODY_SIZES)),
    "radius": Field("float", "sphere/cylinder radius [m]", gt=0),
    "diameter": Field("float", "sphere/cylinder diameter [m] (instead of radius)", gt=0),
    "length": Field("float", "cylinder length / flat-face length [m]", gt=0),
    "width": Field("float", "flat-face width [m]", gt=0),
    "height": Field("float", "flat face: height of the damper body above the face [m] (default max(W, L/2))", gt=0),
    "E": Field("float", "Young's modulus of body 1 [Pa] (and of the plane unless E2)", default=200e9, gt=0),
    "nu": Field("float", "Poisson's ratio of body 1 (and of the plane unless nu2)", default=0.3, gt=-1, lt=0.5),
    "E2": Field("float", "Young's modulus of the plane [Pa]", gt=0),
    "nu2": Field("float", "Poisson's ratio of the plane", gt=-1, lt=0.5),
    "model": Field("str", "FE model variant", default="real", choices=("real", "halfspace")),
    "grid": Field("int", "contact-zone nodes per side", default=21, ge=3, le=MAX_GRID,
                  why="81 nodes per side is ~0.25 M DOF per body and minutes of condensation; "
                  "41 already gives a and p0 within 0.2 % of Hertz"),
    "p_design": Field("float", "design peak pressure sizing the contact zone [Pa]", default=2000e6, gt=0),
    "force": Field("float", "normal load [N] (constant normal force)", required=True, gt=0),
    "zone_load": Field("float", "load [N] the potential contact zone is sized to hold besides the design "
                       "pressure (default: force; 0: design pressure only, as the thesis, App. A.1.2)", ge=0),
    "mu": Field("float", "friction coefficient", gt=0, le=limits.MAX_MU,
                why="dry contacts have mu below a few; a larger value is a typo"),
    "want": Field("list[str]", "this contact's results (default: the scene's contact results)"),
}

ELEMENT = {
    "contact": Field("str", "name of the contact whose virgin curve becomes the element", required=True),
    "loop_force_amplitude": Field("float", "force amplitude of the loop [N]", gt=0),
    "loop_samples": Field("int", "samples per loop cycle", default=256, ge=4, le=limits.MAX_LOOP_SAMPLES,
                          why="1e6 samples take ~4 s and 0.24 GB"),
    "fmi_versions": Field("list[int]", "FMI versions of the FMUs", default=[2, 3], choices=(2, 3)),
}

#: Why a model parameter is bounded by limits.MAX_MAGNITUDE.
_MAG_WHY = "the harmonic balance squares forces and displacements (omega^2 M, residual norms) and overflows"

STRUCTURE = {
    "model": Field("str", "two_dof: the bundled blade-damper model; matrices: a matrices file",
                   default="two_dof", choices=("two_dof", "matrices")),
    "m_tip": Field("float", "two_dof: blade tip mass [kg]", gt=0, le=limits.MAX_MAGNITUDE, why=_MAG_WHY),
    "m_platform": Field("float", "two_dof: platform mass [kg]", gt=0, le=limits.MAX_MAGNITUDE, why=_MAG_WHY),
    "k_blade": Field("float", "two_dof: blade stiffness tip-platform [N/m]", gt=0, le=limits.MAX_MAGNITUDE,
                     why=_MAG_WHY),
    "k_disk": Field("float", "two_dof: disk stiffness platform-ground [N/m]", gt=0, le=limits.MAX_MAGNITUDE,
                    why=_MAG_WHY),
    "zeta": Field("float", "two_dof: damping ratio at the first free mode (Rayleigh beta K)", ge=0,
                  le=limits.MAX_DAMPING_RATIO, why=limits.DAMPING_RATIO_WHY),
    "matrices": Field("str", "matrices: the .npz file (harmonic_balance.model's format; relative to the scene)"),
    "element_dofs": Field("list[int]", "matrices: DOF [a] (to the ground) or [a, b] the element links", ge=0),
}
#: Keys each structure model needs.
STRUCTURE_NEEDS = {"two_dof": ("m_tip", "m_platform", "k_blade", "k_disk", "zeta"),
                   "matrices": ("matrices", "element_dofs")}

EXCITATION = {
    "forces": Field("list[float]", "two_dof: tip force amplitudes [N]; matrices: factors on the file's "
                    "force; one forced response each", required=True, gt=0, le=limits.MAX_MAGNITUDE,
                    why=_MAG_WHY),
}

_F_MAX = limits.MAX_OMEGA / (2 * math.pi)
_F_MIN = limits.MIN_OMEGA / (2 * math.pi)
_F_WHY = "far above any structural mode, and omega^2 M must not overflow"

SWEEP = {
    "f_min": Field("float", "start frequency [Hz]", required=True, ge=_F_MIN, le=_F_MAX, why=_F_WHY),
    "f_max": Field("float", "end frequency [Hz]", required=True, ge=_F_MIN, le=_F_MAX, why=_F_WHY),
    "harmonics": Field("int", "harmonics 0..H retained", default=5, ge=1, le=limits.MAX_HARMONICS,
                       why=limits.harmonics_why(limits.MAX_HARMONICS)),
    "max_step": Field("float", "largest continuation step (scaled arclength; the curve tolerance "
                      "sizes the steps below it; at least 1/2000, the curve's most points, as the "
                      "range alone is 1 in scaled arclength)", default=0.5, ge=5e-4),
    "accuracy": Field("float", "relative accuracy of the peak amplitude: the harmonics are raised "
                      "from `harmonics` until the estimated truncation error is below it (unset: "
                      "the fixed `harmonics`, the estimate reported)", gt=1e-6, lt=0.5),
}

BACKBONE = {
    "element": Field("str", "contact: the [element] built from its contact's virgin curve (runs the "
                     "contact stages); jenkins: a Jenkins element (contact_stiffness, slip_force), no "
                     "contact stage", default="contact", choices=("contact", "jenkins")),
    "contact_stiffness": Field("float", "jenkins: stick stiffness of the element [N/m]", gt=0,
                               le=limits.MAX_MAGNITUDE, why=_MAG_WHY),
    "slip_force": Field("float", "jenkins: slip force of the element [N]", gt=0, le=limits.MAX_MAGNITUDE,
                        why=_MAG_WHY),
    "amplitude": Field("list[float]", "[start, end] mass-normalised modal amplitude [m sqrt(kg)]; "
                       "start small (the start is the stuck linear mode)", required=True, gt=0,
                       le=limits.MAX_MAGNITUDE, why=_MAG_WHY),
    "harmonics": Field("int", "harmonics 0..H retained", default=3, ge=1, le=limits.MAX_HARMONICS,
                       why=limits.harmonics_why(limits.MAX_HARMONICS)),
    "mode": Field("int", "mode of the stuck linear system (0-based)", default=0, ge=0),
    "samples": Field("int", "AFT samples per period (0: automatic)", default=0, ge=0,
                     le=limits.MAX_AFT_SAMPLES, why="the AFT's DFT matrices hold n_t (2H + 1) numbers each"),
    "accuracy": Field("float", "relative accuracy of the frequency and the damping ratio: the harmonics "
                      "are raised from `harmonics` until both estimated truncation errors are below "
                      "it (unset: the fixed `harmonics`, the estimate reported)", gt=1e-6, lt=0.5),
}
#: Keys each backbone element needs.
BACKBONE_NEEDS = {"contact": (), "jenkins": ("contact_stiffness", "slip_force")}

UPD = {
    "config": Field("str", "UPD model TOML (harmonic_balance.bladed_disk's format; relative to the "
                    "scene; default: the bundled UPD-24)"),
    "cf_range": Field("list[float]", "[low, high] centrifugal load CF of the damper [N], log-spaced",
                      default=[30.0, 3000.0], gt=0, le=limits.MAX_MAGNITUDE, why=_MAG_WHY),
    "points": Field("int", "number of CF values", default=20, ge=3, le=limits.MAX_LOAD_POINTS,
                    why="each CF value is a whole forced response (seconds)"),
    "harmonics": Field("int", "highest harmonic", default=7, ge=1, le=limits.MAX_UPD_HARMONICS,
                       why=limits.harmonics_why(limits.MAX_UPD_HARMONICS)),
    "grid": Field("int", "frequency points per curve before the peak refinement (optimal_load: each "
                  "CF's curve; upd_frf: the curve over the band)", default=40, ge=3,
                  le=limits.MAX_UPD_GRID, why="each point is a harmonic-balance solve of the sector"),
    "accuracy": Field("float", "relative accuracy of the peak amplitude (optimal_load: the optimum's; its "
                      "curve is raised in H until the estimated truncation error is below it, and the "
                      "load sweep run again at that H; upd_frf: the curve's peak re-solved with more "
                      "harmonics; unset: the fixed `harmonics`, the estimate reported)", gt=1e-6, lt=0.5),
    "cf": Field("float", "upd_frf: centrifugal load on the damper [N] (default: the UPD model's)",
                ge=limits.MIN_LOAD, le=limits.MAX_MAGNITUDE, why=_MAG_WHY),
    "f0": Field("float", "upd_frf: EO force amplitude on the airfoil [N] (default: the UPD model's)",
                ge=limits.MIN_LOAD, le=limits.MAX_MAGNITUDE, why=_MAG_WHY),
    "band": Field("list[float]", "upd_frf: [low, high] frequency band [Hz] (default: the UPD model's)",
                  ge=_F_MIN, le=_F_MAX, why=_F_WHY),
    "contacts": Field("str", "contact laws: toml (the model's Jenkins points), geometry (computed by "
                      "contact_core from its [geometry] section), surface (the damper's faces as contact "
                      "surfaces of many 3D points on the condensed FE bodies; slower: optimal_load then walks "
                      "the loads with the condensed model, a peak search of minutes per load, and refuses "
                      "grid unless upd_frf is wanted too)",
                      default="toml", choices=("toml", "geometry", "surface")),
    "surface_nodes": Field("int", "contacts = surface: contact-zone nodes per side of each face "
                           "(default 5)", ge=MIN_NODES, le=MAX_NODES,
                           why="each node is a 3D contact point of the harmonic balance"),
    "surface_model": Field("str", "contacts = surface: condensed (default; the faces condensed onto their "
                           "rigid inputs, the nodes marched in time) or nodes (every node's DOFs as "
                           "unknowns; needs a well-loaded damper)", choices=SURFACE_MODELS),
}

MISTUNING = {
    "blades": Field("int", "number of blades N_b (default: the UPD model's)", ge=2),
    "engine_order": Field("int", "engine order EO (default: the UPD model's)", ge=0),
    "std": Field("float", "standard deviation of the random factors (default 0.02)", ge=0),
    "samples": Field("int", "number of random patterns (default 20)", ge=1),
    "seed": Field("int", "seed; sample i draws from [seed, i] (default 1)", ge=0),
    "kind": Field("str", "the factors scale the blades' stiffness or their frequencies",
                  default="stiffness", choices=("stiffness", "frequency")),
    "distribution": Field("str", "distribution of the random factors", default="normal",
                          choices=("normal", "uniform")),
    "factors": Field("list[float]", "one given pattern, a factor per blade (instead of std, "
                     "samples, seed)", gt=0),
    "damper": Field("str", "nonlinear (harmonic balance), or the linear limits free (removed) and "
                    "stuck", default="nonlinear", choices=("nonlinear", "free", "stuck")),
    "cf": Field("float", "centrifugal load on the damper [N] (default: the UPD model's)", ge=limits.MIN_LOAD),
    "f0": Field("float", "EO force amplitude [N] (default: the UPD model's)", ge=limits.MIN_LOAD),
    "harmonics": Field("int", "highest harmonic", default=7, ge=1),
    "band": Field("list[float]", "[low, high] band [Hz] (default: around the tuned peak)", gt=0),
    "points": Field("int", "frequency points per ring curve (solver full)", default=41, ge=3),
    "until_ci": Field("float", "stop when the amplification's 0.95 quantile is known to +- this (its "
                      "95 % interval's half-width); samples is then the most to run", gt=0),
    "solver": Field("str", "fast (adaptive continuation, Hermite peaks) or full (every grid "
                    "point solved: the reference)", default="fast", choices=("fast", "full")),
    "accuracy": Field("float", "relative accuracy of the tuned peak amplitude (damper nonlinear): "
                      "H is raised on the tuned sector from `harmonics` until its estimated "
                      "truncation error is below it, and every sample runs at that H (unset: the "
                      "fixed `harmonics`, the tuned estimate reported)", gt=1e-6, lt=0.5),
}

TOP = {
    "title": Field("str", "a name for the report", default=""),
    "want": Field("list[str]", "results wanted", required=True),
}

#: Tables: name -> (fields, one table per named item?)
TABLES = {"contact": (CONTACT, True), "element": (ELEMENT, False), "structure": (STRUCTURE, False),
          "excitation": (EXCITATION, False), "sweep": (SWEEP, False), "backbone": (BACKBONE, False),
          "upd": (UPD, False), "mistuning": (MISTUNING, False)}


@dataclass
class Problem:
    """One schema violation: the key path and what is wrong."""

    path: tuple
    message: str
    extra: dict = field(default_factory=dict)


def check_value(f: Field, value) -> str | None:
    """What is wrong with ``value`` for ``f`` (None if fine)."""
    scalar = f.type.removeprefix("list[").removesuffix("]")
    if f.type.startswith("list["):
        if not isinstance(value, list):
            return f"must be a list of {scalar}, got {_kind(value)}"
        if not value:  # every list key names something to do or a range: empty is nothing asked
            noun = {"float": "number", "int": "integer", "str": "string"}.get(scalar, scalar)
            return f"is empty: give at least one {noun}" + ("" if f.required else " (or leave the key out)")
        for i, v in enumerate(value):
            msg = _check_scalar(f, scalar, v)
            if msg:
                return f"item {i}: {msg}"
        return None
    return _check_scalar(f, scalar, value)


def _check_scalar(f: Field, scalar: str, v) -> str | None:
    if scalar == "float":
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            return f"must be a number, got {_kind(v)} {v!r}"
        if not math.isfinite(v):
            return f"must be finite, got {v!r}"
    elif scalar == "int":
        if isinstance(v, bool) or not isinstance(v, int):
            return f"must be an integer, got {_kind(v)} {v!r}"
    elif scalar == "str":
        if not isinstance(v, str):
            return f"must be a string, got {_kind(v)} {v!r}"
    elif scalar == "bool" and not isinstance(v, bool):
        return f"must be true or false, got {_kind(v)} {v!r}"
    if f.choices and v not in f.choices:
        return f"must be one of {', '.join(map(repr, f.choices))}, got {v!r}"
    if f.gt is not None and not v > f.gt:
        return f"must be > {f.gt:g}, got {v!r}"
    if f.ge is not None and not v >= f.ge:
        return f"must be >= {f.ge:g}, got {v!r}"
    if f.lt is not None and not v < f.lt:
        return f"must be < {f.lt:g}, got {v!r}"
    if f.le is not None and not v <= f.le:
        return f"must be <= {f.le:g}, got {v!r}" + (f": {f.why}" if f.why else "")
    return None


def _kind(v) -> str:
    return {dict: "a table", list: "a list", str: "a string", bool: "a boolean",
            int: "an integer", float: "a number"}.get(type(v), type(v).__name__)


def json_schema() -> dict:
    """The scene file as a JSON Schema (draft 2020-12), from the tables above: what an
    editor checks and completes a scene with (keys, types, choices, bounds, docs)."""
    props = {k: _field_schema(f) for k, f in TOP.items()}
    for name, (fields, named) in TABLES.items():
        table = _table_schema(fields, f"[{name}]")
        props[name] = ({"type": "object", "description": f"[{name}.NAME] tables, one per item",
                        "additionalProperties": table} if named else table)
    return {"$schema": "https://json-schema.org/draft/2020-12/schema", "title": "damper scene",
            "description": "A scene (TOML, SI units): one analysis `damper run` runs. Checks that relate "
                           "keys (a body's sizes, wants and the tables they need) are the loader's.",
            "type": "object", "properties": props, "required": [k for k, f in TOP.items() if f.required],
            "additionalProperties": False}


def _table_schema(fields: dict, title: str) -> dict:
    return {"type": "object", "title": title, "properties": {k: _field_schema(f) for k, f in fields.items()},
            "required": [k for k, f in fields.items() if f.required], "additionalProperties": False}


def _field_schema(f: Field) -> dict:
    scalar = f.type.removeprefix("list[").removesuffix("]")
    out: dict = {"type": {"float": "number", "int": "integer", "str": "string", "bool": "boolean"}[scalar]}
    if f.choices:
        out["enum"] = list(f.choices)
    for key, bound in (("exclusiveMinimum", f.gt), ("minimum", f.ge), ("exclusiveMaximum", f.lt),
                       ("maximum", f.le)):
        if bound is not None:
            out[key] = bound
    if f.type.startswith("list["):
        out = {"type": "array", "items": out, "minItems": 1}
    out["description"] = f.doc + (f" (bounded: {f.why})" if f.why else "")
    if f.default is not None:
        out["default"] = f.default
    return out
