"""Normal contact validation: sphere and cylinder on a plane against Hertz.
========================================================================

Runs the FE models (real half-sphere / half-cylinder on a block), writes one
JSON file with the results and the Hertz comparison, and plots (pressure map,
contact area vs Hertz, F-approach) per case into ``out_dir``::

    python examples/normal_validation.py --out out/normal

``main(out_dir)`` is what ``make demo`` calls. SI units.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from contact_core import api
from contact_core.fileio import atomic_write
from contact_core.plots import plot_all
from contact_core.spec import ContactSpec

#: The validation cases: (name, spec, force [N]); geometry as the thesis (ch. 2, App. B).
CASES = (
    ("sphere", ContactSpec(body="sphere", radius=0.01, model="real", grid=21), 200.0),
    ("cylinder", ContactSpec(body="cylinder", radius=2.5e-3, length=1.2e-3, model="real", grid=21), 350.0),
)


def approach_fit(curve: dict, spec) -> dict:
    """d = A F^(2/3) + B F fit of a sphere's F-approach curve (:func:`contact_core.hertz.sphere_approach_fit`)."""
    from contact_core.hertz import sphere_approach_fit

    return sphere_approach_fit(curve["force"], curve["approach"], spec.Estar, spec.radius)


def run_case(name: str, spec: ContactSpec, force: float, out_dir: Path, cache=None) -> dict:
    """Solve one case, plot it into ``out_dir/name`` and return the result (no maps)."""
    result = api.run_normal(spec, force=force, cache=cache, curve_points=8)
    plot_all(result, spec.body, out_dir / name)
    if "approach" in result.get("hertz", {}):  # the reference gives an F-approach law
        result["approach_fit"] = approach_fit(result["curve"], spec)
    return {k: v for k, v in result.items() if k != "maps"}


def main(out_dir: str | Path = "out/normal", cache=None) -> dict:
    """Run every case; write ``normal_validation.json`` and plots; return the summary."""
    from damper.cli.common import dumps

    out_dir = Path(out_dir)
    summary = {}
    for name, spec, force in CASES:
        r = run_case(name, spec, force, out_dir, cache)
        summary[name] = r
        h = r["hertz"]
        size = spec.kind.size_key
        print(f"{name:9s} F = {force:g} N  {size} {r[size] * 1e6:.2f} um ({100 * h['error_size']:+.2f} % vs Hertz)"
              f"  p0 {r[spec.kind.peak_key] / 1e6:.0f} MPa "
              f"({100 * h['error_p0']:+.2f} %)  approach {r['approach'] * 1e6:.3f} um"
              f"  k_n {r['k_n']:.4g} N/m  body-1 share {100 * r['body1_share']:.0f} %")
        if "approach_fit" in r:
            fit = r["approach_fit"]
            print(f"{'':9s} approach fit d = A F^(2/3) + B F: A {100 * fit['error_A']:+.2f} % vs Hertz, "
                  f"B = {fit['B']:.3g} m/N (finite bodies)")
    atomic_write(out_dir / "normal_validation.json", dumps(summary, indent=1) + "\n")
    return summary


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="out/normal")
    out = parser.parse_args().out
    from damper.script import run as run_script

    sys.exit(run_script(lambda: main(out)))
