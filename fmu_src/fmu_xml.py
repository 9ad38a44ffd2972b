"""The interfaces of the FMUs, written once: one variable table per model.

Everything the FMI side needs to agree on comes from an :class:`Interface` (its
variable table): the ``modelDescription.xml`` of FMI 2.0 and of FMI 3.0, the FMI 3
build description, and the C header of the model's value references, causalities,
start rules and instantiation token (``fmu_src/fmi/damper_vr.h`` for the 1D friction
element :data:`DAMPER`, ``point_vr.h`` for the contact point :data:`POINT`). The
headers are committed; a test checks that they equal :func:`render_vr_header`
(regenerate with ``python -m fmu_src.fmu_build --write-header``). Nothing is kept in
sync by hand. Every header defines the same C names, so the FMI layer compiles
against whichever one ``fmu_vars.h`` includes. Models whose variables depend on their
data (a blade's named DOFs, a damper's contacts: :mod:`fmu_src.blade_fmu`,
:mod:`fmu_src.upd_fmu`) get their header generated into the FMU's ``sources/`` at build
time, with their start values in it (rule ``value``) and their capabilities (direct
feedthrough, directional derivatives, FMI 2 input derivatives) as flags.

Symbols: u relative tangential displacement [m], N normal load [N], F friction
force [N], kt tangent stiffness dF/du [N/m], W dissipated energy [J], slip slip
fraction [-], N_ref normal load of the virgin curve [N]; contact point: u_x, u_y
slip [m], p penetration [m], F_x, F_y, N contact forces [N], K_ab = dF_a/dq_b [N/m].
"""
from __future__ import annotations

import hashlib
import uuid
from dataclasses import dataclass, field
from xml.sax.saxutils import escape, quoteattr

#: Model identifier of the 1D element: the binary is ``binaries/<platform>/damper.so``.
MODEL_IDENTIFIER = "damper"

#: Start rules shared by XML and C: where a variable's start value comes from. The first
#: three are the FMI layer's own; any other is the model's (``model_start`` in C).
START_RULES = ("none", "zero", "one", "curve_n")
#: The start rules of tables that carry their start values (rule ``value``).
VALUE_START_RULES = ("none", "zero", "one", "value")

#: FMI log categories the FMU declares (and accepts in SetDebugLogging).
LOG_CATEGORIES = (
    ("logStatusError", "Errors: rejected inputs, calls in a wrong state, bad curve"),
    ("logStatusWarning", "Warnings"),
)


@dataclass(frozen=True)
class Variable:
    """One FMU variable (all are Float64 / Real scalars)."""

    name: str
    vr: int
    causality: str      # independent | input | output | parameter
    variability: str    # continuous | fixed
    unit: str
    start: str          # one of the interface's start rules
    description: str
    # the start value of rule "value" (out of the repr: the tables without that rule
    # keep their tokens)
    value: float = field(default=0.0, repr=False)


#: The FMU's variables, in ModelVariables order (value reference = position).
VARIABLES: tuple[Variable, ...] = (
    Variable("time", 0, "independent", "continuous", "s", "none", "Simulation time"),
    Variable("u", 1, "input", "continuous", "m", "zero",
             "Relative tangential displacement of the contact"),
    Variable("N", 2, "input", "continuous", "N", "curve_n",
             "Normal load (default: the normal load of the curve); N <= 0 is lift-off"),
    Variable("F", 3, "output", "continuous", "N", "none", "Friction force"),
    Variable("kt", 4, "output", "continuous", "N/m", "none",
             "Tangent stiffness dF/du for continued motion"),
    Variable("W", 5, "output", "continuous", "J", "none",
             "Cumulative dissipated energy"),
    Variable("slip", 6, "output", "continuous", "1", "none",
             "Slip fraction: slipping strength / total strength, in [0, 1]"),
    Variable("scale", 7, "parameter", "fixed", "1", "one",
             "Friction scale: multiplies every slip strength (1 = as computed)"),
    Variable("N_ref", 8, "parameter", "fixed", "N", "curve_n",
             "Reference normal load: the load the virgin curve was computed at"),
    Variable("stored_energy", 9, "output", "continuous", "J", "none",
             "Elastic energy stored in the sliders and the residual spring: the work of the "
             "input displacement equals W + stored_energy (at constant N)"),
)


#: SI decomposition of every unit used (FMI BaseUnit exponents).
UNITS = {
    "s": {"s": 1},
    "m": {"m": 1},
    "N": {"kg": 1, "m": 1, "s": -2},
    "N/m": {"kg": 1, "s": -2},
    "J": {"kg": 1, "m": 2, "s": -2},
    "1": {},
    "m/s": {"m": 1, "s": -1},
    "N.s/m": {"kg": 1, "s": -1},
    "N/s": {"kg": 1, "m": 1, "s": -3},
    "Hz": {"s": -1},
    "rad": {},
}

#: The 1D element's start rules (the C enum of its header, part of its token).
DAMPER_START_RULES = START_RULES


def _k(a: str, b: str, row: str, col: str) -> Variable:
    return Variable(f"K_{a}{b}", 0, "output", "continuous", "N/m", "none",
                    f"Tangent stiffness dF_{row}/d{col}: exact at the end of the step from "
                    "the last communication point, for continued motion when the inputs are there")


def _numbered(variables) -> tuple[Variable, ...]:
    """The table with value reference = position."""
    return tuple(Variable(v.name, i, v.causality, v.variability, v.unit, v.start, v.description)
                 for i, v in enumerate(variables))


#: The contact point's variables (value reference = position).
POINT_VARIABLES: tuple[Variable, ...] = _numbered((
    Variable("time", 0, "independent", "continuous", "s", "none", "Simulation time"),
    Variable("u_x", 0, "input", "continuous", "m", "zero",
             "Relative tangential displacement (slip) of the contact along its first tangent"),
    Variable("u_y", 0, "input", "continuous", "m", "zero",
             "Relative tangential displacement (slip) along the second tangent"),
    Variable("p", 0, "input", "continuous", "m", "normal_p",
             "Penetration, positive pressed (start: the penetration at the start load); "
             "p <= 0 is lift-off"),
    Variable("v_x", 0, "input", "continuous", "m/s", "zero",
             "Relative tangential velocity along the first tangent (for the dashpot c_t)"),
    Variable("v_y", 0, "input", "continuous", "m/s", "zero",
             "Relative tangential velocity along the second tangent (for the dashpot c_t)"),
    Variable("v_n", 0, "input", "continuous", "m/s", "zero",
             "Rate of penetration (for the dashpot c_n)"),
    Variable("F_x", 0, "output", "continuous", "N", "none",
             "Friction force along the first tangent (tangential dashpot included)"),
    Variable("F_y", 0, "output", "continuous", "N", "none",
             "Friction force along the second tangent (tangential dashpot included)"),
    Variable("N", 0, "output", "continuous", "N", "none",
             "Normal load, >= 0 (normal dashpot included)"),
    Variable("W", 0, "output", "continuous", "J", "none", "Cumulative friction work"),
    Variable("stored_energy", 0, "output", "continuous", "J", "none",
             "Elastic energy in the sliders, the residual spring and the normal spring: the "
             "work of the inputs u_x, u_y, p equals W + stored_energy (dashpots aside)"),
    Variable("state", 0, "output", "continuous", "1", "none",
             "Contact state: 0 open (lift-off), 1 stick, 2 slip (some slider slipping)"),
    Variable("slip", 0, "output", "continuous", "1", "none",
             "Slip fraction: slipping strength / total strength, in [0, 1]"),
    _k("x", "x", "x", "u_x"), _k("x", "y", "x", "u_y"), _k("x", "p", "x", "p"),
    _k("y", "x", "y", "u_x"), _k("y", "y", "y", "u_y"), _k("y", "p", "y", "p"),
    Variable("K_px", 0, "output", "continuous", "N/m", "none", "dN/du_x (zero)"),
    Variable("K_py", 0, "output", "continuous", "N/m", "none", "dN/du_y (zero)"),
    Variable("K_pp", 0, "output", "continuous", "N/m", "none", "Normal stiffness dN/dp"),
    Variable("scale", 0, "parameter", "fixed", "1", "one",
             "Friction scale: multiplies every slip strength (1 = as computed)"),
    Variable("N_ref", 0, "parameter", "fixed", "N", "curve_n",
             "Reference normal load: the load the virgin curve was computed at"),
    Variable("c_t", 0, "parameter", "fixed", "N.s/m", "zero",
             "Tangential contact dashpot (in contact; with the inputs v_x, v_y)"),
    Variable("c_n", 0, "parameter", "fixed", "N.s/m", "zero",
             "Normal contact dashpot (in contact, no adhesion; with the input v_n)"),
))


@dataclass(frozen=True)
class Interface:
    """The variable table of one FMU model and what is derived from it.

    Attributes
    ----------
    model_identifier : str   binary name ``binaries/<platform>/<model_identifier>.so``
    model_name : str         ``modelName`` of the model description
    variables : tuple of Variable (value reference = position)
    start_rules : tuple of str (C enum START_<RULE>; part of the token)
    header : str             the generated C header (committed in fmu_src/fmi, or
                             written into an FMU's sources)
    feedthrough : bool       outputs depend on the current inputs (ModelStructure)
    directional : bool       provides directional derivatives
    interpolates : bool      accepts FMI 2 input derivatives (order 1)
    """

    model_identifier: str
    model_name: str
    variables: tuple
    start_rules: tuple
    header: str
    feedthrough: bool = True
    directional: bool = True
    interpolates: bool = True

    def fmi2_variables(self) -> tuple:
        """The FMI 2 ModelVariables (:func:`fmi2_variables`)."""
        return fmi2_variables(self)

    def by_causality(self, causality: str) -> list[Variable]:
        """Variables of one causality, in table order."""
        return [v for v in self.variables if v.causality == causality]

    def units(self) -> dict:
        """The UNITS entries this table uses, in UNITS order."""
        used = {v.unit for v in self.variables}
        return {k: v for k, v in UNITS.items() if k in used}


#: The 1D friction element (``damper fmu --curve``).
DAMPER = Interface(MODEL_IDENTIFIER, "damper friction element", VARIABLES, DAMPER_START_RULES,
                   "damper_vr.h")
#: The 3D contact point (``damper fmu --curve --normal`` / ``--k-n``).
POINT = Interface("contact_point", "damper contact point", POINT_VARIABLES,
                  (*START_RULES, "normal_p"), "point_vr.h")
#: Every interface, by the name of its model hooks (fmu_build.MODELS).
INTERFACES = {"iwan": DAMPER, "passthrough": DAMPER, "point": POINT}


def fmi2_variables(iface: Interface = DAMPER) -> tuple[Variable, ...]:
    """The FMI 2 ModelVariables: all but the independent ``time``.

    FMI 2 does not require an independent variable, and FMI Library before 2.0.3
    (libcosim) logs "Start attribute is required" for one without a start value.
    """
    return tuple(v for v in iface.variables if v.causality != "independent")


def by_causality(causality: str, iface: Interface = DAMPER) -> list[Variable]:
    """Variables of one causality, in table order."""
    return iface.by_causality(causality)


def instantiation_token(iface: Interface = DAMPER) -> str:
    """GUID (FMI 2) / instantiation token (FMI 3): a hash of the variable table.

    The C side checks it at instantiation, so a binary built against another
    table refuses to load.
    """
    text = repr((iface.model_identifier, iface.variables, iface.start_rules))
    values = [v.value for v in iface.variables if v.start == "value"]
    if values or not (iface.feedthrough and iface.directional and iface.interpolates):
        text += repr((values, iface.feedthrough, iface.directional, iface.interpolates))
    digest = hashlib.sha256(text.encode()).digest()[:16]
    return "{" + str(uuid.UUID(bytes=digest)) + "}"


def start_value(var: Variable, curve_n: float, starts: dict | None = None) -> float | None:
    """Numeric start value of ``var`` for an FMU whose curve was computed at ``curve_n``;
    ``starts`` gives the values of the model's own rules (e.g. ``normal_p``)."""
    rules = {"none": None, "zero": 0.0, "one": 1.0, "curve_n": float(curve_n),
             "value": var.value, **(starts or {})}
    return rules[var.start]


def _fmt(x: float) -> str:
    return repr(float(x))  # shortest repr round-trips exactly


def _units_xml(iface: Interface) -> str:
    lines = ["  <UnitDefinitions>"]
    for name, exps in iface.units().items():
        base = " ".join(f'{k}="{v}"' for k, v in exps.items())
        inner = f"<BaseUnit {base}/>" if base else "<BaseUnit/>"
        lines.append(f"    <Unit name={quoteattr(name)}>{inner}</Unit>")
    lines.append("  </UnitDefinitions>")
    return "\n".join(lines)


def _log_categories_xml() -> str:
    items = "".join(f"\n    <Category name={quoteattr(n)} description={quoteattr(d)}/>"
                    for n, d in LOG_CATEGORIES)
    return f"  <LogCategories>{items}\n  </LogCategories>"


def _bound_attrs(var: Variable, bounds: dict) -> str:
    """min/max of a bounded input: the FMU refuses |value| beyond its bound."""
    b = bounds.get(var.name)
    if b is None or not b < float("inf"):
        return ""
    return f' min="{_fmt(-b)}" max="{_fmt(b)}"'


def _variable_attrs(var: Variable) -> str:
    attrs = (f"name={quoteattr(var.name)} valueReference=\"{var.vr}\" "
             f"causality=\"{var.causality}\" variability=\"{var.variability}\"")
    if var.causality == "parameter":
        attrs += ' initial="exact"'
    return attrs + f" description={quoteattr(var.description)}"


def _fmi2_variables(iface: Interface, curve_n: float, bounds: dict, starts: dict) -> str:
    out = ["  <ModelVariables>"]
    for i, var in enumerate(fmi2_variables(iface), start=1):
        start = start_value(var, curve_n, starts)
        real = f"<Real unit={quoteattr(var.unit)}" + _bound_attrs(var, bounds)
        real += f' start="{_fmt(start)}"/>' if start is not None else "/>"
        out.append(f"    <!-- index {i} -->")
        out.append(f"    <ScalarVariable {_variable_attrs(var)}>\n      {real}\n"
                   f"    </ScalarVariable>")
    out.append("  </ModelVariables>")
    return "\n".join(out)


def _fmi3_variables(iface: Interface, curve_n: float, bounds: dict, starts: dict) -> str:
    out = ["  <ModelVariables>"]
    for var in iface.variables:
        start = start_value(var, curve_n, starts)
        attrs = _variable_attrs(var) + f" unit={quoteattr(var.unit)}" + _bound_attrs(var, bounds)
        if start is not None:
            attrs += f' start="{_fmt(start)}"'
        out.append(f"    <Float64 {attrs}/>")
    out.append("  </ModelVariables>")
    return "\n".join(out)


def _structure(fmi_version: int, iface: Interface = DAMPER) -> str:
    """ModelStructure: with direct feedthrough every output depends on every input,
    without it on none (the outputs are the state at the communication point).

    During initialization the outputs also depend on the parameters (knowns with
    initial="exact"). FMI 2 dependencies are 1-based indices into the FMI 2 ModelVariables;
    FMI 3 dependencies are value references.
    """
    inputs = iface.by_causality("input") if iface.feedthrough else []
    knowns = inputs + iface.by_causality("parameter")
    outputs = iface.by_causality("output")
    if fmi_version == 2:
        index = {v.vr: i for i, v in enumerate(fmi2_variables(iface), start=1)}
        deps = " ".join(str(index[v.vr]) for v in inputs)
        init_deps = " ".join(str(index[v.vr]) for v in knowns)
        outs = "\n".join(f'      <Unknown index="{index[v.vr]}" dependencies="{deps}"/>'
                         for v in outputs)
        inits = "\n".join(f'      <Unknown index="{index[v.vr]}" dependencies="{init_deps}"/>'
                          for v in outputs)
        return (f"  <ModelStructure>\n    <Outputs>\n{outs}\n    </Outputs>\n"
                f"    <InitialUnknowns>\n{inits}\n    </InitialUnknowns>\n  </ModelStructure>")
    deps = " ".join(str(v.vr) for v in inputs)
    init_deps = " ".join(str(v.vr) for v in knowns)
    rows = [f'    <Output valueReference="{v.vr}" dependencies="{deps}"/>' for v in outputs]
    rows += [f'    <InitialUnknown valueReference="{v.vr}" dependencies="{init_deps}"/>'
             for v in outputs]
    return "  <ModelStructure>\n" + "\n".join(rows) + "\n  </ModelStructure>"


def _flag(v: bool) -> str:
    return "true" if v else "false"


def render_model_description(fmi_version: int, curve_n: float, source_files: list[str],
                             description: str, u_bound: float | None = None,
                             iface: Interface = DAMPER, bounds: dict | None = None,
                             starts: dict | None = None) -> str:
    """Text of ``modelDescription.xml`` for FMI 2.0 or 3.0 (co-simulation).

    Parameters
    ----------
    fmi_version : {2, 3}
    curve_n : float
        Normal load of the packaged curve [N] (start of the ``curve_n`` rule: ``N``
        and ``N_ref``).
    source_files : list of str
        C files of the source FMU (FMI 2 ``<SourceFiles>``; FMI 3 uses
        :func:`render_build_description` instead).
    description : str
        Free text (curve provenance).
    u_bound : float, optional
        Largest |u| the 1D FMU accepts [m] (``min``/``max`` of the input ``u``).
    iface : Interface
        The model's variable table (default the 1D element).
    bounds : dict, optional
        Input name -> largest |value| (``min``/``max``); default ``{"u": u_bound}``.
    starts : dict, optional
        Start values of the model's own start rules (``{"normal_p": p0}``).
    """
    bounds = {"u": u_bound} if bounds is None else bounds
    token = instantiation_token(iface)
    common = (f'modelName="{iface.model_name}" description={quoteattr(description)} '
              f'generationTool="damper-toolkit fmu_src.fmu_build" variableNamingConvention="flat"')
    mid = iface.model_identifier
    if fmi_version == 2:
        files = "".join(f'\n      <File name={quoteattr(f)}/>' for f in source_files)
        head = (f'<fmiModelDescription fmiVersion="2.0" {common} guid="{token}" '
                f'numberOfEventIndicators="0">\n'
                f'  <CoSimulation modelIdentifier="{mid}" '
                'canHandleVariableCommunicationStepSize="true" '
                f'canInterpolateInputs="{_flag(iface.interpolates)}" '
                'maxOutputDerivativeOrder="0" canGetAndSetFMUstate="true" '
                'canSerializeFMUstate="true" '
                f'providesDirectionalDerivative="{_flag(iface.directional)}" '
                'canNotUseMemoryManagementFunctions="true" '
                'canBeInstantiatedOnlyOncePerProcess="false">\n'
                f'    <SourceFiles>{files}\n    </SourceFiles>\n  </CoSimulation>')
        variables = _fmi2_variables(iface, curve_n, bounds, starts or {})
    elif fmi_version == 3:
        head = (f'<fmiModelDescription fmiVersion="3.0" {common} '
                f'instantiationToken="{token}">\n'
                f'  <CoSimulation modelIdentifier="{mid}" '
                'canHandleVariableCommunicationStepSize="true" canGetAndSetFMUState="true" '
                'canSerializeFMUState="true" '
                f'providesDirectionalDerivatives="{_flag(iface.directional)}" '
                'providesAdjointDerivatives="false" hasEventMode="false" '
                'canBeInstantiatedOnlyOncePerProcess="false"/>')
        variables = _fmi3_variables(iface, curve_n, bounds, starts or {})
    else:
        raise ValueError(f"fmi_version must be 2 or 3, not {fmi_version!r}")
    parts = ['<?xml version="1.0" encoding="UTF-8"?>', head, _units_xml(iface),
             _log_categories_xml(),
             '  <DefaultExperiment startTime="0" stopTime="1"/>',
             variables, _structure(fmi_version, iface), "</fmiModelDescription>", ""]
    return "\n".join(parts)


def render_build_description(source_files: list[str], iface: Interface = DAMPER) -> str:
    """Text of the FMI 3 ``sources/buildDescription.xml`` (paths relative to sources/)."""
    files = "".join(f"\n      <SourceFile name={quoteattr(f)}/>" for f in source_files)
    return ('<?xml version="1.0" encoding="UTF-8"?>\n<fmiBuildDescription fmiVersion="3.0">\n'
            f'  <BuildConfiguration modelIdentifier="{iface.model_identifier}">\n'
            f'    <SourceFileSet language="C99">{files}\n    </SourceFileSet>\n'
            "  </BuildConfiguration>\n</fmiBuildDescription>\n")


def render_fmu_vars(iface: Interface) -> str:
    """Text of ``fmu_vars.h``: the one include that picks the model's variable table."""
    return (f"/* fmu_vars.h -- the variable table this FMU is built with (written by "
            f"fmu_src.fmu_build). */\n#include \"{iface.header}\"\n")


def c_name(name: str) -> str:
    """A variable name as a C macro suffix (letters, digits, underscores, upper case)."""
    return "".join(c if c.isalnum() else "_" for c in name).upper()


def render_vr_header(iface: Interface = DAMPER) -> str:
    """Text of the model's C header (``fmu_src/fmi/<iface.header>``): the C view of its table."""
    guard = c_name(iface.header)
    variables = iface.variables
    lines = [
        f"/* {iface.header} -- GENERATED by `python -m fmu_src.fmu_build --write-header`",
        " * from the variable table in fmu_src/fmu_xml.py. Do not edit: a test",
        " * checks this file equals the generated text. */",
        f"#ifndef {guard}", f"#define {guard}", "",
        f'#define DAMPER_MODEL_IDENTIFIER "{iface.model_identifier}"',
        f'#define DAMPER_TOKEN "{instantiation_token(iface)}"',
        f"#define DAMPER_N_VARIABLES {len(variables)}",
        f"#define DAMPER_FEEDTHROUGH {int(iface.feedthrough)}"
        "  /* outputs depend on the current inputs */",
        f"#define DAMPER_DIRECTIONAL {int(iface.directional)}"
        "  /* directional derivatives provided */",
        f"#define DAMPER_INTERPOLATES {int(iface.interpolates)}"
        "  /* FMI 2 input derivatives accepted */", "",
        "/* value references */",
    ]
    lines += [f"#define VR_{c_name(v.name)} {v.vr}" for v in variables]
    lines += ["", "typedef enum { CAUS_INDEPENDENT, CAUS_INPUT, CAUS_OUTPUT, CAUS_PARAMETER }"
              " damper_causality;",
              "typedef enum { " + ", ".join(f"START_{r.upper()}" for r in iface.start_rules)
              + " } damper_start_rule;", "",
              "/* causality and start rule of each value reference */",
              "static const damper_causality damper_causality_of[DAMPER_N_VARIABLES] = {"]
    lines += [f"    CAUS_{v.causality.upper()},  /* {v.name} */" for v in variables]
    lines += ["};", "static const damper_start_rule damper_start_of[DAMPER_N_VARIABLES] = {"]
    lines += [f"    START_{v.start.upper()},  /* {v.name} */" for v in variables]
    lines += ["};", "static const char *const damper_name_of[DAMPER_N_VARIABLES] = {"]
    lines += [f'    "{escape(v.name)}",' for v in variables]
    lines += ["};", "/* start values of rule value (0 for the others) */",
              "static const double damper_start_value[DAMPER_N_VARIABLES] = {"]
    lines += [f"    {_fmt(v.value if v.start == 'value' else 0.0)},  /* {v.name} */"
              for v in variables]
    lines += ["};", "static const char *const damper_unit_of[DAMPER_N_VARIABLES] = {"]
    lines += [f'    "{escape(v.unit)}",' for v in variables]
    lines += ["};", "", "/* value references of the inputs and of the outputs */"]
    for caus in ("input", "output"):
        vrs = [str(v.vr) for v in iface.by_causality(caus)]
        lines += [f"#define DAMPER_N_{caus.upper()}S {len(vrs)}",
                  f"static const unsigned int damper_{caus}s[DAMPER_N_{caus.upper()}S] = "
                  "{" + ", ".join(vrs) + "};"]
    lines += ["", "/* log categories */",
              f"#define DAMPER_N_LOG_CATEGORIES {len(LOG_CATEGORIES)}",
              "static const char *const damper_log_categories[DAMPER_N_LOG_CATEGORIES] = {"]
    lines += [f'    "{n}",' for n, _ in LOG_CATEGORIES]
    lines += ["};", "", f"#endif /* {guard} */", ""]
    return "\n".join(lines)
