"""Contacts of the underplatform damper from its geometry (``damper upd ... --contacts geometry``).

One run goes geometry -> contact -> forced response: ``contact_core`` solves the two
contacts of the UPD model (``harmonic_balance.bladed_disk``) at their nominal normal
loads, and the results replace the TOML's Jenkins points through ``UPDConfig.contacts``:

* left, the cylinder line on blade j: a cylinder of radius R (``geometry.cylinder_radius``)
  and length L (``damper.contact_length``, axis along the disk axis) on the platform;
* right, the flat on blade j+1: a face of width W (``damper.right_width``, along the slip
  direction) and length L on the platform; the model's two end points right1 and right2
  each get half of it: k_n / 2 and the curve T / 2 at N_ref / 2 (same slip displacement).

Per contact (thesis Appendix A; ``contact_core.tangential_run.run``): the Guyan-condensed
FE bodies (cached in the application's store), the active-set normal solve at the nominal
load N_ref, k_n = dN/d(approach) there (the tangent at the load: the penalty spring of the
harmonic balance is linear, so it is exact for small changes of N about N_ref), and the
constant-normal-force tangential solve, whose virgin curve T(u) ends at gross slip T = mu N.
The curve gives k_t (its initial slope) and the Masing/Iwan element
(``IwanElement.from_virgin_curve``) whose slip strengths scale with N / N_ref, so the
friction limit follows the varying normal load; the slider stiffnesses (and k_n) stay
those of N_ref.

Nominal loads: ``geometry.normal_load_left`` and ``geometry.normal_load_flat`` [N], or
(0, the default) the frictionless static loads at the run's CF. With one face angle g on
both sides the damper's force balance gives N_L = N_R = CF / (2 cos g) for any point
positions (x: N_L sin g = N_R sin g; y: (N_L + N_R) cos g = CF); the flat's load is taken
centred on it (the moment balance may split it unevenly between its end points: not
modelled here).

The result of each contact (curve, k_n, k_t) is kept in the content-addressed store
(``damper.cache.Store``) under a key of the contact's model, load, mu and the code of
``contact_core``, so a second run neither condenses nor solves again.

Symbols: R cylinder radius, L contact length, W flat width, h damper body height above the
flat [m]; E, nu Young's modulus [Pa] and Poisson ratio; N normal load [N]; mu friction
coefficient; k_n, k_t normal / tangential contact stiffness [N/m]; u, T tangential
displacement [m] and force [N] of the virgin curve.
"""
from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np

#: Version of the cached contact entry's content (bump when it changes).
ENTRY_VERSION = 2
#: The cylinder's potential contact zone holds the 2D Hertz contact of this many times its
#: nominal load (plus contact_core's margins: zone_margin 1.15, end widening 1.3). Sized
#: from the load, not from the thesis's 2000 MPa design pressure: at the default 85 N the
#: contact is 19 um wide and a 2000 MPa zone (136 um) puts only ~1.4 grid spacings across
#: it at grid 21; sized from 1.5 N it gets ~7 (k_n within 0.3 % of grid 21 at grid 11).
ZONE_LOAD_FACTOR = 1.5
#: Steps of the zone's design pressure (2^(1/4): the zone's half-width in steps of 19 %, so
#: the zone holds the contact of 1.5-2.1 times the load; factor 2 changed k_n by < 1 %).
ZONE_STEP = 2.0 ** 0.25
#: The [geometry] keys: positive / Poisson ratios / loads >= 0 (0: from CF); the cylinder
#: FE variant is ``real`` or ``halfspace`` (the flat is always the block model).
_POSITIVE = ("cylinder_radius", "flat_height", "E_damper", "E_blade")
_POISSON = ("nu_damper", "nu_blade")
_LOADS = ("normal_load_left", "normal_load_flat")


# ------------------------------------------------------------------ inputs
def geometry_params(cfg, cf: float | None = None) -> dict:
    """The contact inputs of a UPD config, checked.

    Parameters
    ----------
    cfg : UPDConfig
        With a ``[geometry]`` section (the bundled default has one).
    cf : float, optional
        Centrifugal load of the run [N] (default: ``load.cf``); sets the nominal loads
        that ``geometry.normal_load_*`` leave at 0.

    Returns
    -------
    dict: R, L, W, h, E1, nu1 (damper), E2, nu2 (blade), mu, N_left, N_flat, grid,
    cylinder_model.

    Raises
    ------
    ValueError
        A missing or unusable value, named with its key and what to change.
    """
    # types and ranges of the [geometry] keys: the config's typed model (config_model.GeometrySection)
    geo = cfg.data["geometry"]
    val = {key: float(geo[key]) for key in _POSITIVE + _POISSON + _LOADS}
    grid, model = geo["grid"], geo["cylinder_model"]
    mu = cfg.mu
    if not mu > 0:
        raise ValueError(f"config: damper.mu = {mu:g}: the contacts from geometry need mu > 0 "
                         "(the virgin curve ends at gross slip, T = mu N)")
    cf = cfg.cf if cf is None else float(cf)
    N_static = cf / (2.0 * math.cos(math.radians(float(cfg["damper.angle_deg"]))))
    for key in _LOADS:
        if not (val[key] or N_static) > 0:
            raise ValueError(f"config: geometry.{key} = 0 takes the static load at CF = {cf:g} N, "
                             "which is 0: give a CF > 0 or the load itself")
    from damper import limits

    for key in _LOADS:  # a contact model at 1e-300 N marched for minutes (CF = 1e-300 N)
        limits.check_range(f"the nominal normal load of geometry.{key} (CF = {cf:g} N)", val[key] or N_static,
                           limits.MIN_NORMAL_LOAD, limits.MAX_NORMAL_LOAD, "N",
                           "a friction damper's contacts carry mN to MN; give another CF or the load itself")
    return {"R": val["cylinder_radius"], "L": float(cfg["damper.contact_length"]),
            "W": float(cfg["damper.right_width"]), "h": val["flat_height"],
            "E1": val["E_damper"], "nu1": val["nu_damper"], "E2": val["E_blade"],
            "nu2": val["nu_blade"], "mu": mu, "grid": grid, "cylinder_model": model,
            "N_left": val["normal_load_left"] or N_static,
            "N_flat": val["normal_load_flat"] or N_static}


def contact_specs(p: dict) -> dict:
    """``contact_core`` specifications of the two contacts: {"left": (spec, model, N), "flat": ...}.

    Body 1 is the damper (cylinder / flat face), body 2 the platform.
    """
    from contact_core import hertz
    from contact_core.spec import ContactSpec

    mats = {"E1": p["E1"], "nu1": p["nu1"], "E2": p["E2"], "nu2": p["nu2"], "grid": p["grid"]}
    if p["R"] > 0 and p["L"] > 0 and p["N_left"] > 0:
        Es = hertz.contact_modulus(p["E1"], p["nu1"], p["E2"], p["nu2"])
        p_zone = hertz.cylinder(ZONE_LOAD_FACTOR * p["N_left"], p["L"], p["R"], Es)["p0"]
        # rounded up to a step of ZONE_STEP: nearby loads (--cf runs) share one condensed model
        p_zone = ZONE_STEP ** math.ceil(math.log(p_zone) / math.log(ZONE_STEP))
    else:
        p_zone = 1.0  # ContactSpec refuses the geometry with its own message
    try:
        cyl = ContactSpec(body="cylinder", radius=p["R"], length=p["L"], p_design=p_zone,
                          load_hint=p["N_left"], model=p["cylinder_model"], **mats)
    except ValueError as err:
        raise ValueError(f"left contact (cylinder R = {p['R']:g} m, L = {p['L']:g} m) at its nominal "
                         f"load N = {p['N_left']:.4g} N: {err} (config: geometry.cylinder_radius, "
                         "damper.contact_length, load.cf or geometry.normal_load_left)") from None
    try:
        flat = ContactSpec(body="flat", length=p["L"], width=p["W"], height=p["h"],
                           model="halfspace", **mats)
    except ValueError as err:
        raise ValueError(f"right contact (flat W = {p['W']:g} m, L = {p['L']:g} m): {err}") from None
    return {"left": (cyl, p["cylinder_model"], p["N_left"]), "flat": (flat, "halfspace", p["N_flat"])}


# ------------------------------------------------------------------ solves
def solve_contact(name: str, spec, model: str, N: float, mu: float, store=None) -> dict:
    """Virgin curve and k_n of one contact at the normal load N (cached in ``store``).

    Returns
    -------
    dict: curve (VirginCurve, tail "flat", N = N_ref), k_n, k_t [N/m], contact_nodes,
    warnings (list of str), cached (bool: loaded from the store), time_s.
    """
    from contact_core import tangential_run
    from contact_core.curve import VirginCurve
    from damper.cache import make_key
    from damper.provenance import code_version

    t0 = time.perf_counter()
    key = make_key("upd-geometry-contact", ENTRY_VERSION, spec.key_dict(), spec.p_design, model,
                   float(N), float(mu), code_version(("contact_core",)))
    hit = store.get(key, stage="upd_contact") if store is not None else None
    if hit is not None:
        arrays, meta = hit
        curve = VirginCurve(u=arrays["u"], T=arrays["T"], N=meta["N"], mu=mu, k_t=meta["k_t"],
                            k_n=meta["k_n"], load_case="CNF", tail="flat")
        return {"curve": curve, "k_n": meta["k_n"], "k_t": meta["k_t"],
                "contact_nodes": meta["contact_nodes"], "warnings": meta["warnings"],
                "cached": True, "time_s": time.perf_counter() - t0}
    try:
        run = tangential_run.run(spec, mu, force=N, model=model,
                                 cache=store if store is not None else False,
                                 command=f"damper upd --contacts geometry ({name})")
    except ValueError as err:
        raise ValueError(f"{name} contact ({spec.body}) at N = {N:.4g} N: {err}") from None
    # N: the solved nodal forces' sum (N to round-off), the curve's own N_ref
    meta = {"N": run.curve.N, "k_n": run.k_n, "k_t": run.problem.k_t, "contact_nodes": int(run.problem.n_c),
            "warnings": list(run.warnings)}
    if store is not None:
        store.put(key, {"u": np.asarray(run.curve.u), "T": np.asarray(run.curve.T)}, meta, stage="upd_contact")
    return {"curve": run.curve, **meta, "cached": False, "time_s": time.perf_counter() - t0}


def _split(curve, share: float):
    """The curve of a share of a contact: T share at N_ref share (same slip displacements)."""
    return replace(curve, T=np.asarray(curve.T) * share, N=curve.N * share,
                   k_t=None if curve.k_t is None else curve.k_t * share,
                   k_n=None if curve.k_n is None else curve.k_n * share)


def geometry_contacts(cfg, cf: float | None = None, store=None) -> tuple[dict, dict]:
    """Contact laws of the three UPD points from ``contact_core`` (module docstring).

    Parameters
    ----------
    cfg : UPDConfig
    cf : float, optional
        The run's centrifugal load [N] (nominal loads; default ``load.cf``).
    store : damper.cache.Store, optional
        Cache of the FE condensation and of each contact's result; None: nothing cached.

    Returns
    -------
    contacts : dict
        ``UPDConfig.contacts``: point name -> {"kn": float, "friction": IwanElement}.
    report : dict
        ``contacts`` (per contact: body, N_ref, k_n, k_t, slip force mu N_ref, gross-slip
        displacement, curve points, cached, time_s, warnings), ``points`` (per point: kn,
        kt, slip force at its N_ref, N_ref) and ``time_s`` of the whole contact stage.
    """
    from fmu_src.element import IwanElement

    t0 = time.perf_counter()
    p = geometry_params(cfg, cf)
    solved, report = {}, {}
    for name, (spec, model, N) in contact_specs(p).items():
        r = solve_contact(name, spec, model, N, p["mu"], store)
        solved[name] = r
        c = r["curve"]
        report[name] = {"body": spec.body, "model": model, "N_ref": N, "k_n": r["k_n"],
                        "k_t": r["k_t"], "slip_force": p["mu"] * N,
                        "gross_slip_displacement": float(c.u[-1]), "curve_points": int(c.u.size),
                        "contact_nodes": r["contact_nodes"], "cached": r["cached"],
                        "time_s": r["time_s"], "warnings": r["warnings"]}
    contacts, points = {}, {}
    for point, name, share in (("left", "left", 1.0), ("right1", "flat", 0.5), ("right2", "flat", 0.5)):
        r = solved[name]
        el = IwanElement.from_virgin_curve(_split(r["curve"], share))
        contacts[point] = {"kn": share * r["k_n"], "friction": el}
        points[point] = {"kn": share * r["k_n"], "kt": float(np.sum(el.k) + el.k_res),
                         "slip_force": el.gross_slip_force(), "N_ref": el.N_ref,
                         "sliders": el.n_sliders, "fit_error": el.fit_error}
    return contacts, {"contacts": report, "points": points, "time_s": time.perf_counter() - t0}


def with_geometry_contacts(cfg, cf: float | None = None, store=None):
    """``cfg`` with the geometry's contact laws, and the report of :func:`geometry_contacts`."""
    contacts, report = geometry_contacts(cfg, cf, store)
    out = replace(cfg, contacts=contacts)  # keeps every other field of the config
    out.validate()
    return out, report


def report_lines(report: dict) -> list[str]:
    """Text lines of a contact report (one per contact and per point)."""
    out = [f"contacts from geometry ({report['time_s']:.2f} s):"]
    for name, c in report["contacts"].items():
        how = "cached" if c["cached"] else "computed"
        out.append(f"  {name:5s} {c['body']:8s} N_ref {c['N_ref']:.4g} N  k_n {c['k_n']:.4g} N/m  "
                   f"k_t {c['k_t']:.4g} N/m  slip force {c['slip_force']:.4g} N at "
                   f"u = {c['gross_slip_displacement']:.3g} m  ({how}, {c['time_s']:.2f} s)")
        out += [f"  warning: {w}" for w in c["warnings"]]
    for name, q in report["points"].items():
        out.append(f"  point {name:6s} k_n {q['kn']:.4g} N/m  k_t {q['kt']:.4g} N/m  "
                   f"slip force {q['slip_force']:.4g} N at N_ref {q['N_ref']:.4g} N "
                   f"({q['sliders']} sliders)")
    return out


def apply_to_args(args, cfg, store=None):
    """The CLI hook of ``damper upd``: ``cfg`` with the contacts that ``args.contacts`` names.

    ``--contacts toml`` (or no such option) returns ``cfg`` unchanged; ``geometry`` computes
    them (the run's ``--cf`` sets the nominal loads; the condensations kept in ``store``,
    default the application's cache), stores the report in ``args.contact_report`` (the
    JSON's ``contacts_from_geometry``) and prints its lines unless ``--json``.
    """
    if getattr(args, "contacts", "toml") != "geometry":
        return cfg
    if store is None:
        from damper.cache import Store

        store = Store().prepare()
    cfg, report = with_geometry_contacts(cfg, getattr(args, "cf", None), store)
    args.contact_report = report
    if not getattr(args, "json", False):
        print("\n".join(report_lines(report)))
    return cfg
