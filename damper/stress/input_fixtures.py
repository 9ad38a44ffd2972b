"""Files the input stage's bad inputs point at: curves, scenes, matrices, element and UPD files.

:func:`make` writes them once into a fixtures folder (``{fx}`` in a case's command);
each good file has broken siblings (binary, truncated, empty, NaN, wrong shape, unknown
key) so that every file type the toolkit reads is tried with each way it can be bad.
Nominal values as the stress grid's: a Cattaneo-Mindlin curve of 10 points at N =
200 N, mu = 0.5; the small scene of the application tests (a 7x7 cylinder contact).
"""
from __future__ import annotations

import io
import json
import zipfile
from pathlib import Path

import numpy as np

N0, MU, U_SLIP = 200.0, 0.5, 2.5e-6
BINARY = bytes(range(128, 256)) * 4


def _curve(n: int = 10) -> dict:
    u = U_SLIP * np.linspace(0.0, 1.0, n)
    T = MU * N0 * (1.0 - (1.0 - u / U_SLIP) ** 1.5)
    T[-1] = MU * N0
    return {"schema": "damper-virgin-curve/1", "u": u.tolist(), "T": T.tolist(), "N": N0, "mu": MU,
            "k_t": 1.5 * MU * N0 / U_SLIP, "load_case": "CNF"}


def curves() -> dict[str, str | bytes]:
    good = _curve()
    text = json.dumps(good)
    nan = dict(good, T=[float("nan")] + good["T"][1:])
    convex = dict(good, T=(MU * N0 * np.linspace(0, 1, 10) ** 2).tolist())
    dip = dict(good, T=good["T"][:4] + [good["T"][2]] + good["T"][5:])
    return {"curve.json": text, "curve_binary.json": BINARY, "curve_trunc.json": text[: len(text) // 2],
            "curve_empty.json": "", "curve_list.json": "[1, 2, 3]", "curve_nan.json": json.dumps(nan),
            "curve_decreasing.json": json.dumps(dict(good, u=good["u"][::-1])),
            "curve_convex.json": json.dumps(convex), "curve_dip.json": json.dumps(dip),
            "curve_one.json": json.dumps(dict(good, u=[0.0], T=[0.0])),
            "curve_negT.json": json.dumps(dict(good, T=[-t for t in good["T"]])),
            "curve_noN.json": json.dumps({k: v for k, v in good.items() if k not in ("N", "mu")}),
            "curve_steep.json": json.dumps(dict(good, u=[1e-300 * x for x in good["u"]], k_t=None)),
            "normal_120.json": json.dumps(_normal_curve(120.0))}


def _normal_curve(top: float, n: int = 8) -> dict:
    """A Hertzian normal approach curve N = top (p / p_top)^(3/2) up to ``top`` [N]."""
    N = top * np.linspace(0.0, 1.0, n)
    return {"schema": "damper-normal-curve/1", "approach": (1e-6 * (N / top) ** (2 / 3)).tolist(),
            "N": N.tolist(), "load": top}


def _npz(**arrays) -> bytes:
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


def matrices() -> dict[str, bytes]:
    """A 2-DOF model (tip and platform of the 2-DOF blade, SI units) and broken variants."""
    M = np.diag([0.5, 0.05])
    K = np.array([[4e7, -4e7], [-4e7, 8e7]])
    C = 1e-5 * K
    f = np.array([10.0, 0.0])
    bad_K = K.copy()
    bad_K[0, 1] = np.nan
    asym = K.copy()
    asym[0, 1] *= 2.0
    return {"m_good.npz": _npz(M=M, K=K, C=C, force=f), "m_nan.npz": _npz(M=M, K=bad_K, C=C, force=f),
            "m_negM.npz": _npz(M=-np.eye(2), K=K, C=C, force=f), "m_asym.npz": _npz(M=M, K=asym, C=C, force=f),
            "m_shape.npz": _npz(M=np.eye(3), K=K, force=f), "m_noforce.npz": _npz(M=M, K=K),
            "m_forcelen.npz": _npz(M=M, K=K, force=np.ones(5)),
            "m_cnan.npz": _npz(M=M, K=K, C=np.full((2, 2), np.inf), force=f),
            "m_text.npz": b"M = [[1, 0], [0, 1]]\n", "m_empty.npz": b"",
            "m_nokeys.npz": _npz(A=np.eye(2)), "m_trunc.npz": _npz(M=M, K=K, C=C, force=f)[:200],
            "m_complex.npz": _npz(M=M, K=K * (1 + 0.02j), force=f),
            "m_negC.npz": _npz(M=M, K=K, C=-C, force=f), "m_negK.npz": _npz(M=M, K=-K, C=C, force=f),
            "m_0x0.npz": _npz(M=np.zeros((0, 0)), K=np.zeros((0, 0)), force=np.zeros(0)),
            "m_Mhuge.npz": _npz(M=1e300 * M, K=K, C=C, force=f), "m_Mtiny.npz": _npz(M=1e-300 * M, K=K, C=C, force=f)}


def elements() -> dict[str, str | bytes]:
    jen = '[[element]]\ndofs = [1]\ntype = "jenkins"\nk = 3.85e7\nfs = 60.0\n'
    return {"el_good.toml": jen, "el_wobble.toml": jen + "wobble = 3\n",
            "el_scael.toml": '[[element]]\ndofs = [1]\ntype = "curve"\npath = "curve.json"\nscael = 2.0\n',
            "el_top.toml": "scale = 2.0\n" + jen, "el_badtoml.toml": "[[element]\ndofs = [1\n",
            "el_binary.toml": BINARY, "el_none.toml": "# no elements\n",
            "el_dof9.toml": jen.replace("dofs = [1]", "dofs = [9]"),
            "el_nok.toml": jen.replace("k = 3.85e7\n", ""), "el_type.toml": jen.replace('"jenkins"', '"magic"'),
            "el_path.toml": '[[element]]\ndofs = [1]\ntype = "curve"\npath = "missing.json"\n',
            "el_negk.toml": jen.replace("k = 3.85e7", "k = -1.0"),
            "el_dofstr.toml": jen.replace("dofs = [1]", 'dofs = ["tip"]'),
            "el_same.toml": jen.replace("dofs = [1]", "dofs = [1, 1]"),
            "el_contact.toml": '[[element]]\ntype = "contact"\ndofs = [0, 1]\nnormal = [0.0, 1.0]\nk_n = 1e8\n'
                               "wobble = 1\n"}


#: The application tests' small scene (a 7x7 cylinder contact, loop, one FRF level at H = 3).
SMALL = """title = "small scene"
want = ["virgin_curve", "k_t", "loop", "frf"]

[contact.damper]
body = "cylinder"
diameter = 5.0e-3
length = 1.2e-3
force = 120.0
mu = 0.5
grid = 7

[element]
contact = "damper"
loop_force_amplitude = 40.0
fmi_versions = [2]

[structure]
m_tip = 0.5
m_platform = 0.05
k_blade = 4.0e7
k_disk = 4.0e7
zeta = 0.002

[excitation]
forces = [30.0]

[sweep]
f_min = 880.0
f_max = 1300.0
harmonics = 3
"""
_TWO_DOF = "m_tip = 0.5\nm_platform = 0.05\nk_blade = 4.0e7\nk_disk = 4.0e7\nzeta = 0.002\n"


def _matrices_scene(npz: str, dofs: str = "[1]") -> str:
    return SMALL.replace(_TWO_DOF, f'model = "matrices"\nmatrices = "{npz}"\nelement_dofs = {dofs}\n')


#: Scene variants: file name -> (text replaced, replacement) on SMALL, or a whole text.
SCENE_EDITS = {
    "s_ok.toml": ("", ""),
    "s_loopamp.toml": ("loop_force_amplitude = 40.0", "loop_force_amplitude = 400.0"),
    "s_grid.toml": ("grid = 7", "grid = 100000"),
    "s_grid2.toml": ("grid = 7", "grid = 2"),
    "s_forces.toml": ("forces = [30.0]", "forces = []"),
    "s_forceneg.toml": ("forces = [30.0]", "forces = [-30.0]"),
    "s_harm.toml": ("harmonics = 3", "harmonics = 100000"),
    "s_harm0.toml": ("harmonics = 3", "harmonics = 0"),
    "s_accuracy.toml": ("harmonics = 3", "harmonics = 3\naccuracy = 0.6"),
    "s_samples.toml": ("fmi_versions = [2]", "fmi_versions = [2]\nloop_samples = 1000000000"),
    "s_mu0.toml": ("mu = 0.5", "mu = 0.0"),
    "s_mubig.toml": ("mu = 0.5", "mu = 1e300"),
    "s_munan.toml": ("mu = 0.5", "mu = nan"),
    "s_fmax.toml": ("f_max = 1300.0", "f_max = 800.0"),
    "s_fhuge.toml": ("f_max = 1300.0", "f_max = 1e300"),
    "s_zone.toml": ("grid = 7", "grid = 7\nzone_load = -1.0"),
    "s_hertz.toml": ("force = 120.0", "force = 1.0e9"),
    "s_unknown.toml": ('title = "small scene"', 'title = "small scene"\nwobble = 3'),
    "s_ckey.toml": ("grid = 7", "grid = 7\nscael = 2.0"),
    "s_want.toml": ('want = ["virgin_curve", "k_t", "loop", "frf"]', 'want = ["virgin_curve", "wobble"]'),
    "s_elcontact.toml": ('contact = "damper"', 'contact = "nosuch"'),
    "s_fmi.toml": ("fmi_versions = [2]", "fmi_versions = [4]"),
    "s_body.toml": ('body = "cylinder"', 'body = "cube"'),
    "s_both.toml": ("diameter = 5.0e-3", "diameter = 5.0e-3\nradius = 2.5e-3"),
    "s_nu.toml": ("grid = 7", "grid = 7\nnu = 0.5"),
    "s_kbhuge.toml": ("k_blade = 4.0e7", "k_blade = 1e300"),
    "s_zetahuge.toml": ("zeta = 0.002", "zeta = 1e300"),
    "s_fbig.toml": ("forces = [30.0]", "forces = [1e300]"),
    "s_fmintiny.toml": ("f_min = 880.0", "f_min = 1e-300"),
    "s_type.toml": ("force = 120.0", 'force = "heavy"'),
    "s_step.toml": ("harmonics = 3", "harmonics = 3\nmax_step = 1e-300"),
    "s_dupkey.toml": ("grid = 7", "grid = 7\ngrid = 9"),
    "s_contactpath.toml": ("[contact.damper]", '[contact."../../../escaped"]'),
    "s_wantempty.toml": ('want = ["virgin_curve", "k_t", "loop", "frf"]', "want = []"),
    "s_fmiempty.toml": None,
    "s_duptable.toml": ("[element]", '[contact.damper]\nbody = "sphere"\n\n[element]'),
    "s_dofs.toml": None, "s_mnan.toml": None, "s_mtext.toml": None, "s_mneg.toml": None,
    "s_mmissing.toml": None, "s_dofsame.toml": None,
}


def _jenkins_backbone(keys: str) -> str:
    """A backbone scene of the 2-DOF blade with a Jenkins element of the given keys."""
    return 'want = ["backbone"]\n[structure]\n' + _TWO_DOF + '[backbone]\nelement = "jenkins"\n' + keys


def scenes() -> dict[str, str | bytes]:
    out = {}
    for name, edit in SCENE_EDITS.items():
        if edit is not None:
            assert edit[0] in SMALL, name
            out[name] = SMALL.replace(*edit) if edit[0] else SMALL
    out |= {"s_dofs.toml": _matrices_scene("m_good.npz", "[7]"), "s_mnan.toml": _matrices_scene("m_nan.npz"),
            "s_mtext.toml": _matrices_scene("m_text.npz"), "s_mneg.toml": _matrices_scene("m_negM.npz"),
            "s_mmissing.toml": _matrices_scene("nowhere.npz"),
            "s_dofsame.toml": _matrices_scene("m_good.npz", "[1, 1]")}
    out |= {"s_toml.toml": "want = [\n[contact.damper\n", "s_empty.toml": "", "s_binary.toml": BINARY,
            "s_bbmode.toml": ('want = ["backbone"]\n[structure]\n' + _TWO_DOF + '[backbone]\nelement = "jenkins"\n'
                              "contact_stiffness = 3.85e7\nslip_force = 60.0\namplitude = [1e-7, 1e-4]\nmode = 5\n"),
            "s_bbamp.toml": ('want = ["backbone"]\n[structure]\n' + _TWO_DOF + '[backbone]\nelement = "jenkins"\n'
                             "contact_stiffness = 3.85e7\nslip_force = 60.0\namplitude = [1e-4, 1e-7]\n"),
            "s_updpoints.toml": 'want = ["optimal_load"]\n[upd]\npoints = 1000000\n',
            "s_updharm.toml": 'want = ["optimal_load"]\n[upd]\nharmonics = 100000\n',
            "s_updacc.toml": 'want = ["optimal_load"]\n[upd]\naccuracy = 1e-7\n',
            "s_mtacc.toml": 'want = ["mistuning"]\n[mistuning]\naccuracy = 0.6\n',
            "s_mtacclin.toml": 'want = ["mistuning"]\n[mistuning]\ndamper = "stuck"\naccuracy = 0.01\n',
            "s_bbacc.toml": ('want = ["backbone"]\n[structure]\n' + _TWO_DOF + '[backbone]\nelement = "jenkins"\n'
                             "contact_stiffness = 3.85e7\nslip_force = 60.0\namplitude = [1e-7, 1e-4]\n"
                             "accuracy = 0.5\n"),
            "s_updcfg.toml": 'want = ["optimal_load"]\n[upd]\nconfig = "missing.toml"\n',
            # a flat face's load past the small strains (an approach of 6 m printed before)
            "s_flatbig.toml": ('want = ["k_n"]\n[contact.damper]\nbody = "flat"\nwidth = 1.2e-3\nlength = 1.2e-3\n'
                               "force = 1e9\ngrid = 7\n"),
            "s_fmiempty.toml": SMALL.replace('want = ["virgin_curve", "k_t", "loop", "frf"]', 'want = ["fmu"]')
                                    .replace("fmi_versions = [2]", "fmi_versions = []"),
            "s_updcflow.toml": 'want = ["optimal_load"]\n[upd]\ncf_range = [1e-3, 10.0]\npoints = 3\n',
            # upd_frf: the refusals of `damper upd frf`'s options, as [upd] keys
            "s_ufnodes.toml": 'want = ["upd_frf"]\n[upd]\nsurface_nodes = 7\n',
            "s_ufmodel.toml": 'want = ["upd_frf"]\n[upd]\ncontacts = "geometry"\nsurface_model = "nodes"\n',
            "s_ufnodes4.toml": 'want = ["upd_frf"]\n[upd]\ncontacts = "surface"\nsurface_nodes = 4\n',
            "s_ufnodes42.toml": 'want = ["upd_frf"]\n[upd]\ncontacts = "surface"\nsurface_nodes = 42\n',
            "s_ufunknowns.toml": ('want = ["upd_frf"]\n[upd]\ncontacts = "surface"\nsurface_model = "nodes"\n'
                                  "surface_nodes = 41\nharmonics = 20\n"),
            "s_ufacc.toml": 'want = ["upd_frf"]\n[upd]\ncontacts = "surface"\naccuracy = 0.01\n',
            "s_ufband.toml": 'want = ["upd_frf"]\n[upd]\nband = [480.0, 440.0]\n',
            "s_ufcflow.toml": 'want = ["upd_frf"]\n[upd]\ncf = 1e-3\n',
            "s_ufolsurf.toml": 'want = ["optimal_load"]\n[upd]\ncontacts = "surface"\naccuracy = 0.01\n',
            "s_ufolsurfpts.toml": 'want = ["optimal_load"]\n[upd]\ncontacts = "surface"\npoints = 41\n',
            "s_ufolsurfnodes.toml": 'want = ["optimal_load"]\n[upd]\ncontacts = "surface"\nsurface_model = "nodes"\n',
            "s_ufolsurfgrid.toml": 'want = ["optimal_load"]\n[upd]\ncontacts = "surface"\ngrid = 20\n',
            "s_ufolsurfcfhi.toml": 'want = ["optimal_load"]\n[upd]\ncontacts = "surface"\ncf_range = [300.0, 1e12]\n',
            "s_ufolsurfaxial.toml": ('want = ["optimal_load"]\n[upd]\nconfig = "upd_axial.toml"\n'
                                     'contacts = "surface"\n'),
            "s_ufnoupd.toml": 'want = ["upd_frf"]\n',
            "s_ufaxial.toml": 'want = ["upd_frf"]\n[upd]\nconfig = "upd_axial.toml"\ncontacts = "surface"\n',
            "s_uff0tiny.toml": 'want = ["upd_frf"]\n[upd]\nf0 = 1e-300\npoints = 3\nharmonics = 1\n',
            "s_ufmu0.toml": 'want = ["upd_frf"]\n[upd]\nconfig = "upd_mu0.toml"\ncontacts = "surface"\n',
            "s_cfrone.toml": 'want = ["optimal_load"]\n[upd]\ncf_range = [100.0]\npoints = 3\n',
            "s_mtcflow.toml": 'want = ["mistuning"]\n[mistuning]\ncf = 1e-3\nsamples = 1\n',
            "s_mtci.toml": 'want = ["mistuning"]\n[mistuning]\nuntil_ci = 1e300\n',
            "s_mtband.toml": 'want = ["mistuning"]\n[mistuning]\ndamper = "free"\nband = [380.0, 424.0]\nsamples = 1\n',
            "s_mtblades.toml": 'want = ["mistuning"]\n[mistuning]\ndamper = "free"\nblades = 2\nsamples = 1\n',
            "s_bbk.toml": _jenkins_backbone("contact_stiffness = 1e300\nslip_force = 60.0\n"
                                            "amplitude = [1e-7, 1e-4]\n"),
            "s_bbf.toml": _jenkins_backbone("contact_stiffness = 3.85e7\nslip_force = 1e300\n"
                                            "amplitude = [1e-7, 1e-4]\n"),
            "s_bbamphuge.toml": _jenkins_backbone("contact_stiffness = 3.85e7\nslip_force = 60.0\n"
                                                  "amplitude = [1e-7, 1e300]\n"),
            "s_updbad.toml": 'want = ["optimal_load"]\n[upd]\nconfig = "upd_unknown.toml"\n',
            "s_nocontact.toml": 'want = ["virgin_curve"]\n',
            # the SIGINT and cache cases: a cold condensation that takes a few seconds (kn only)
            "s_kn.toml": ('want = ["k_n", "report"]\n[contact.damper]\nbody = "cylinder"\ndiameter = 5.0e-3\n'
                          "length = 1.2e-3\nforce = 120.0\ngrid = 21\n"),
            "s_kn_small.toml": ('want = ["k_n"]\n[contact.damper]\nbody = "sphere"\nradius = 0.01\n'
                                'model = "halfspace"\nforce = 100.0\ngrid = 5\n')}
    return out


def upd_files() -> dict[str, str | bytes]:
    return {"upd_unknown.toml": "[load]\nwobble = 3\n", "upd_binary.toml": BINARY,
            "upd_badtoml.toml": "[load\n", "upd_section.toml": "[nosuch]\nx = 1\n",
            "upd_mu0.toml": "[damper]\nmu = 0.0\n", "upd_axial.toml": '[blade]\nfile = "axial_blade.npz"\n',
            "axial_blade.npz": _axial_blade()}


def _axial_blade() -> bytes:
    """UPD-24's blade plus an axial platform DOF w_p (its own spring to ground): platform
    points [u, v, w], a sector that is not planar."""
    from harmonic_balance.bladed_disk.blade import blade_arrays
    from harmonic_balance.bladed_disk.config import load_config

    arr = blade_arrays(load_config().blade())
    n = arr["M"].shape[0]
    grow = lambda A, d: np.pad(A, ((0, 1), (0, 1))) + np.diag([0.0] * n + [d])  # noqa: E731
    arr.update(M=grow(arr["M"], 0.1), K=grow(arr["K"], 8e5), K_next=grow(arr["K_next"], 0.0),
               dofs=np.append(arr["dofs"], "w_p"), left=np.array(["u_p", "v_p", "w_p"]),
               right=np.array(["u_p", "v_p", "w_p"]), forced=np.array("u_a"))
    buf = io.BytesIO()
    np.savez(buf, **arr)
    return buf.getvalue()


def _forged_sizes(blob: bytes, size: int) -> bytes:
    """A zip archive whose members declare ``size`` bytes unpacked (local and central headers)."""
    out = bytearray(blob)
    for sig, offset in ((b"PK\x03\x04", 22), (b"PK\x01\x02", 24)):
        at = out.find(sig)
        while at >= 0:
            out[at + offset:at + offset + 4] = size.to_bytes(4, "little")
            at = out.find(sig, at + 4)
    return bytes(out)


def forged_archives() -> dict[str, bytes]:
    """Forged archives: members declaring 4 GiB (an SSP, a model .npz), an SSP of 5000
    members, Matrix Market headers declaring a 1e8 x 1e8 matrix and 1e12 entries."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("resources/system.json", '{"kind": "damper-ring"}')
    many = io.BytesIO()
    with zipfile.ZipFile(many, "w") as zf:
        for i in range(5000):
            zf.writestr(f"m{i}", b"")
    mtx = b"%%MatrixMarket matrix coordinate real general\n100000000 100000000 1\n1 1 1.0\n"
    return {"bomb.ssp": _forged_sizes(buf.getvalue(), 2**32 - 16), "many.ssp": many.getvalue(),
            "m_bomb.npz": _forged_sizes(matrices()["m_good.npz"], 2**32 - 16), "big_M.mtx": mtx, "big_K.mtx": mtx,
            "upd_bigmtx.toml": b'[blade]\nM = "big_M.mtx"\nK = "big_K.mtx"\n',
            "big_nnz.mtx": b"%%MatrixMarket matrix coordinate real general\n1000 1000 1000000000000\n1 1 1.0\n"}


def typed_files() -> dict[str, str | bytes]:
    """Files well-formed as JSON / TOML whose content the typed models refuse: booleans or
    strings as numbers, lists of the wrong length, unknown keys, a curve above its own
    mu N, sizes out of bounds, and ring archives whose ``system.json`` is forged."""
    good = _curve()
    normal = {"schema": "damper-normal-curve/1", "approach": [0.0, 1e-6, 2e-6], "N": [0.0, 50.0, 140.0]}
    out = {"curve_mutrue.json": json.dumps(dict(good, mu=True)),
           "curve_Tstr.json": json.dumps(dict(good, T=[str(t) for t in good["T"]])),
           "curve_wobble.json": json.dumps(dict(good, wobble=3)),
           # plateau 180 N against the file's mu N = 0.5 x 120 N = 60 N
           "curve_plateau.json": json.dumps(dict(good, T=[1.8 * t for t in good["T"]], N=120.0)),
           "curve_huge.json": json.dumps(dict(good, T=[t * 1e300 for t in good["T"]])),
           "normal_good.json": json.dumps(normal),
           "normal_wobble.json": json.dumps(dict(normal, wobble=3)),
           "normal_Nstr.json": json.dumps(dict(normal, N=["0", "50", "140"])),
           "normal_steep.json": json.dumps(dict(normal, approach=[0.0, 1e-306, 2e-306])),
           "upd_mutrue.toml": "[damper]\nmu = true\n", "upd_mdstr.toml": '[damper]\nm_d = "0.005"\n',
           "upd_band3.toml": "[load]\nband_hz = [400.0, 450.0, 500.0]\n",
           "upd_bandnan.toml": "[load]\nband_hz = [nan, 500.0]\n",
           "upd_blades.toml": "[disk]\nblades = 100000000\n"}
    for name, info in forged_ring_infos().items():
        out[f"ring_{name}.ssp"] = _ring_archive(info)
    return out


def _ring_info() -> dict:
    """A ring archive's description as ``damper system`` writes it (UPD-24, 4 ring blades)."""
    return {"kind": "damper-ring", "config": "UPD-24", "blades": 24, "engine_order": 6, "ring_blades": 4,
            "interblade_phase": 1.5707963267948966, "cf": 120.0, "f0": 30.0, "frequency_hz": 450.0,
            "fmi_version": 2, "omega_max": 271903.68, "step_limit": 7.3555e-06, "default_step": 9.1944e-07,
            "step_fraction": 0.125, "damper_substep": 3.2116e-06,
            "blades_components": [f"blade{j}" for j in range(4)],
            "damper_components": [f"damper{j}" for j in range(4)],
            "response": "q_u_a", "response_dof": "u_a", "contacts": ["left", "right1", "right2"],
            "coupling_dofs": ["u_r"], "K_next_coupling": [[-2e7]]}


def forged_ring_infos() -> dict[str, object]:
    """Seven forged ``resources/system.json``: keys missing, wrong types, null, a list."""
    info = _ring_info()
    return {"no_step_limit": {k: v for k, v in info.items() if k != "step_limit"},
            "no_components": {k: v for k, v in info.items() if k != "blades_components"},
            "step_abc": info | {"default_step": "abc"}, "limit_null": info | {"step_limit": None},
            "list": [info], "components_text": info | {"blades_components": "blade0"},
            "coupling_text": info | {"K_next_coupling": "x"}}


def _ring_archive(info, ssd: str = "<ssd:SystemStructureDescription/>\n") -> bytes:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        zf.writestr("SystemStructure.ssd", ssd)
        zf.writestr("resources/system.json", json.dumps(info))
    return buf.getvalue()


def archives() -> dict[str, bytes]:
    """A ring archive whose SystemStructure.ssd uses an FMU the archive does not hold."""
    ssd = ('<ssd:SystemStructureDescription><ssd:System><ssd:Elements><ssd:Component name="blade0" '
           'source="resources/blade.fmu"/></ssd:Elements></ssd:System></ssd:SystemStructureDescription>\n')
    return {"ring_nofmu.ssp": _ring_archive(_ring_info(), ssd)}


def imported_bodies() -> dict[str, bytes]:
    """Bodies for ``damper normal --stiffness/--nodes``: the half-space model's flat blocks
    (a sphere's curvature in its gap, none in the coordinates), a flat punch in contact
    over every node."""
    import tempfile

    from contact_core import assembly, byo, mesh
    from contact_core.spec import ContactSpec

    spec = ContactSpec(body="sphere", model="halfspace", grid=3)
    b1, b2, meta = mesh.build(spec)
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        for i, body in ((1, b1), (2, b2)):
            k, n = Path(tmp) / f"byo_K{i}.npz", Path(tmp) / f"byo_n{i}.npz"
            byo.export_body(body, assembly.stiffness(body.p, body.t, spec.E1, spec.nu1), k, n,
                            symmetry=meta["symmetry"])
            out |= {k.name: k.read_bytes(), n.name: n.read_bytes()}
    return out


def make(folder: Path) -> Path:
    """Write every fixture into ``folder``; return it."""
    folder.mkdir(parents=True, exist_ok=True)
    for group in (curves(), matrices(), elements(), scenes(), upd_files(), typed_files(), archives(),
                  forged_archives(), imported_bodies()):
        for name, content in group.items():
            path = folder / name
            if isinstance(content, bytes):
                path.write_bytes(content)
            else:
                path.write_text(content)
    (folder / "binary.bin").write_bytes(BINARY)
    (folder / "a_file").write_text("not a folder\n")
    return folder
