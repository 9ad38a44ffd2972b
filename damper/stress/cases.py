"""The grid of extreme but legal inputs, stage by stage.

A case is a ``damper`` command line (or the FMU child) plus what a correct
outcome is: ``expect="converged"`` for legal inputs the tool must handle, or
``"clear_error"`` for inputs it must refuse (nu = 0.5, mu = 0, a NaN input).
``quick`` marks the subset of ``damper stress --quick``.

Nominal values: sphere R = 10 mm on a plane, steel, N = 200 N, mu = 0.5; the
single-DOF Jenkins model m = k = 1, c = 0.01, slip force 0.05, forcing 0.05.
"""
from __future__ import annotations

from dataclasses import dataclass, field

R, N0, MU = 0.01, 200.0, 0.5
SPHERE = ["--body", "sphere", "--radius", str(R)]
SDOF = {"mass": 1.0, "stiffness": 1.0, "damping": 0.01, "contact-stiffness": 1.0, "slip-force": 0.05,
        "force": 0.05}


@dataclass
class Case:
    """One stress case."""

    stage: str
    name: str
    argv: list[str]                # damper CLI arguments ({curve:NAME} and {work} are filled in)
    request: dict = field(default_factory=dict)  # what the checks compare with
    expect: str = "converged"
    quick: bool = False
    timeout: float = 300.0


def _normal() -> list[Case]:
    cases = []
    for f, q in ((1e-6, True), (1e-3, False), (1.0, False), (1e3, False), (1e6, True)):
        for model, grid, quick in (("halfspace", 11, q), ("real", 11, False)):
            cases.append(Case("normal", f"load {f:g} x nominal, {model} {grid}",
                              ["normal", *SPHERE, "--force", f"{f * N0:g}", "--model", model, "--grid", str(grid),
                               "--json", "--no-cache"], {"force": f * N0, "radius": R}, quick=quick,
                              # 1e3 and 1e6 x nominal: Hertz radius 0.24 R and 2.4 R, beyond a <= 0.15 R
                              expect="clear_error" if f >= 1e3 else "converged"))
    for ratio, q in ((1e-3, False), (1e-1, False), (1e3, False), (1e6, True)):
        cases.append(Case("normal", f"E2/E1 = {ratio:g}",
                          ["normal", *SPHERE, "--force", f"{N0:g}", "--E", "2e11", "--E2", f"{2e11 * ratio:g}",
                           "--model", "halfspace", "--grid", "11", "--json", "--no-cache"], {"force": N0}, quick=q))
    cases += [
        Case("normal", "coarsest grid 3", ["normal", *SPHERE, "--force", "200", "--model", "halfspace", "--grid", "3",
                                           "--json", "--no-cache"], {"force": N0}),
        Case("normal", "finest grid 81 halfspace", ["normal", *SPHERE, "--force", "200", "--model", "halfspace",
                                                    "--grid", "81", "--json", "--no-cache"], {"force": N0},
             timeout=1800.0),  # MAX_GRID: ~4 GB and minutes on a busy 2-core machine
        Case("normal", "radius 10 um, real", ["normal", "--body", "sphere", "--radius", "1e-5", "--force", "200",
                                              "--model", "real", "--grid", "11", "--json", "--no-cache"],
             {"force": N0}, quick=True, expect="clear_error"),  # Hertz radius 2.4 R: refused with the limit
        Case("normal", "near-grazing: approach 1e-12 m", ["normal", *SPHERE, "--approach", "1e-12", "--model",
                                                          "halfspace", "--grid", "11", "--json", "--no-cache"]),
        Case("normal", "cylinder, load 1e-6 x", ["normal", "--body", "cylinder", "--radius", "2.5e-3", "--length",
                                                 "1.2e-3", "--force", "3.5e-4", "--model", "halfspace", "--grid",
                                                 "11", "--json", "--no-cache"], {"force": 3.5e-4}),
        Case("normal", "flat face, eccentric", ["normal", "--body", "flat", "--width", "2e-3", "--length", "2e-3",
                                                "--force", "200", "--eccentricity", "4e-4", "--model", "halfspace",
                                                "--grid", "11", "--json", "--no-cache"], {"force": N0}),
        Case("normal", "refused: nu = 0.5", ["normal", *SPHERE, "--force", "200", "--nu", "0.5", "--json",
                                             "--no-cache"], expect="clear_error", quick=True),
        Case("normal", "refused: negative E", ["normal", *SPHERE, "--force", "200", "--E=-2e11", "--json",
                                               "--no-cache"], expect="clear_error"),
    ]
    return cases


def _tangential() -> list[Case]:
    base = ["tangential", *SPHERE, "--json", "--no-cache"]
    cases = []
    for mu, q in ((1e-3, False), (0.5, False), (10.0, True)):
        cases.append(Case("tangential", f"mu = {mu:g}, bem 11", [*base, "--force", "200", "--mu", f"{mu:g}",
                                                                "--model", "bem", "--grid", "11"],
                          {"force": N0}, quick=q))
    for f, q in ((1e-6, False), (1e6, False)):
        cases.append(Case("tangential", f"load {f:g} x nominal, bem 11", [*base, "--force", f"{f * N0:g}", "--mu",
                                                                          "0.5", "--model", "bem", "--grid", "11"],
                          {"force": f * N0, "radius": R}, quick=q,
                          expect="clear_error" if f >= 1e3 else "converged"))  # 1e6: Hertz radius 2.4 R
    cases += [
        Case("tangential", "real 11, nominal", [*base, "--force", "200", "--mu", "0.5", "--model", "real", "--grid",
                                                "11"], {"force": N0}),
        Case("tangential", "full slip loop (amplitude 10 x slip)", [*base, "--force", "200", "--mu", "0.5", "--model",
                                                                     "bem", "--grid", "11", "--loop-amplitude",
                                                                     "3e-5"], {"force": N0}),
        Case("tangential", "refused: mu = 0", [*base, "--force", "200", "--mu", "0", "--model", "bem", "--grid",
                                               "11"], expect="clear_error", quick=True),
        Case("tangential", "refused: tangential force above mu N", [*base, "--force", "200", "--mu", "0.5", "--model",
                                                                     "bem", "--grid", "11", "--tangential-force",
                                                                     "150"], expect="clear_error"),
    ]
    return cases


def _loop() -> list[Case]:
    cases = []
    for n, q in ((2, True), (10, False), (1000, False), (10000, False)):
        for amp, label, qa in ((1e-12, "stick", False), (2e-6, "partial slip", False), (1.0, "full slip 1 m", True)):
            cases.append(Case("loop", f"{n}-point curve, {label}", ["loop", "--curve", f"{{curve:mindlin{n}}}",
                                                                   "--amplitude", f"{amp:g}", "--fit", "concave",
                                                                   "--json"], quick=q and qa))
    cases += [
        Case("loop", "reversal chatter: 4 samples a cycle", ["loop", "--curve", "{curve:mindlin10}", "--amplitude",
                                                             "2e-6", "--samples", "4", "--json"], quick=True),
        Case("loop", "1e5 samples a cycle", ["loop", "--curve", "{curve:mindlin10}", "--amplitude", "2e-6",
                                             "--samples", "100000", "--json"]),
        Case("loop", "N = 1e-6 x the curve's", ["loop", "--curve", "{curve:mindlin10}", "--amplitude", "2e-6",
                                                "--N", "2e-4", "--json"]),
        Case("loop", "refused: non-concave curve", ["loop", "--curve", "{curve:convex}", "--amplitude", "2e-6",
                                                    "--json"], expect="clear_error", quick=True),
    ]
    return cases


def _fmu() -> list[Case]:
    cases = []
    for dt, q in ((1e-9, True), (1e-3, False), (1.0 / 64, False), (1.0, False)):
        cases.append(Case("fmu", f"step {dt:g} s, 1e4 steps", ["{curve:mindlin10}", "2", f"{dt:g}", "10000", "sine",
                                                              "2e-6"], quick=q))
    cases += [
        Case("fmu", "reversal chatter every step", ["{curve:mindlin10}", "2", "1e-3", "10000", "chatter", "2e-6"],
             quick=True),
        Case("fmu", "chatter in full slip (1 m)", ["{curve:mindlin10}", "2", "1e-3", "10000", "chatter", "1"]),
        Case("fmu", "FMI 3, sine", ["{curve:mindlin10}", "3", "1e-3", "10000", "sine", "2e-6"]),
        Case("fmu", "1e7 steps", ["{curve:mindlin10}", "2", "1e-4", "10000000", "sine", "2e-6"], timeout=1800.0),
        Case("fmu", "1e5 steps, 10000-point curve", ["{curve:mindlin10000}", "2", "1e-4", "100000", "sine", "2e-6"]),
        Case("fmu", "refused: NaN input", ["{curve:mindlin10}", "2", "1e-3", "10", "nan", "2e-6"],
             expect="clear_error", quick=True),
    ]
    return cases


def _sdof(**over) -> tuple[list[str], dict]:
    p = dict(SDOF, **over)
    argv = ["frf", "--model", "sdof"]
    for k, v in p.items():
        argv += [f"--{k}", f"{v:g}"]
    return argv, {"force": p["force"], "damping": p["damping"]}


def _frf() -> list[Case]:
    cases = []
    for kc, q in ((1e-3, False), (1.0, False), (30.0, True), (1e3, False), (1e6, False)):
        argv, req = _sdof(**{"contact-stiffness": kc})
        cases.append(Case("frf", f"contact stiffness {kc:g} k, H 7", [*argv, "--harmonics", "7", "--omega", "0.5",
                                                                      "2", "--json"], req, quick=q))
    for fs, q in ((5e-5, False), (0.5, False)):
        argv, req = _sdof(**{"slip-force": fs})
        cases.append(Case("frf", f"slip force {fs / 0.05:g} x forcing, H 7", [*argv, "--harmonics", "7", "--omega",
                                                                              "0.5", "2", "--json"], req, quick=q))
    argv, req = _sdof(damping=1e-4)
    cases.append(Case("frf", "damping 1e-4, H 7", [*argv, "--harmonics", "7", "--omega", "0.9", "1.3", "--json"], req))
    for H, q in ((1, False), (51, False)):
        argv, req = _sdof()
        cases.append(Case("frf", f"H {H}", [*argv, "--harmonics", str(H), "--omega", "0.9", "1.3", "--json"], req,
                          quick=q))
    argv, req = _sdof()
    cases.append(Case("frf", "sweep starting in the resonance", [*argv, "--harmonics", "7", "--omega", "1.05", "1.2",
                                                                 "--json"], req, quick=True))
    return cases


def all_cases() -> list[Case]:
    """Every stage's cases, in stage order (the blade-damper stage joins here when it lands)."""
    return _normal() + _tangential() + _loop() + _fmu() + _frf()
