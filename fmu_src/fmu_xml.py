"""The interface of an FMU model, written once: its variable table.

Everything the FMI side needs to agree on comes from an :class:`Interface` (the
friction element's is :data:`IWAN`, its variables :data:`VARIABLES`): the
``modelDescription.xml`` of FMI 2.0 and of FMI 3.0, the FMI 3 build description,
and the C header ``damper_vr.h`` (value references, causalities, start rules and
values, the instantiation token). The friction element's header is committed as
``fmu_src/fmi/damper_vr.h``; a test checks that it equals :func:`render_vr_header`
(regenerate with ``python -m fmu_src.fmu_build --write-header``). Models whose
variables depend on their data (a blade's named DOFs) get the header generated into
the FMU's ``sources/`` at build time. Nothing is kept in sync by hand.

Symbols of the friction element: u relative tangential displacement [m], N normal
load [N], F friction force [N], kt tangent stiffness dF/du [N/m], W dissipated energy
[J], slip slip fraction [-], N_ref normal load of the virgin curve [N].
"""
from __future__ import annotations

import hashlib
import uuid
from dataclasses import dataclass, field
from xml.sax.saxutils import escape, quoteattr

#: Model identifier of the friction element: its binary is ``binaries/<platform>/damper.so``.
MODEL_IDENTIFIER = "damper"

#: Start rules shared by XML and C: where a variable's start value comes from.
#: ``model``: from the model's resources (``model_start`` in C, ``starts`` in Python);
#: ``value``: the number in the variable table (compiled into the header).
START_RULES = ("none", "zero", "one", "model", "value")

#: FMI log categories the FMU declares (and accepts in SetDebugLogging).
LOG_CATEGORIES = (
    ("logStatusError", "Errors: rejected inputs, calls in a wrong state, bad resources"),
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
    value: float = 0.0  # the start value of rule "value"


@dataclass(frozen=True)
class Interface:
    """The variable table of one FMU model and its capabilities.

    Attributes
    ----------
    identifier : str          model identifier (binary name, C prefix of nothing)
    name : str                modelName
    variables : tuple of Variable, value reference = position
    feedthrough : bool        outputs depend on the current inputs (ModelStructure)
    directional : bool        provides directional derivatives
    interpolates : bool       accepts FMI 2 input derivatives (order 1)
    """

    identifier: str
    name: str
    variables: tuple
    feedthrough: bool = True
    directional: bool = True
    interpolates: bool = True
    units: dict = field(default_factory=dict)

    def by_causality(self, causality: str) -> list[Variable]:
        """Variables of one causality, in table order."""
        return [v for v in self.variables if v.causality == causality]

    def fmi2_variables(self) -> tuple:
        """The FMI 2 ModelVariables: all but the independent ``time``.

        FMI 2 does not require an independent variable, and FMI Library before 2.0.3
        (libcosim) logs "Start attribute is required" for one without a start value.
        """
        return tuple(v for v in self.variables if v.causality != "independent")

    def all_units(self) -> dict:
        """SI decomposition of every unit the variables use."""
        out = dict(UNITS)
        out.update(self.units)
        missing = {v.unit for v in self.variables} - set(out)
        if missing:
            raise ValueError(f"units without a definition: {sorted(missing)}")
        return {u: out[u] for u in dict.fromkeys(v.unit for v in self.variables)}


#: The FMU's variables, in ModelVariables order (value reference = position).
VARIABLES: tuple[Variable, ...] = (
    Variable("time", 0, "independent", "continuous", "s", "none", "Simulation time"),
    Variable("u", 1, "input", "continuous", "m", "zero",
             "Relative tangential displacement of the contact"),
    Variable("N", 2, "input", "continuous", "N", "model",
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
    Variable("N_ref", 8, "parameter", "fixed", "N", "model",
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
}


#: The friction element (``damper fmu``).
IWAN = Interface(MODEL_IDENTIFIER, "damper friction element", VARIABLES)


def fmi2_variables(interface: Interface = IWAN) -> tuple:
    """The FMI 2 ModelVariables of ``interface`` (:meth:`Interface.fmi2_variables`)."""
    return interface.fmi2_variables()


def by_causality(causality: str, interface: Interface = IWAN) -> list[Variable]:
    """Variables of one causality, in table order."""
    return interface.by_causality(causality)


def instantiation_token(interface: Interface = IWAN) -> str:
    """GUID (FMI 2) / instantiation token (FMI 3): a hash of the variable table.

    The C side checks it at instantiation, so a binary built against another
    table refuses to load.
    """
    text = repr((interface.identifier, interface.variables, START_RULES,
                 interface.feedthrough, interface.directional, interface.interpolates))
    digest = hashlib.sha256(text.encode()).digest()[:16]
    return "{" + str(uuid.UUID(bytes=digest)) + "}"


def start_value(var: Variable, starts) -> float | None:
    """Numeric start value of ``var``; ``starts`` gives those of rule ``model``: a float
    (the friction element: the curve's normal load for N and N_ref) or a dict by name."""
    if var.start == "model":
        return float(starts[var.name] if isinstance(starts, dict) else starts)
    return {"none": None, "zero": 0.0, "one": 1.0, "value": var.value}[var.start]


def _fmt(x: float) -> str:
    return repr(float(x))  # shortest repr round-trips exactly


def _units_xml(interface: Interface) -> str:
    lines = ["  <UnitDefinitions>"]
    for name, exps in interface.all_units().items():
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
    """min/max of an input the FMU refuses beyond a bound (``bounds``: name -> bound)."""
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


def _fmi2_variables(interface: Interface, starts, bounds: dict) -> str:
    out = ["  <ModelVariables>"]
    for i, var in enumerate(interface.fmi2_variables(), start=1):
        start = start_value(var, starts)
        real = f"<Real unit={quoteattr(var.unit)}" + _bound_attrs(var, bounds)
        real += f' start="{_fmt(start)}"/>' if start is not None else "/>"
        out.append(f"    <!-- index {i} -->")
        out.append(f"    <ScalarVariable {_variable_attrs(var)}>\n      {real}\n"
                   f"    </ScalarVariable>")
    out.append("  </ModelVariables>")
    return "\n".join(out)


def _fmi3_variables(interface: Interface, starts, bounds: dict) -> str:
    out = ["  <ModelVariables>"]
    for var in interface.variables:
        start = start_value(var, starts)
        attrs = _variable_attrs(var) + f" unit={quoteattr(var.unit)}" + _bound_attrs(var, bounds)
        if start is not None:
            attrs += f' start="{_fmt(start)}"'
        out.append(f"    <Float64 {attrs}/>")
    out.append("  </ModelVariables>")
    return "\n".join(out)


def _structure(fmi_version: int, interface: Interface) -> str:
    """ModelStructure: with direct feedthrough every output depends on every input,
    without it on none (the outputs are the state at the communication point).

    During initialization the outputs also depend on the parameters (knowns with
    initial="exact"). FMI 2 dependencies are 1-based indices into the FMI 2 ModelVariables;
    FMI 3 dependencies are value references.
    """
    inputs = interface.by_causality("input") if interface.feedthrough else []
    knowns = inputs + interface.by_causality("parameter")
    outputs = interface.by_causality("output")
    if fmi_version == 2:
        index = {v.vr: i for i, v in enumerate(interface.fmi2_variables(), start=1)}
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


def render_model_description(fmi_version: int, starts, source_files: list[str],
                             description: str, u_bound: float | None = None,
                             interface: Interface = IWAN, bounds: dict | None = None) -> str:
    """Text of ``modelDescription.xml`` for FMI 2.0 or 3.0 (co-simulation).

    Parameters
    ----------
    fmi_version : {2, 3}
    starts : float or dict
        Start values of the variables of rule ``model`` (:func:`start_value`): for the
        friction element the normal load of the packaged curve [N] (``N``, ``N_ref``).
    source_files : list of str
        C files of the source FMU (FMI 2 ``<SourceFiles>``; FMI 3 uses
        :func:`render_build_description` instead).
    description : str
        Free text (provenance).
    u_bound : float, optional
        Largest |u| the friction element accepts [m] (``min``/``max`` of the input ``u``).
    interface : Interface
        The model's variable table (default: the friction element).
    bounds : dict, optional
        Other inputs' bounds by name (``min``/``max``).
    """
    bounds = dict(bounds or {})
    if u_bound is not None:
        bounds["u"] = u_bound
    token = instantiation_token(interface)
    ident, it = interface.identifier, interface
    common = (f'modelName={quoteattr(interface.name)} description={quoteattr(description)} '
              f'generationTool="damper-toolkit fmu_src.fmu_build" variableNamingConvention="flat"')
    if fmi_version == 2:
        files = "".join(f'\n      <File name={quoteattr(f)}/>' for f in source_files)
        head = (f'<fmiModelDescription fmiVersion="2.0" {common} guid="{token}" '
                f'numberOfEventIndicators="0">\n'
                f'  <CoSimulation modelIdentifier="{ident}" '
                'canHandleVariableCommunicationStepSize="true" '
                f'canInterpolateInputs="{_flag(it.interpolates)}" '
                'maxOutputDerivativeOrder="0" canGetAndSetFMUstate="true" '
                'canSerializeFMUstate="true" '
                f'providesDirectionalDerivative="{_flag(it.directional)}" '
                'canNotUseMemoryManagementFunctions="true" '
                'canBeInstantiatedOnlyOncePerProcess="false">\n'
                f'    <SourceFiles>{files}\n    </SourceFiles>\n  </CoSimulation>')
        variables = _fmi2_variables(interface, starts, bounds)
    elif fmi_version == 3:
        head = (f'<fmiModelDescription fmiVersion="3.0" {common} '
                f'instantiationToken="{token}">\n'
                f'  <CoSimulation modelIdentifier="{ident}" '
                'canHandleVariableCommunicationStepSize="true" canGetAndSetFMUState="true" '
                'canSerializeFMUState="true" '
                f'providesDirectionalDerivatives="{_flag(it.directional)}" '
                'providesAdjointDerivatives="false" hasEventMode="false" '
                'canBeInstantiatedOnlyOncePerProcess="false"/>')
        variables = _fmi3_variables(interface, starts, bounds)
    else:
        raise ValueError(f"fmi_version must be 2 or 3, not {fmi_version!r}")
    parts = ['<?xml version="1.0" encoding="UTF-8"?>', head, _units_xml(interface),
             _log_categories_xml(),
             '  <DefaultExperiment startTime="0" stopTime="1"/>',
             variables, _structure(fmi_version, interface), "</fmiModelDescription>", ""]
    return "\n".join(parts)


def render_build_description(source_files: list[str], identifier: str = MODEL_IDENTIFIER) -> str:
    """Text of the FMI 3 ``sources/buildDescription.xml`` (paths relative to sources/)."""
    files = "".join(f"\n      <SourceFile name={quoteattr(f)}/>" for f in source_files)
    return ('<?xml version="1.0" encoding="UTF-8"?>\n<fmiBuildDescription fmiVersion="3.0">\n'
            f'  <BuildConfiguration modelIdentifier="{identifier}">\n'
            f'    <SourceFileSet language="C99">{files}\n    </SourceFileSet>\n'
            "  </BuildConfiguration>\n</fmiBuildDescription>\n")


def _c_name(name: str) -> str:
    """A variable name as a C macro suffix (letters, digits, underscores, upper case)."""
    return "".join(c if c.isalnum() else "_" for c in name).upper()


def render_vr_header(interface: Interface = IWAN) -> str:
    """Text of ``damper_vr.h``: the C view of ``interface`` (the committed
    ``fmu_src/fmi/damper_vr.h`` is the friction element's)."""
    variables = interface.variables
    lines = [
        "/* damper_vr.h -- GENERATED by `python -m fmu_src.fmu_build --write-header`",
        " * from the variable table fmu_src/fmu_xml.py:VARIABLES (or, in an FMU's sources,",
        " * from its model's table). Do not edit: a test checks the committed file equals",
        " * the generated text. */",
        "#ifndef DAMPER_VR_H", "#define DAMPER_VR_H", "",
        f'#define DAMPER_MODEL_IDENTIFIER "{interface.identifier}"',
        f'#define DAMPER_TOKEN "{instantiation_token(interface)}"',
        f"#define DAMPER_N_VARIABLES {len(variables)}",
        f"#define DAMPER_FEEDTHROUGH {int(interface.feedthrough)}"
        "  /* outputs depend on the current inputs */",
        f"#define DAMPER_DIRECTIONAL {int(interface.directional)}"
        "  /* directional derivatives provided */",
        f"#define DAMPER_INTERPOLATES {int(interface.interpolates)}"
        "  /* FMI 2 input derivatives accepted */", "",
        "/* value references */",
    ]
    lines += [f"#define VR_{_c_name(v.name)} {v.vr}" for v in variables]
    lines += ["", "typedef enum { CAUS_INDEPENDENT, CAUS_INPUT, CAUS_OUTPUT, CAUS_PARAMETER }"
              " damper_causality;",
              "typedef enum { " + ", ".join(f"START_{r.upper()}" for r in START_RULES)
              + " } damper_start_rule;", "",
              "/* causality, start rule and start value (rule START_VALUE) of each value reference */",
              "static const damper_causality damper_causality_of[DAMPER_N_VARIABLES] = {"]
    lines += [f"    CAUS_{v.causality.upper()},  /* {v.name} */" for v in variables]
    lines += ["};", "static const damper_start_rule damper_start_of[DAMPER_N_VARIABLES] = {"]
    lines += [f"    START_{v.start.upper()},  /* {v.name} */" for v in variables]
    lines += ["};", "static const double damper_start_value[DAMPER_N_VARIABLES] = {"]
    lines += [f"    {_fmt(v.value if v.start == 'value' else 0.0)},  /* {v.name} */"
              for v in variables]
    lines += ["};", "static const char *const damper_name_of[DAMPER_N_VARIABLES] = {"]
    lines += [f'    "{escape(v.name)}",' for v in variables]
    lines += ["};", "", "/* value references of the inputs and of the outputs */"]
    for caus in ("input", "output"):
        vrs = [str(v.vr) for v in interface.by_causality(caus)]
        lines += [f"#define DAMPER_N_{caus.upper()}S {len(vrs)}",
                  f"static const unsigned int damper_{caus}s[DAMPER_N_{caus.upper()}S] = "
                  "{" + ", ".join(vrs) + "};"]
    lines += ["", "/* log categories */",
              f"#define DAMPER_N_LOG_CATEGORIES {len(LOG_CATEGORIES)}",
              "static const char *const damper_log_categories[DAMPER_N_LOG_CATEGORIES] = {"]
    lines += [f'    "{n}",' for n, _ in LOG_CATEGORIES]
    lines += ["};", "", "#endif /* DAMPER_VR_H */", ""]
    return "\n".join(lines)
