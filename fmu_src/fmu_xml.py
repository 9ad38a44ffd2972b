"""The interface of the friction-element FMU, written once: the variable table.

Everything the FMI side needs to agree on comes from :data:`VARIABLES`: the
``modelDescription.xml`` of FMI 2.0 and of FMI 3.0, the FMI 3 build description,
and the C header ``fmu_src/fmi/damper_vr.h`` (value references, causalities, start
rules and the instantiation token). The header is committed; a test checks that it
equals :func:`render_vr_header` (regenerate with ``python -m fmu_src.fmu_build
--write-header``). Nothing is kept in sync by hand.

Symbols: u relative tangential displacement [m], N normal load [N], F friction
force [N], kt tangent stiffness dF/du [N/m], W dissipated energy [J], slip slip
fraction [-], N_ref normal load of the virgin curve [N].
"""
from __future__ import annotations

import hashlib
import uuid
from dataclasses import dataclass
from xml.sax.saxutils import escape, quoteattr

#: Model identifier: the binary is ``binaries/<platform>/<MODEL_IDENTIFIER>.so``.
MODEL_IDENTIFIER = "damper"

#: Start rules shared by XML and C: where a variable's start value comes from.
START_RULES = ("none", "zero", "one", "curve_n")

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
    start: str          # one of START_RULES
    description: str


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


def fmi2_variables() -> tuple[Variable, ...]:
    """The FMI 2 ModelVariables: all but the independent ``time``.

    FMI 2 does not require an independent variable, and FMI Library before 2.0.3
    (libcosim) logs "Start attribute is required" for one without a start value.
    """
    return tuple(v for v in VARIABLES if v.causality != "independent")

#: SI decomposition of every unit used (FMI BaseUnit exponents).
UNITS = {
    "s": {"s": 1},
    "m": {"m": 1},
    "N": {"kg": 1, "m": 1, "s": -2},
    "N/m": {"kg": 1, "s": -2},
    "J": {"kg": 1, "m": 2, "s": -2},
    "1": {},
}


def by_causality(causality: str) -> list[Variable]:
    """Variables of one causality, in table order."""
    return [v for v in VARIABLES if v.causality == causality]


def instantiation_token() -> str:
    """GUID (FMI 2) / instantiation token (FMI 3): a hash of the variable table.

    The C side checks it at instantiation, so a binary built against another
    table refuses to load.
    """
    text = repr((MODEL_IDENTIFIER, VARIABLES, START_RULES))
    digest = hashlib.sha256(text.encode()).digest()[:16]
    return "{" + str(uuid.UUID(bytes=digest)) + "}"


def start_value(var: Variable, curve_n: float) -> float | None:
    """Numeric start value of ``var`` for an FMU whose curve was computed at ``curve_n``."""
    return {"none": None, "zero": 0.0, "one": 1.0, "curve_n": float(curve_n)}[var.start]


def _fmt(x: float) -> str:
    return repr(float(x))  # shortest repr round-trips exactly


def _units_xml() -> str:
    lines = ["  <UnitDefinitions>"]
    for name, exps in UNITS.items():
        base = " ".join(f'{k}="{v}"' for k, v in exps.items())
        inner = f"<BaseUnit {base}/>" if base else "<BaseUnit/>"
        lines.append(f"    <Unit name={quoteattr(name)}>{inner}</Unit>")
    lines.append("  </UnitDefinitions>")
    return "\n".join(lines)


def _log_categories_xml() -> str:
    items = "".join(f"\n    <Category name={quoteattr(n)} description={quoteattr(d)}/>"
                    for n, d in LOG_CATEGORIES)
    return f"  <LogCategories>{items}\n  </LogCategories>"


def _bound_attrs(var: Variable, u_bound: float | None) -> str:
    """min/max of the displacement input: the FMU refuses |u| beyond the bound."""
    if var.name != "u" or u_bound is None or not u_bound < float("inf"):
        return ""
    return f' min="{_fmt(-u_bound)}" max="{_fmt(u_bound)}"'


def _variable_attrs(var: Variable) -> str:
    attrs = (f"name={quoteattr(var.name)} valueReference=\"{var.vr}\" "
             f"causality=\"{var.causality}\" variability=\"{var.variability}\"")
    if var.causality == "parameter":
        attrs += ' initial="exact"'
    return attrs + f" description={quoteattr(var.description)}"


def _fmi2_variables(curve_n: float, u_bound: float | None) -> str:
    out = ["  <ModelVariables>"]
    for i, var in enumerate(fmi2_variables(), start=1):
        start = start_value(var, curve_n)
        real = f"<Real unit={quoteattr(var.unit)}" + _bound_attrs(var, u_bound)
        real += f' start="{_fmt(start)}"/>' if start is not None else "/>"
        out.append(f"    <!-- index {i} -->")
        out.append(f"    <ScalarVariable {_variable_attrs(var)}>\n      {real}\n"
                   f"    </ScalarVariable>")
    out.append("  </ModelVariables>")
    return "\n".join(out)


def _fmi3_variables(curve_n: float, u_bound: float | None) -> str:
    out = ["  <ModelVariables>"]
    for var in VARIABLES:
        start = start_value(var, curve_n)
        attrs = _variable_attrs(var) + f" unit={quoteattr(var.unit)}" + _bound_attrs(var, u_bound)
        if start is not None:
            attrs += f' start="{_fmt(start)}"'
        out.append(f"    <Float64 {attrs}/>")
    out.append("  </ModelVariables>")
    return "\n".join(out)


def _structure(fmi_version: int) -> str:
    """ModelStructure: every output depends directly on both inputs (feedthrough).

    During initialization the outputs also depend on the parameters (knowns with
    initial="exact"). FMI 2 dependencies are 1-based indices into the FMI 2 ModelVariables;
    FMI 3 dependencies are value references.
    """
    inputs = by_causality("input")
    knowns = inputs + by_causality("parameter")
    outputs = by_causality("output")
    if fmi_version == 2:
        index = {v.vr: i for i, v in enumerate(fmi2_variables(), start=1)}
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


def render_model_description(fmi_version: int, curve_n: float, source_files: list[str],
                             description: str, u_bound: float | None = None) -> str:
    """Text of ``modelDescription.xml`` for FMI 2.0 or 3.0 (co-simulation).

    Parameters
    ----------
    fmi_version : {2, 3}
    curve_n : float
        Normal load of the packaged curve [N] (start of ``N`` and ``N_ref``).
    source_files : list of str
        C files of the source FMU (FMI 2 ``<SourceFiles>``; FMI 3 uses
        :func:`render_build_description` instead).
    description : str
        Free text (curve provenance).
    u_bound : float, optional
        Largest |u| the FMU accepts [m] (``min``/``max`` of the input ``u``).
    """
    token = instantiation_token()
    common = (f'modelName="damper friction element" description={quoteattr(description)} '
              f'generationTool="damper-toolkit fmu_src.fmu_build" variableNamingConvention="flat"')
    if fmi_version == 2:
        files = "".join(f'\n      <File name={quoteattr(f)}/>' for f in source_files)
        head = (f'<fmiModelDescription fmiVersion="2.0" {common} guid="{token}" '
                f'numberOfEventIndicators="0">\n'
                f'  <CoSimulation modelIdentifier="{MODEL_IDENTIFIER}" '
                'canHandleVariableCommunicationStepSize="true" canInterpolateInputs="true" '
                'maxOutputDerivativeOrder="0" canGetAndSetFMUstate="true" '
                'canSerializeFMUstate="true" providesDirectionalDerivative="true" '
                'canNotUseMemoryManagementFunctions="true" '
                'canBeInstantiatedOnlyOncePerProcess="false">\n'
                f'    <SourceFiles>{files}\n    </SourceFiles>\n  </CoSimulation>')
        variables = _fmi2_variables(curve_n, u_bound)
    elif fmi_version == 3:
        head = (f'<fmiModelDescription fmiVersion="3.0" {common} '
                f'instantiationToken="{token}">\n'
                f'  <CoSimulation modelIdentifier="{MODEL_IDENTIFIER}" '
                'canHandleVariableCommunicationStepSize="true" canGetAndSetFMUState="true" '
                'canSerializeFMUState="true" providesDirectionalDerivatives="true" '
                'providesAdjointDerivatives="false" hasEventMode="false" '
                'canBeInstantiatedOnlyOncePerProcess="false"/>')
        variables = _fmi3_variables(curve_n, u_bound)
    else:
        raise ValueError(f"fmi_version must be 2 or 3, not {fmi_version!r}")
    parts = ['<?xml version="1.0" encoding="UTF-8"?>', head, _units_xml(),
             _log_categories_xml(),
             '  <DefaultExperiment startTime="0" stopTime="1"/>',
             variables, _structure(fmi_version), "</fmiModelDescription>", ""]
    return "\n".join(parts)


def render_build_description(source_files: list[str]) -> str:
    """Text of the FMI 3 ``sources/buildDescription.xml`` (paths relative to sources/)."""
    files = "".join(f"\n      <SourceFile name={quoteattr(f)}/>" for f in source_files)
    return ('<?xml version="1.0" encoding="UTF-8"?>\n<fmiBuildDescription fmiVersion="3.0">\n'
            f'  <BuildConfiguration modelIdentifier="{MODEL_IDENTIFIER}">\n'
            f'    <SourceFileSet language="C99">{files}\n    </SourceFileSet>\n'
            "  </BuildConfiguration>\n</fmiBuildDescription>\n")


def render_vr_header() -> str:
    """Text of ``fmu_src/fmi/damper_vr.h``: the C view of :data:`VARIABLES`."""
    lines = [
        "/* damper_vr.h -- GENERATED by `python -m fmu_src.fmu_build --write-header`",
        " * from the variable table fmu_src/fmu_xml.py:VARIABLES. Do not edit: a test",
        " * checks this file equals the generated text. */",
        "#ifndef DAMPER_VR_H", "#define DAMPER_VR_H", "",
        f'#define DAMPER_MODEL_IDENTIFIER "{MODEL_IDENTIFIER}"',
        f'#define DAMPER_TOKEN "{instantiation_token()}"',
        f"#define DAMPER_N_VARIABLES {len(VARIABLES)}", "",
        "/* value references */",
    ]
    lines += [f"#define VR_{v.name.upper()} {v.vr}" for v in VARIABLES]
    lines += ["", "typedef enum { CAUS_INDEPENDENT, CAUS_INPUT, CAUS_OUTPUT, CAUS_PARAMETER }"
              " damper_causality;",
              "typedef enum { " + ", ".join(f"START_{r.upper()}" for r in START_RULES)
              + " } damper_start_rule;", "",
              "/* causality and start rule of each value reference */",
              "static const damper_causality damper_causality_of[DAMPER_N_VARIABLES] = {"]
    lines += [f"    CAUS_{v.causality.upper()},  /* {v.name} */" for v in VARIABLES]
    lines += ["};", "static const damper_start_rule damper_start_of[DAMPER_N_VARIABLES] = {"]
    lines += [f"    START_{v.start.upper()},  /* {v.name} */" for v in VARIABLES]
    lines += ["};", "static const char *const damper_name_of[DAMPER_N_VARIABLES] = {"]
    lines += [f'    "{escape(v.name)}",' for v in VARIABLES]
    lines += ["};", "", "/* value references of the inputs and of the outputs */"]
    for caus in ("input", "output"):
        vrs = [str(v.vr) for v in by_causality(caus)]
        lines += [f"#define DAMPER_N_{caus.upper()}S {len(vrs)}",
                  f"static const unsigned int damper_{caus}s[DAMPER_N_{caus.upper()}S] = "
                  "{" + ", ".join(vrs) + "};"]
    lines += ["", "/* log categories */",
              f"#define DAMPER_N_LOG_CATEGORIES {len(LOG_CATEGORIES)}",
              "static const char *const damper_log_categories[DAMPER_N_LOG_CATEGORIES] = {"]
    lines += [f'    "{n}",' for n, _ in LOG_CATEGORIES]
    lines += ["};", "", "#endif /* DAMPER_VR_H */", ""]
    return "\n".join(lines)
