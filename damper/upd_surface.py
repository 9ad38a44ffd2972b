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
    from harmonic_balance.surface import build, check_nodes

    from .upd_geometry import contact_specs, geometry_params

    nodes = check_nodes(nodes_per_side)
    p = geometry_params(cfg, cf)
    specs = contact_specs(p)
    out = {}
    for face in ("left", "flat"):
        spec, model, _ = specs[face]
        cc = condense(replace(spec, grid=nodes, model=model), directions=("z", "x"),
                      cache=store if store is not None else False)
        out[face] = build(cc, p["mu"], penalty=DYNAMICS_PENALTY if penalty is None else penalty, tangents=("x",))
    return out
