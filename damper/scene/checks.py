"""Scene checks that need the libraries, run with the schema's before any stage runs.

What a stage would otherwise refuse only when it runs, after the stages upstream of
it (with the output folder half written), is checked here, each problem named by its
key: a contact the FE model cannot represent (``contact_core.spec``: grid, zone,
load against the body size), a loop force amplitude at or above the contact's
gross-slip force mu N, a matrices file that does not read or holds a bad model
(``harmonic_balance.model.load_matrices``: finite, symmetric, M positive
definite), element DOFs or a backbone mode outside the model, an empty excitation
list for a forced response, and a UPD model file that does not load.
"""
from __future__ import annotations

import re

from . import schema


def check_contacts(data: dict, problems: list) -> None:
    """Each contact's FE specification and its normal load, as the stages will build them."""
    from damper.run.contact_stages import contact_spec

    for name, c in data.get("contact", {}).items():
        path = ("contact", name)
        try:
            spec = contact_spec(c)
        except ValueError as err:
            problems.append((path, str(err)))
            continue
        try:
            spec.kind.check_load(spec, c["force"])
        except ValueError as err:
            problems.append((path + ("force",), str(err)))


def check_element(data: dict, problems: list) -> None:
    """The loop's force amplitude below the gross-slip force mu N of the element's contact.

    The virgin curve of a contact under the constant normal force N ends at T = mu N
    (gross slip), so no steady loop exists at or above that amplitude.
    """
    el, contacts = data.get("element"), data.get("contact", {})
    if not el or "loop_force_amplitude" not in el or el["contact"] not in contacts:
        return
    c = contacts[el["contact"]]
    if "mu" not in c:
        return
    limit = c["mu"] * c["force"]
    amp = el["loop_force_amplitude"]
    if amp >= limit:
        problems.append((("element", "loop_force_amplitude"),
                         f"{amp:g} N is not below the gross-slip force mu N = {c['mu']:g} x {c['force']:g} N "
                         f"= {limit:g} N of contact {el['contact']!r}: no steady loop (the contact slides); "
                         f"give an amplitude below {limit:g} N"))


def structure_size(data: dict, problems: list) -> int | None:
    """DOFs of the scene's structure (reading a matrices file once, with its checks); None if unknown."""
    s = data.get("structure")
    if s is None:
        return None
    if s["model"] == "two_dof":
        return 2
    if "matrices_sha256" not in s:           # unreadable: already reported
        return None
    from harmonic_balance.model import load_matrices

    try:
        lin, _, _ = load_matrices(s["matrices"])
    except ValueError as err:
        problems.append((("structure", "matrices"), str(err)))
        return None
    n = lin.n
    dofs = s.get("element_dofs", [])
    bad = [d for d in dofs if d >= n]
    if bad:
        problems.append((("structure", "element_dofs"), f"DOF {bad[0]} outside the model's 0..{n - 1} "
                         f"({s['matrices']} has {n} DOFs)"))
    if len(dofs) == 2 and dofs[0] == dofs[1]:
        problems.append((("structure", "element_dofs"), f"[{dofs[0]}, {dofs[1]}] joins a DOF to itself; "
                         "give two different DOFs, or [a] for a link to the ground"))
    return n


def check_response(data: dict, problems: list) -> None:
    """Forced response and backbone inputs that depend on the structure's size."""
    wants = data["want"]
    n = structure_size(data, problems) if ("frf" in wants or "backbone" in wants) else None
    ex = data.get("excitation")
    if "frf" in wants and ex is not None:
        forces = ex["forces"]
        if not forces:
            problems.append((("excitation", "forces"), "empty: frf needs at least one force amplitude "
                             "(one forced response each)"))
        elif len(forces) > schema.limits.MAX_FORCE_LEVELS:
            problems.append((("excitation", "forces"), f"{len(forces)} levels is above the limit "
                             f"{schema.limits.MAX_FORCE_LEVELS}: each is a whole forced response"))
    bb = data.get("backbone")
    if "backbone" in wants and bb is not None and n is not None and bb["mode"] >= n:
        problems.append((("backbone", "mode"), f"mode {bb['mode']} of a structure with {n} DOFs "
                         f"(modes 0..{n - 1})"))


def check_upd(data: dict, problems: list) -> None:
    """The [upd] model file loads (its own checks: sections, keys, values)."""
    u = data.get("upd")
    if u is None or "config" not in u or "config_sha256" not in u:
        return
    from harmonic_balance.bladed_disk.config import load_config

    try:
        load_config(u["config"])
    except ValueError as err:
        problems.append((("upd", "config"), str(err)))


def check_upd_contacts(data: dict, problems: list) -> None:
    """Contacts other than the TOML's, checked on the model before any stage: its geometry
    (``damper.upd_geometry.geometry_params``: a [geometry] section, mu > 0), and for surfaces a
    planar sector, the faces' specifications and the node-DOF model's harmonic-balance unknowns
    within their limit (``damper.upd_surface.check_unknowns``, counted on the faces' meshes); for
    optimal_load's walk the faces at both ends of ``cf_range``, as ``upd optimize`` checks them."""
    u = data.get("upd")
    if u is None or u["contacts"] == "toml" or any(path[:1] == ("upd",) for path, _ in problems):
        return
    from damper.upd_frf import options, upd_sector
    from damper.upd_geometry import geometry_params
    from damper.upd_surface import check_unknowns, face_specs
    from harmonic_balance.bladed_disk.surface_hb import face_inputs

    key = "contacts"
    try:
        sector = upd_sector(options(config=u.get("config")))
        geometry_params(sector.cfg, u.get("cf"))
        if u["contacts"] == "surface" and {"upd_frf", "optimal_load"} & set(data["want"]):
            face_inputs(sector, "left")
        if u["contacts"] == "surface" and "upd_frf" in data["want"]:
            face_specs(sector.cfg, u["surface_nodes"], u.get("cf"))
            key = "surface_nodes"
            if u["surface_model"] == "nodes":
                check_unknowns(sector, u["surface_nodes"], u["harmonics"], u.get("cf"))
        if u["contacts"] == "surface" and "optimal_load" in data["want"]:
            key = "cf_range"
            for cf in u["cf_range"]:   # damper.upd_surface.optimize_record's check, before the stage
                face_specs(sector.cfg, u["surface_nodes"], cf)
    except ValueError as err:   # the command's message, its options named as the scene's keys
        msg = re.sub(r"--([a-z-]+) (\d+|nodes|condensed|toml|geometry|surface)\b",
                     lambda m: f"{m[1]} = {m[2]}", str(err))
        msg = re.sub(r"--([a-z-]+)", lambda m: m[1], msg).replace("surface-", "surface_")
        problems.append((("upd", key), msg))
