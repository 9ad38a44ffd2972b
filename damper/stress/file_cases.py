"""The input stage's cases about files themselves: outputs onto inputs, onto FIFOs, and
inputs that are too large, endless or forged archives.

* Data loss: an output path that is one of the command's inputs, however spelled
  (``./``, a symbolic link, a hard link), a result folder holding the scene, two outputs
  naming one path, an output that is a FIFO, a cache folder of the user's: refused, nothing written, the input's
  bytes unchanged (the case's ``files`` are checked).
* Bounded reads: ``/dev/zero``, a 3 GiB (sparse) file and a FIFO as input files; an SSP
  and an .npz whose members declare more bytes than the cap; a Matrix Market header
  declaring a 1e8 x 1e8 matrix: refused before any large allocation (the child's
  address space is capped, so an attempt shows as a crash).
* The cache: an entry that is a FIFO is a miss (a warning), never a blocking read.

``mutate`` names a set-up of :data:`.inputs.MUTATE` with its arguments after colons
(``symlink:c.json:l.json``).
"""
from __future__ import annotations

import shlex

from . import input_fixtures as fx
from .input_cases import KN_SMALL, InputCase, _case

#: A 3 GiB sparse file (no disk used): above every input cap.
BIG = 3 * 2**30
CURVE = fx.curves()["curve.json"]
NPZ = fx.matrices()["m_good.npz"]
EL = fx.elements()["el_good.toml"]
SCENE = fx.SMALL
SDOF = "--model m.npz --elements el.toml"


def _loss() -> list[InputCase]:
    curve, model = {"c.json": CURVE}, {"m.npz": NPZ, "el.toml": EL}
    return [
        _case("files", "fmu -o the curve", "fmu --curve c.json -o c.json", files=curve),
        _case("files", "fmu -o the curve as ./ and absolute", "fmu --curve ./c.json -o c.json", files=curve),
        _case("files", "fmu -o a symlink to the curve", "fmu --curve c.json -o l.json", files=curve,
              mutate="symlink:c.json:l.json"),
        _case("files", "fmu -o a hard link of the curve", "fmu --curve c.json -o h.json", files=curve,
              mutate="hardlink:c.json:h.json"),
        _case("files", "fmu -o a FIFO", "fmu --curve c.json -o p.fmu", files=curve, mutate="fifo:p.fmu"),
        _case("files", "system --config u.toml -o u.toml", "system --config u.toml -o u.toml",
              files={"u.toml": "# the bundled UPD-24\n"}),
        _case("files", "frf --out the model", f"frf {SDOF} --omega 100 300 --out m.npz", files=model),
        _case("files", "frf --out the elements", f"frf {SDOF} --omega 100 300 --out el.toml", files=model),
        _case("files", "frf --out a FIFO", f"frf {SDOF} --omega 100 300 --out p.json", files=model,
              mutate="fifo:p.json"),
        _case("files", "backbone --out the model", f"backbone {SDOF} --amplitude 1e-6 1e-4 --out m.npz",
              files=model),
        _case("files", "normal --out and --normal-curve one path",
              "normal --body sphere --radius 0.01 --force 100 --grid 5 --model halfspace --out r.json "
              "--normal-curve ./r.json"),
        _case("files", "tangential --out and --plot one path",
              "tangential --body sphere --radius 0.01 --force 200 --mu 0.5 --model bem --grid 11 --out c.json "
              "--plot c.json"),
        _case("files", "run --out the scene's folder", "run s.toml --out .", files={"s.toml": SCENE}),
        _case("files", "sweep --out the scene's folder",
              "sweep s.toml --param contact.damper.mu --values 0.4 --serial --out .", files={"s.toml": SCENE}),
        _case("files", "cache clear: a user's 24-hex .npz, no tag", "cache clear --cache-dir cd",
              files={"cd/0123456789abcdef01234567.npz": "user data\n"}),
        _case("files", "a run with a user's 24-hex .npz as cache", KN_SMALL + " --cache-dir cd",
              files={"cd/0123456789abcdef01234567.npz": "user data\n"}),
    ]


def _bounded() -> list[InputCase]:
    cmds = {"fmu": "fmu --curve {f} -o d.fmu", "loop": "loop --curve {f} --amplitude 2e-6", "run": "run {f}",
            "upd frf --config": "upd frf --config {f}"}
    cases = []
    for name, cmd in cmds.items():
        cases.append(_case("files", f"{name} /dev/zero", cmd.format(f="/dev/zero")))
        cases.append(_case("files", f"{name} a 3 GiB file", cmd.format(f="big.in"), mutate=f"sparse:big.in:{BIG}"))
        cases.append(_case("files", f"{name} a FIFO", cmd.format(f="p.in"), mutate="fifo:p.in"))
    return cases + [
        _case("files", "cosim an SSP that unpacks to 4 GiB", "cosim {fx}/bomb.ssp --frequency-hz 400"),
        _case("files", "cosim an SSP of 5000 members", "cosim {fx}/many.ssp --frequency-hz 400"),
        _case("files", "frf an .npz whose member unpacks to 4 GiB",
              "frf --model {fx}/m_bomb.npz --elements {fx}/el_good.toml --omega 100 300"),
        _case("files", "upd modes: blade Matrix Market 1e8 x 1e8", "upd modes --config {fx}/upd_bigmtx.toml"),
        _case("files", "normal: stiffness Matrix Market of 1e12 entries",
              "normal --body sphere --force 100 --stiffness {fx}/big_nnz.mtx {fx}/big_nnz.mtx "
              "--nodes {fx}/m_good.npz {fx}/m_good.npz"),
        _case("files", "run: the scene's matrices a 3 GiB file", "run s.toml",
              files={"s.toml": fx._matrices_scene("big.npz")}, mutate=f"sparse:big.npz:{BIG}"),
    ]


def _cache() -> list[InputCase]:
    return [_case("files", "a FIFO named like a cache entry is a miss", KN_SMALL, pre=[shlex.split(KN_SMALL)],
                  mutate="fifo_entries", expect="converged", check="one_warning:is unreadable")]


def cases() -> list[InputCase]:
    """Every file case (module docstring)."""
    return _loss() + _bounded() + _cache()
