"""A small SSP 1.0 writer: ``SystemStructure.ssd`` with FMU components, their connectors,
parameter bindings and connections, zipped with the FMUs into one ``.ssp`` archive.

Only what a co-simulation of FMUs needs (SSP 1.0, "System Structure and Parameterization",
Modelica Association): one ``ssd:System`` of ``ssd:Component`` elements (source
``resources/<file>.fmu``), ``ssd:Connectors`` (kind input / output / parameter, type
``ssc:Real``), inline ``ssd:ParameterBindings`` (an ``ssv:ParameterSet``), ``ssd:Connections``
and a ``ssd:DefaultExperiment`` carrying the Open Simulation Platform's fixed-step
annotation (libcosim reads its ``baseStepSize``). Extra files (e.g. a JSON description)
go under ``resources/`` too.
"""
from __future__ import annotations

import io
import os
import zipfile
from dataclasses import dataclass, field
from pathlib import Path
from xml.sax.saxutils import quoteattr

from contact_core.fileio import atomic_write

NS = {"ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
      "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
      "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
      "osp": "http://opensimulationplatform.com/SSP/OSPAnnotations"}


@dataclass
class Component:
    """One FMU instance: its name, the FMU file name under ``resources/``, connectors
    (name -> kind: input / output / parameter) and parameter values (name -> float)."""

    name: str
    fmu: str
    connectors: dict = field(default_factory=dict)
    parameters: dict = field(default_factory=dict)


def _component_xml(c: Component) -> str:
    lines = [f'      <ssd:Component name={quoteattr(c.name)} source="resources/{c.fmu}" '
             'type="application/x-fmu-sharedlibrary">', "        <ssd:Connectors>"]
    lines += [f"          <ssd:Connector name={quoteattr(n)} kind={quoteattr(k)}><ssc:Real/>"
              "</ssd:Connector>" for n, k in c.connectors.items()]
    lines.append("        </ssd:Connectors>")
    if c.parameters:
        lines += ["        <ssd:ParameterBindings>", "          <ssd:ParameterBinding>",
                  "            <ssd:ParameterValues>",
                  f'              <ssv:ParameterSet version="1.0" name={quoteattr(c.name)}>',
                  "                <ssv:Parameters>"]
        lines += [f"                  <ssv:Parameter name={quoteattr(n)}><ssv:Real "
                  f'value="{float(v)!r}"/></ssv:Parameter>' for n, v in c.parameters.items()]
        lines += ["                </ssv:Parameters>", "              </ssv:ParameterSet>",
                  "            </ssd:ParameterValues>", "          </ssd:ParameterBinding>",
                  "        </ssd:ParameterBindings>"]
    lines.append("      </ssd:Component>")
    return "\n".join(lines)


def ssd_text(name: str, components: list[Component], connections: list[tuple],
             step: float, stop_time: float, description: str = "") -> str:
    """Text of ``SystemStructure.ssd``.

    Parameters
    ----------
    name : str                    system name
    components : list of Component
    connections : list of (start component, start connector, end component, end connector)
    step : float                  fixed communication step [s] (OSP annotation)
    stop_time : float             default stop time [s]
    """
    names = {c.name: c for c in components}
    for a, ca, b, cb in connections:
        for comp, con, kind in ((a, ca, "output"), (b, cb, "input")):
            if comp not in names or names[comp].connectors.get(con) != kind:
                raise ValueError(f"SSP connection {a}.{ca} -> {b}.{cb}: {comp}.{con} is not an "
                                 f"{kind} connector")
    ns = " ".join(f'xmlns:{k}="{v}"' for k, v in NS.items())
    conns = "\n".join(f"      <ssd:Connection startElement={quoteattr(a)} startConnector="
                      f"{quoteattr(ca)} endElement={quoteattr(b)} endConnector={quoteattr(cb)}/>"
                      for a, ca, b, cb in connections)
    return (f'<?xml version="1.0" encoding="UTF-8"?>\n<ssd:SystemStructureDescription {ns} '
            f'version="1.0" name={quoteattr(name)} generationTool="damper-toolkit damper.ssp">\n'
            f"  <ssd:System name={quoteattr(name)} description={quoteattr(description)}>\n"
            "    <ssd:Elements>\n" + "\n".join(_component_xml(c) for c in components)
            + "\n    </ssd:Elements>\n    <ssd:Connections>\n" + conns
            + "\n    </ssd:Connections>\n  </ssd:System>\n"
            f'  <ssd:DefaultExperiment startTime="0" stopTime="{float(stop_time)!r}">\n'
            "    <ssd:Annotations>\n"
            '      <ssc:Annotation type="com.opensimulationplatform">\n'
            "        <osp:Algorithm>\n"
            f'          <osp:FixedStepAlgorithm baseStepSize="{float(step)!r}"/>\n'
            "        </osp:Algorithm>\n      </ssc:Annotation>\n    </ssd:Annotations>\n"
            "  </ssd:DefaultExperiment>\n</ssd:SystemStructureDescription>\n")


def write_ssp(out: str | os.PathLike, ssd: str, resources: dict) -> Path:
    """Zip ``SystemStructure.ssd`` and ``resources/<name>`` (name -> a ``Path`` to copy,
    or the content as str / bytes) into ``out`` (atomic: a failed write leaves no file)."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("SystemStructure.ssd", ssd)
        for name, data in resources.items():
            if isinstance(data, Path):
                zf.write(data, f"resources/{name}")
            else:
                zf.writestr(f"resources/{name}", data)
    path = atomic_write(out, buf.getvalue())
    return path
