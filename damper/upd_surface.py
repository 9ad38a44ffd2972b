"""Contact surfaces of the underplatform damper from its geometry (``damper upd frf --contacts surface``).

The damper's cylinder line and flat face as contact surfaces
(:mod:`harmonic_balance.surface`, planar; the sector model
:class:`harmonic_balance.bladed_disk.surface_hb.SurfaceSectorHB`): the bodies,
materials and potential contact zones are those of ``--contacts geometry``
(:func:`damper.upd_geometry.contact_specs`), condensed by ``contact_core`` with the
user's node count per side (``--surface-nodes``) and kept in the application's store.

Symbols: N nodes per side of each face's contact-zone grid; mu friction coefficient.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

#: Contact penalty of the UPD surfaces (relative to each node's own body stiffness). The
#: harmonic balance's Newton converged at 100 and stalled at 1000 and 1e4 (UPD-24, 5 nodes per
#: side, CF 300 N, H 3, 440 Hz: |R| stuck near 0.1-0.2 N); at 100 the quasi-static cylinder
#: loop of tests/hb/test_surface.py is -0.18 % in k_t and -2.4 % in energy per cycle against the
#: contact core (1e4: 2e-5 and 7e-5). A smoother or better-globalised solve would allow more.
DYNAMICS_PENALTY = 100.0


def build_surfaces(cfg, nodes_per_side: int, cf: float | None = None, store=None,
                   penalty: float | None = None) -> dict:
    """Planar contact surfaces {"left": cylinder, "flat": flat face} of a UPD config.

    Parameters
    ----------
    cfg : UPDConfig
        With a [geometry] section.
    nodes_per_side : int
        Contact-zone nodes per side of each face (``surface.check_nodes`` bounds).
    cf : float, optional
        The run's centrifugal load [N] (sizes the cylinder's potential zone as for
        ``--contacts geometry``).
    store : damper.cache.Store, optional
        Cache of the condensation (None: none).
    penalty : float, optional
        Contact penalty factor (default ``DYNAMICS_PENALTY``).

    Raises
    ------
    ValueError
        A node count outside its bound, or a geometry contact_core refuses.
    """
    from contact_core.condense import condense
    from harmonic_balance.surface import build

    mu, specs = face_specs(cfg, nodes_per_side, cf)
    out = {}
    for face, spec in specs.items():
        cc = condense(spec, directions=("z", "x"), cache=store if store is not None else False)
        out[face] = build(cc, mu, penalty=DYNAMICS_PENALTY if penalty is None else penalty, tangents=("x",))
    return out


def face_specs(cfg, nodes_per_side: int, cf: float | None) -> tuple:
    """(mu, {face: ContactSpec}) of the two faces at ``nodes_per_side`` (bound checked)."""
    from harmonic_balance.surface import check_nodes

    from .upd_geometry import contact_specs, geometry_params

    nodes = check_nodes(nodes_per_side)
    p = geometry_params(cfg, cf)
    specs = contact_specs(p)
    return p["mu"], {face: replace(specs[face][0], grid=nodes, model=specs[face][1])
                     for face in ("left", "flat")}


def check_unknowns(sector, nodes_per_side: int, H: int, cf: float | None) -> None:
    """ValueError, before any condensation, when the sector with surfaces has more than
    :data:`damper.limits.MAX_SURFACE_UNKNOWNS` harmonic-balance unknowns, (n_dof + 2 n) (2H + 1)
    with n the faces' contact-zone nodes (2 DOFs each, planar), counted on their meshes."""
    from contact_core import mesh
    from damper import limits

    _, specs = face_specs(sector.cfg, nodes_per_side, cf)
    nodes = sum(mesh.build(spec)[1].contact.size for spec in specs.values())
    n = (sector.n_dof + 2 * nodes) * (2 * H + 1)
    if n > limits.MAX_SURFACE_UNKNOWNS:
        raise ValueError(f"--surface-model nodes with --surface-nodes {nodes_per_side} and --harmonics {H}: "
                         f"{nodes} contact nodes, {n} unknowns, above the limit {limits.MAX_SURFACE_UNKNOWNS} "
                         f"({limits.SURFACE_UNKNOWNS_WHY}); lower --surface-nodes or --harmonics, or use "
                         "--surface-model condensed (the sector's unknowns only)")


def check_options(args) -> None:
    """The --contacts surface options: a node count in its bound, a nonlinear fixed-H run, no
    time-integration check."""
    from harmonic_balance.surface import check_nodes

    if args.contacts != "surface":
        return
    check_nodes(args.surface_nodes)
    if args.damper != "nonlinear":
        raise ValueError(f"--contacts surface with --damper {args.damper}: the linear limits use the "
                         "point model; drop --contacts surface or use --damper nonlinear")
    if args.accuracy is not None:
        raise ValueError("--contacts surface runs at the fixed --harmonics: drop --accuracy")
    if getattr(args, "check_steady_state", False):   # refused now, not after the (slow) curve
        raise ValueError("--check-steady-state integrates the ring with point contacts: drop it with "
                         "--contacts surface")


#: ``--surface-model``: the faces condensed onto their rigid inputs, the nodes marched in
#: time inside each evaluation (CondensedSurfaceSectorHB; the default: it reaches UPD-24's
#: default CF 120 N by the path in CF), or every node's DOFs as harmonic-balance unknowns
#: (SurfaceSectorHB; its Newton needs a well-loaded damper, CF ~300 N on UPD-24).
SURFACE_MODELS = ("condensed", "nodes")


def sector_hb(sector, args):
    """The sector with the damper's faces as contact surfaces of ``args.surface_model``
    (:data:`SURFACE_MODELS`) at ``args.cf``, and ``make(cf)``: the same model at another
    centrifugal load [N] (the CF path's), on the same condensed surfaces."""
    from damper.cache import store_of
    from harmonic_balance.bladed_disk.surface_hb import CondensedSurfaceSectorHB, SurfaceSectorHB, face_inputs

    face_inputs(sector, "left")   # a sector with axial platform DOFs refused before any condensation
    if args.surface_model == "nodes":   # the condensed model's unknowns are the sector's alone
        check_unknowns(sector, args.surface_nodes, args.harmonics, args.cf)
    surfaces = build_surfaces(sector.cfg, args.surface_nodes, args.cf, store_of(args))
    kind = CondensedSurfaceSectorHB if args.surface_model == "condensed" else SurfaceSectorHB

    def make(cf):
        return kind(sector, surfaces, args.harmonics, cf=cf, f0=args.f0)
    args.surface_report = {face: {"nodes": s.n, "dofs": s.n_w, "nodes_per_side": args.surface_nodes}
                           for face, s in surfaces.items()}
    return make(args.cf), make


def surface_curve(sector, args, omegas):
    """(hb, curve, truncation record, run record) of ``upd frf --contacts surface``.

    The condensed model's first point comes from
    :func:`harmonic_balance.bladed_disk.load_path.first_point` (the path in CF from the
    open load where the CF is below it), the curve then continues from it as any
    ``frf``. The run record: the model, its nodes, every residual evaluation (the path's
    models' and the curve's; the truncation check's model counts its own), CPU and wall time
    [s] of the whole, the truncation check's CPU time (a peak search at ceil(1.5 H): on
    UPD-24 at H 1 it took longer than the curve), and the start.

    Raises
    ------
    SolverError
        The path, the start or the continuation failed (message says what to change).
    """
    import time

    from damper import limits
    from harmonic_balance.bladed_disk.accuracy import truncation_error
    from harmonic_balance.bladed_disk.load_path import first_point
    from harmonic_balance.bladed_disk.solve import SolverError, frf

    t0, p0 = time.perf_counter(), time.process_time()
    hb, make = sector_hb(sector, args)
    built = [hb]

    def counted(cf):
        built.append(make(cf))
        return built[-1]
    start = {"method": "Newton from the stuck start at the CF"}
    if args.surface_model == "condensed":
        x0, path = first_point(counted, omegas[0], hb.cf)
        start = {"method": "path in CF" if len(path["loads"]) > 1 else start["method"], **path}
        c = frf(hb, omegas, x0=x0)
    else:
        try:
            c = frf(hb, omegas)
        except SolverError as err:   # the generic advice (band, harmonics) misses the load and the model
            raise SolverError(f"{err}; the node-DOF surface model needs a well-loaded damper (UPD-24: CF "
                              "300 N solved a curve at H 1, the default 120 N failed): use --surface-model "
                              "condensed or a larger --cf") from None
    p1 = time.process_time()
    rec = truncation_error(hb, c, limits.MAX_UPD_HARMONICS)
    nodes = sum(r["nodes"] for r in args.surface_report.values())
    run = {"model": args.surface_model, "nodes_per_side": args.surface_nodes, "nodes": nodes,
           "evaluations": sum(m.evaluations for m in built), "start": start,
           "truncation_check_cpu_s": time.process_time() - p1,
           "cpu_s": time.process_time() - p0, "time_s": time.perf_counter() - t0}
    return hb, c, rec, run


def _condensed_faces(hb) -> list:
    """(index in the model's elements, CondensedSurface) of each face of a condensed sector."""
    from harmonic_balance.surface_condensed import CondensedSurface

    return [(i, el) for i, el in enumerate(hb.model.elements) if isinstance(el, CondensedSurface)]


def static_loads(hb) -> list:
    """Prestress normal load per contact point [N]; with surfaces, per face (sum over its nodes;
    condensed: the face's normal resultant, the same sum)."""
    faces = _condensed_faces(hb)
    if faces:   # (Q2) of harmonic_balance.surface_condensed at the prestress, approach row
        return [float((el.RtAR @ el.q_static - el.RtA @ el.w_static)[0]) for _, el in faces]
    N = hb.static["N"]
    if not hasattr(hb, "surfaces"):
        return N.tolist()
    names = [e.name for e in hb.points]
    return [float(sum(n for n, name in zip(N, names) if name.startswith(f"{face} node")))
            for face in hb.surfaces]


def condensed_summary(hb, x, omega: float) -> dict:
    """Per face of a condensed sector at the solution x (omega [rad/s]): mean and range of
    its normal resultant [N] (the sum over its nodes), the share of the period the whole
    face is open (resultant <= 0: the nodes' own states stay inside the march), friction
    energy per cycle of the marched loop [J]; refuses a damper that left both faces.
    The zone-edge check needs each node's load: the node-DOF model's (``face_summary``)."""
    lfs = hb.residual.evaluate(x, omega, jac=False)
    out = {"names": [], "normal_load_mean": [], "normal_load_range": [], "lift_off": [],
           "friction_energy": []}
    for i, el in _condensed_faces(hb):
        N = lfs[i].f[:, 0]
        out["names"].append(el.name)
        out["normal_load_mean"].append(float(N.mean()))
        out["normal_load_range"].append(float(np.ptp(N)))
        out["lift_off"].append(float((N <= 0.0).mean()))
        out["friction_energy"].append(float(lfs[i].W - lfs[i].W_viscous))
    if max(out["normal_load_mean"]) <= 0.0:
        raise RuntimeError("the damper lost contact on both faces at the peak (no face carries a "
                           "load): raise --cf or lower --f0")
    return out


def face_summary(hb, summ: dict) -> dict:
    """Per face (sums over its nodes): mean and range of N [N], the share of the period
    lifted off (mean over the nodes that touch at some time of the share of the period each
    is open: the potential zone's nodes that never touch are not the contact, and counted a
    stuck face a third open; 1 where none touches), friction energy per cycle [J];
    refuses a damper that left both faces; warns when a face loads its zone edge."""
    out = {"names": [], "normal_load_mean": [], "normal_load_range": [], "lift_off": [],
           "friction_energy": []}
    for face in hb.surfaces:
        idx = [i for i, name in enumerate(summ["names"]) if name.startswith(f"{face} node")]
        out["names"].append(face)
        out["normal_load_mean"].append(sum(summ["normal_load_mean"][i] for i in idx))
        out["normal_load_range"].append(sum(summ["normal_load_range"][i] for i in idx))
        shares = [summ["lift_off"][i] for i in idx if summ["lift_off"][i] < 1.0]
        out["lift_off"].append(float(np.mean(shares)) if shares else 1.0)
        out["friction_energy"].append(sum(summ["friction_energy"][i] for i in idx))
    if max(out["normal_load_mean"]) <= 0.0:
        raise RuntimeError("the damper lost contact on both faces at the peak (no node carries a "
                           "load): raise --cf or lower --f0")
    edge = [face for face, surf in hb.surfaces.items()
            if any(summ["normal_load_mean"][i] + summ["normal_load_range"][i] > 0
                   for i, name in enumerate(summ["names"])
                   if name.startswith(f"{face} node ") and surf.zone_edge[int(name.split()[-1])])]
    if edge:
        out["warning_zone_edge"] = (f"warning: the {' and '.join(edge)} contact reaches the edge of its "
                                    "potential zone at the peak: the surface cuts it there (raise "
                                    "geometry.normal_load_left, which sizes the zone)")
    return out


#: ``upd optimize --contacts surface`` walks the loads with the condensed model only: its unknowns
#: are the sector's at every load, so each load's search starts from the last one's peak.
OPTIMIZE_MODEL = "condensed"
#: Most loads of ``upd optimize --contacts surface``: each is a peak search of 2-3 min CPU at 5
#: nodes per side and H 7 (~120 evaluations of ~1.3 s), so 40 loads are about two hours.
MAX_OPTIMIZE_POINTS = 40


def check_optimize_options(args) -> None:
    """``upd optimize --contacts surface``: the options of the point-contact sweep that do not
    apply refused (ValueError naming what to drop); the surface options checked."""
    from harmonic_balance.surface import check_nodes

    if args.contacts != "surface":
        return
    check_nodes(args.surface_nodes)
    if args.points > MAX_OPTIMIZE_POINTS:
        raise ValueError(f"--points {args.points} with --contacts surface: at most {MAX_OPTIMIZE_POINTS} loads "
                         "(each a peak search of minutes); lower --points")
    if args.surface_model != OPTIMIZE_MODEL:
        raise ValueError(f"upd optimize --contacts surface walks the loads with --surface-model {OPTIMIZE_MODEL} "
                         f"(its unknowns are the same at every load): drop --surface-model {args.surface_model}")
    refused = [("--accuracy", args.accuracy is not None, "runs at the fixed --harmonics"),
               ("--grid", args.grid is not None, "searches each peak by Brent's method, not on a grid"),
               ("--workers", args.workers is not None, "walks the loads in one process, each load "
                "warm-started from the last")]
    for opt, given, why in refused:
        if given:
            raise ValueError(f"upd optimize --contacts surface {why}: drop {opt}")


def optimize_record(sector, args, note=None) -> dict:
    """The ``upd optimize --contacts surface`` record
    (:func:`harmonic_balance.bladed_disk.surface_peak.optimal_load_surface`): the faces condensed
    at each load with ``args.surface_nodes`` per side (kept in the store), the same keys as the
    point-contact sweep, ``surface_model`` with the node count, and no truncation estimate (a
    peak search at more harmonics per load would double a run of minutes per load).

    ``note(line)`` receives the cost estimate before the walk (evaluations expected of the walk
    and of the refinement x the measured CPU time of the first one) and a line per load solved.

    Raises
    ------
    ValueError
        A geometry contact_core refuses at a load of the range.
    SolverError
        A load's peak search failed (the message names the load).
    """
    from damper.cache import store_of
    from harmonic_balance.bladed_disk.solve import SolverError
    from harmonic_balance.bladed_disk.surface_hb import face_inputs
    from harmonic_balance.bladed_disk.surface_peak import optimal_load_surface

    face_inputs(sector, "left")   # a sector with axial platform DOFs refused before any condensation
    for cf in args.cf_range:      # the faces' inputs (mu, nominal loads) at both ends, before any solve
        face_specs(sector.cfg, args.surface_nodes, cf)
    if note is not None:   # after the refusals (one line each); the faces' condensation and statics
        # and the point model's peak come first (minutes)
        note(f"upd optimize --contacts surface: building the faces at {args.surface_nodes} nodes per side and "
             f"the point model's peak at H {args.harmonics} at CF {max(args.cf_range):g} N, then the "
             "estimate of the walk")
    store = store_of(args)

    def surfaces_at(cf):   # called once per load: the walk keeps each load's model
        return build_surfaces(sector.cfg, args.surface_nodes, cf, store)

    def estimate(walk, refine, seconds):
        if note is not None:
            note(f"upd optimize --contacts surface: about {walk} residual evaluations for the {args.points} loads "
                 f"at {seconds:.2g} s CPU each (the first one measured): ~{walk * seconds / 60:.0f} min CPU, and "
                 f"~{refine * seconds / 60:.0f} min more if the optimum lies inside the range (its refinement)")

    def on_load(r):
        if note is not None:
            note(f"  CF {r['cf']:.4g} N: peak {r['peak_hz']:.3f} Hz, |u_a,1| {r['peak_amplitude_h1']:.5e} m "
                 f"({r['evaluations']} evaluations, {r['cpu_s']:.0f} s CPU; {r['start']})")

    try:
        out = optimal_load_surface(sector, surfaces_at, args.cf_range, args.points, args.harmonics,
                                   estimate=estimate, on_load=on_load)
    except SolverError as err:
        raise SolverError(f"{err} (upd optimize --contacts surface: narrow --cf-range, or raise its low end)") \
            from None
    out["surface_model"] |= {"nodes_per_side": args.surface_nodes}
    out["truncation_error"] = None
    return out


def optimize_line(run: dict) -> str:
    """The printed line of ``upd optimize --contacts surface``'s ``surface_model`` record."""
    loads = run["loads"]
    nodes = sorted({r["nodes"] for r in loads})
    span = f"{nodes[0]}" if len(nodes) == 1 else f"{nodes[0]} ... {nodes[-1]}"
    return (f"surface model {run['model']}, {run['nodes_per_side']} nodes per side ({span} nodes): "
            f"{len(loads)} loads searched, {run['evaluations']} evaluations, {run['cpu_s']:.0f} s CPU "
            f"({run['time_s']:.0f} s wall)")
