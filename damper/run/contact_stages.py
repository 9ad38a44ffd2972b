"""Contact stages: FE condensation, normal solve, tangential solve (``contact_core``).

The condensation is its own stage so the plan shows when the FE work is skipped; its
matrices live in the shared store under ``contact_core``'s own key (the library takes
the store through its cache protocol), and the stage records that key. The normal and
tangential stages call ``contact_core`` with the same store, so they load the
condensed bodies instead of rebuilding them.
"""
from __future__ import annotations

import json
import tempfile
from pathlib import Path

import numpy as np

from .graph import Kind, Result, Stage, warning_texts

#: Body fields of a scene contact that define the FE model (the condensation's inputs).
BODY_KEYS = ("body", "radius", "length", "width", "height", "E", "nu", "E2", "nu2", "model", "grid", "p_design",
             "zone_load")
#: Points of the normal stage's F-approach curve (5 % to 100 % of the load), as the
#: normal validation example: enough for the sphere's A F^(2/3) + B F fit.
CURVE_POINTS = 8


def contact_spec(p: dict):
    """The library's contact specification of the scene contact inputs ``p``."""
    from contact_core.spec import ContactSpec

    return ContactSpec(body=p["body"], radius=p.get("radius", 0.0), length=p.get("length", 0.0),
                       width=p.get("width", 0.0), E1=p["E"], nu1=p["nu"], E2=p["E2"], nu2=p["nu2"],
                       model=p["model"], grid=p["grid"], p_design=p["p_design"],
                       load_hint=p["zone_load"], height=p.get("height", 0.0))


def _body(c: dict) -> dict:
    return {k: c[k] for k in BODY_KEYS if k in c} | {"force": c["force"]}


def collect_files(folder: Path, prefix: str = "") -> dict:
    """Every file below ``folder`` as name -> bytes (plots a library wrote to a folder)."""
    return {prefix + p.name: p.read_bytes() for p in sorted(Path(folder).rglob("*")) if p.is_file()}


class Condense(Kind):
    """Guyan condensation of the two FE bodies onto the contact (the FE work)."""

    name = "condense"
    modules = ("contact_core",)

    def instances(self, data):
        out = []
        for cname, c in data.get("contact", {}).items():
            kinds = {_needs(w) for w in c["want"]}
            for directions, needed_by in ((("z",), "normal"), (("z", "x"), "tangential")):
                if needed_by in kinds or (needed_by == "tangential" and "mu" in c):
                    out.append(Stage(f"condense:{cname}:{''.join(directions)}", self,
                                     {"body": _body(c), "directions": list(directions)}, contact=cname))
        return out

    def is_cached(self, stage, store):
        hit = store.get(stage.key, stage=self.name) if store.contains(stage.key) else None
        return hit is not None and all(store.contains(e) for e in _entries(hit[1]["data"]))

    def compute(self, stage, inputs, ctx):
        from contact_core.condense import condense

        if stage.name in ctx.forced:           # --force: rebuild the FE matrices
            for entry in self._entries(stage, ctx):
                ctx.store.delete(entry)
        cc = condense(contact_spec(stage.params["body"]), tuple(stage.params["directions"]),
                      cache=ctx.store, progress=ctx.progress)
        meta = cc.meta
        # one store entry per direction: the stage is cached only while all of them are
        return Result({"entries": meta["cache"]["keys"], "hit": meta["cache"]["hit"],
                       "hits": meta["cache"]["hits"],
                       "timings": meta.get("timings", {}), "dofs": meta.get("dofs"),
                       "solver": meta.get("solver")})

    def _entries(self, stage, ctx):
        hit = ctx.store.get(stage.key, stage=self.name)
        return _entries(hit[1]["data"]) if hit else []

    def lines(self, stage, result):
        d = result.data
        hits = d.get("hits", {})
        how = ("loaded from the cache" if d["hit"] else
               "built" if not any(hits.values()) else
               "built " + ", ".join(k for k, v in hits.items() if not v) + "; loaded "
               + ", ".join(k for k, v in hits.items() if v) + " from the cache")
        times = ", ".join(f"{k} {v:.2f} s" for k, v in d["timings"].items())
        if stage.action == "cached":   # the stage itself came from the cache: its timings are the build's
            return [f"condensed bodies loaded from the cache (built with {times})"]
        return [f"condensed bodies {how} ({times})"]


def _entries(data: dict) -> list:
    """Store entries of a condense stage's result (one per direction)."""
    return list(data["entries"].values())


def _needs(result_name: str) -> str:
    from damper.scene.schema import RESULTS

    return RESULTS[result_name][0]


class Normal(Kind):
    """Active-set normal solve: k_n, pressure map, contact size against Hertz."""

    name = "normal"
    modules = ("contact_core",)

    def instances(self, data):
        return [Stage(f"normal:{n}", self, _body(c), deps=(f"condense:{n}:z",),
                      products=("k_n", "pressure_map"), contact=n)
                for n, c in data.get("contact", {}).items() if "normal" in {_needs(w) for w in c["want"]}]

    def compute(self, stage, inputs, ctx):
        from contact_core import api
        from contact_core.plots import plot_all

        p = stage.params
        result = api.run_normal(contact_spec(p), force=p["force"], cache=ctx.store,
                                curve_points=CURVE_POINTS)
        if p["body"] == "sphere":
            result["approach_fit"] = approach_fit(result["curve"], contact_spec(p))
        with tempfile.TemporaryDirectory() as tmp:
            plot_all(result, p["body"], tmp)
            files = collect_files(Path(tmp))
        maps = result.pop("maps")
        data = {k: v for k, v in result.items()}
        return Result(_plain(data), {f"map_{k}": np.asarray(v) for k, v in maps.items()}, files)

    def outputs(self, stage, result):
        return {"k_n": "result.json", "pressure_map": "pressure_map.png"}

    def lines(self, stage, result):
        r, body = result.data, stage.params["body"]
        h = r["hertz"] if "hertz" in r else None
        if h is None:
            return [f"{stage.contact:9s} F = {r['force']:g} N  approach {r['approach'] * 1e6:.3f} um  "
                    f"k_n {r['k_n']:.4g} N/m"]
        size = "contact_radius" if body == "sphere" else "contact_halfwidth"
        out = [f"{stage.contact:9s} F = {r['force']:g} N  {size} {r[size] * 1e6:.2f} um "
               f"({100 * h['error_size']:+.2f} % vs Hertz)"
               f"  p0 {r['p_max' if body == 'sphere' else 'p_mid_max'] / 1e6:.0f} MPa "
               f"({100 * h['error_p0']:+.2f} %)  approach {r['approach'] * 1e6:.3f} um"
               f"  k_n {r['k_n']:.4g} N/m  body-1 share {100 * r['body1_share']:.0f} %"]
        if "approach_fit" in r:
            fit = r["approach_fit"]
            out.append(f"{'':9s} approach fit d = A F^(2/3) + B F: A {100 * fit['error_A']:+.2f} % vs Hertz, "
                       f"B = {fit['B']:.3g} m/N (finite bodies)")
        if r.get("under_resolved"):
            from contact_core.bodies import under_resolved_warning

            out.append(f"{'':9s} " + under_resolved_warning("p_design", "grid"))
        return out

    def warnings(self, stage, result):
        out = super().warnings(stage, result)
        if result.data.get("under_resolved"):
            from contact_core.bodies import under_resolved_warning

            out = warning_texts(out + [under_resolved_warning("p_design", "grid")])
        return out

    def scalars(self, stage, result):
        r = result.data
        out = {"force_N": r["force"], "k_n_N_per_m": r["k_n"], "approach_m": r["approach"],
               "contact_area_m2": r["contact_area"]}
        if "hertz" in r:
            out |= {"hertz_error_size": r["hertz"]["error_size"], "hertz_error_p0": r["hertz"]["error_p0"]}
        return out


def approach_fit(curve: dict, spec) -> dict:
    """d = A F^(2/3) + B F fit of a sphere's F-approach curve (:func:`contact_core.hertz.sphere_approach_fit`)."""
    from contact_core.hertz import sphere_approach_fit

    return sphere_approach_fit(curve["force"], curve["approach"], spec.Estar, spec.radius)


class Tangential(Kind):
    """Stick/slip tangential solve at constant normal force: the virgin curve to gross slip."""

    name = "tangential"
    modules = ("contact_core",)

    def instances(self, data):
        return [Stage(f"tangential:{n}", self, _body(c) | {"mu": c["mu"]}, deps=(f"condense:{n}:zx",),
                      products=("virgin_curve", "k_t"), contact=n)
                for n, c in data.get("contact", {}).items() if "mu" in c]

    def compute(self, stage, inputs, ctx):
        from contact_core import tangential_run
        from contact_core.tangential_plots import plot_all

        p = stage.params
        run = tangential_run.run(contact_spec(p), p["mu"], force=p["force"], model=p["model"],
                                 cache=ctx.store, progress=ctx.progress,
                                 command=f"damper run {ctx.scene.source} ({stage.name})")
        with tempfile.TemporaryDirectory() as tmp:
            plot_all(run.virgin, run.problem, tmp)
            files = collect_files(Path(tmp))
        # the curve file (contact_core.curve's format), as write_curve writes it
        files["curve.json"] = (json.dumps(run.curve.to_dict(), indent=1, allow_nan=False) + "\n").encode()
        data = {"curve": run.curve.to_dict(), "load_case": run.load_case, "normal_force": run.problem.N,
                "mu": run.problem.mu, "k_t": run.problem.k_t, "k_n": run.k_n,
                "gross_slip_displacement": float(run.virgin.u[-1]), "points": int(len(run.virgin.u)),
                "stick_fraction": np.asarray(run.virgin.stick_fraction), "warnings": list(run.warnings),
                "timings": run.timings}
        return Result(_plain(data), files=files)

    def outputs(self, stage, result):
        return {"virgin_curve": "curve.json", "k_t": "result.json"}

    def lines(self, stage, result):
        s = result.data
        out = [f"{s['load_case']}: N = {s['normal_force']:.6g} N, mu = {s['mu']:g}, "
               f"k_t = {s['k_t']:.6g} N/m, k_n = {s['k_n']:.6g} N/m, gross slip at "
               f"u = {s['gross_slip_displacement']:.6g} m ({s['points']} points)"]
        return out + [f"warning: {w}" for w in s["warnings"]]

    def scalars(self, stage, result):
        return _scalars_tangential(result)


def _scalars_tangential(result):
    s = result.data
    return {"N_N": s["normal_force"], "mu": s["mu"], "k_t_N_per_m": s["k_t"], "k_n_N_per_m": s["k_n"],
            "u_gross_slip_m": s["gross_slip_displacement"], "curve_points": s["points"]}


def _plain(obj):
    """numpy values -> plain Python (JSON), recursively."""
    from damper.cli.common import to_jsonable

    return to_jsonable(obj)
