"""Files a command reads and writes: no input is ever overwritten (whatever the spelling of
the output path), nothing is renamed over a FIFO or a device, every input is read bounded
(its size checked first, at most cap + 1 bytes read, FIFOs and devices refused without
blocking), forged archives are refused before they are unpacked, a cache folder of the
user's is never taken over, new files follow the umask and SIGTERM cleans up as Ctrl-C."""
import os
import signal
import stat
import tempfile
import zipfile
from pathlib import Path

import pytest

import damper.cli.fmu as fmu_cli
from contact_core import fileio
from contact_core.fileio import (
    InputOverwriteError,
    NotRegularFileError,
    atomic_write,
    check_matrix_market,
    guard_inputs,
    open_npz,
    read_bounded,
    read_text_bounded,
)
from damper.cache import Store
from damper.cli import main as damper
from damper.cosim import read_info
from damper.stress import input_fixtures as fx

CURVE = fx.curves()["curve.json"]
NPZ = fx.matrices()["m_good.npz"]
EL = fx.elements()["el_good.toml"]
SDOF = ["--mass", "1", "--stiffness", "1", "--damping", "0.01", "--contact-stiffness", "1", "--slip-force", "0.05",
        "--force", "0.05"]


#: Files up to this size are compared by content; larger ones (the sparse 3 GiB inputs) by
#: size, modification time and inode: reading them would take the memory the tests guard.
CONTENT_BYTES = 2**20


def _folder(tmp_path: Path) -> dict:
    """Every file below ``tmp_path``: relative name -> (file type, content or (size, mtime, inode))."""
    out = {}
    for p in sorted(tmp_path.rglob("*")):
        st = os.lstat(p)
        small = stat.S_ISREG(st.st_mode) and st.st_size <= CONTENT_BYTES
        out[str(p.relative_to(tmp_path))] = (stat.S_IFMT(st.st_mode), p.read_bytes() if small
                                             else (st.st_size, st.st_mtime_ns, st.st_ino))
    return out


def _refused(argv, tmp_path, capsys, text: str) -> None:
    """``damper argv`` exits 2 with one line holding ``text`` and leaves ``tmp_path`` as it was."""
    before = _folder(tmp_path)
    assert damper(argv) == 2
    err = capsys.readouterr().err
    assert text in err and err.count("\n") == 1, err
    assert _folder(tmp_path) == before


# -- an output is never one of the inputs ----------------------------------------------
@pytest.mark.parametrize("spelling", ["same", "dot", "absolute", "symlink", "hardlink"])
def test_fmu_output_onto_its_curve_is_refused_whatever_the_spelling(tmp_path, monkeypatch, capsys, spelling):
    monkeypatch.chdir(tmp_path)
    Path("c.json").write_text(CURVE)
    out = {"same": "c.json", "dot": "./c.json", "absolute": str(tmp_path / "c.json"), "symlink": "l.json",
           "hardlink": "h.json"}[spelling]
    if spelling == "symlink":
        os.symlink("c.json", "l.json")
    if spelling == "hardlink":
        os.link("c.json", "h.json")
    _refused(["fmu", "--curve", "c.json", "-o", out], tmp_path, capsys, "is the input --curve")
    assert Path("c.json").read_text() == CURVE


@pytest.mark.parametrize("command,out", [("frf", "m.npz"), ("frf", "el.toml"), ("backbone", "m.npz")])
def test_frf_and_backbone_out_onto_their_model_or_elements_is_refused(tmp_path, monkeypatch, capsys, command, out):
    monkeypatch.chdir(tmp_path)
    Path("m.npz").write_bytes(NPZ)
    Path("el.toml").write_text(EL)
    span = ["--omega", "100", "300"] if command == "frf" else ["--amplitude", "1e-6", "1e-4"]
    _refused([command, "--model", "m.npz", "--elements", "el.toml", *span, "--out", out], tmp_path, capsys,
             "is the input --")
    assert Path("m.npz").read_bytes() == NPZ and Path("el.toml").read_text() == EL


def test_system_output_onto_its_config_is_refused(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    Path("u.toml").write_text("# the bundled UPD-24\n")
    _refused(["system", "--config", "u.toml", "-o", "u.toml"], tmp_path, capsys, "is the input --config")


def test_a_result_folder_holding_the_scene_is_refused(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    Path("s.toml").write_text(fx.SMALL)
    _refused(["run", "s.toml", "--out", "."], tmp_path, capsys, "holds the input scene")


@pytest.mark.parametrize(("command", "folder"), [(["run"], "out/s"),
                                               (["sweep", "--param", "upd.points", "--values", "3", "--serial"],
                                                "out/sweep_s")])
def test_the_default_result_folder_holding_the_scene_is_refused_before_any_work(tmp_path, monkeypatch, capsys,
                                                                                 command, folder):
    """No --out: the default folder out/<scene name> (sweep: out/sweep_<scene name>) that holds
    the scene is refused as --out is, nothing written beside it (it was, and the run failed
    on run.json afterwards when the scene was named so)."""
    monkeypatch.chdir(tmp_path)
    Path(folder).mkdir(parents=True)
    Path(folder, "s.toml").write_text('want = ["upd_frf"]\n[upd]\npoints = 3\nharmonics = 1\n')
    _refused([command[0], f"{folder}/s.toml", *command[1:]], tmp_path, capsys, "holds the input scene")
    assert [p.name for p in Path(folder).iterdir()] == ["s.toml"]


def test_save_png_writes_a_png_and_leaves_nothing_when_drawing_fails(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    ax.plot([0, 1], [1, 0])
    assert fileio.save_png(fig, tmp_path / "a" / "f.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    ax.text(0, 0, "$\\undefinedmacro$")   # mathtext fails while the figure is drawn
    with pytest.raises(ValueError):
        fileio.save_png(fig, tmp_path / "b.png")
    plt.close(fig)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a"]


@pytest.mark.parametrize("command", [["run"], ["sweep", "--param", "upd.points", "--values", "3", "--serial"]])
def test_a_result_folder_holding_a_file_the_scene_names_is_refused(tmp_path, monkeypatch, capsys, command):
    """The scene's own files (here its [upd] model) are inputs too: a result folder that holds
    one is refused before any work, the file and the folder left as they were."""
    monkeypatch.chdir(tmp_path)
    Path("scenes").mkdir()
    Path("res").mkdir()
    Path("res/upd.toml").write_text("# the bundled UPD-24\n")
    Path("scenes/s.toml").write_text('want = ["optimal_load"]\n[upd]\nconfig = "../res/upd.toml"\npoints = 3\n')
    _refused([command[0], "scenes/s.toml", *command[1:], "--out", "res"], tmp_path, capsys,
             "holds the input upd.config")
    assert sorted(p.name for p in Path("res").iterdir()) == ["upd.toml"]


def test_inputs_read_by_a_command_are_never_replaced_by_its_writes(tmp_path):
    """The guard behind every command (files named inside a scene included); a library user
    outside it may read, edit and write back a file."""
    path = tmp_path / "c.json"
    path.write_text(CURVE)
    with guard_inputs():
        read_text_bounded(path)
        with pytest.raises(InputOverwriteError, match="input file"):
            atomic_write(tmp_path / "." / "c.json", "{}")
        atomic_write(tmp_path / "other.json", "{}")
    assert path.read_text() == CURVE
    read_text_bounded(path)
    atomic_write(path, "{}")
    assert path.read_text() == "{}"


# -- never renamed over something that is not a regular file ---------------------------
@pytest.mark.parametrize("argv", [["fmu", "--curve", "c.json", "-o", "p"],
                                  ["frf", "--model", "sdof", *SDOF, "--omega", "0.9", "1.3", "--out", "p"]])
def test_an_output_that_is_a_fifo_is_refused_and_stays_a_fifo(tmp_path, monkeypatch, capsys, argv):
    monkeypatch.chdir(tmp_path)
    Path("c.json").write_text(CURVE)
    os.mkfifo("p")
    _refused(argv, tmp_path, capsys, "FIFO")
    assert stat.S_ISFIFO(os.lstat("p").st_mode)


def test_atomic_write_refuses_a_fifo_and_writes_through_a_symlink(tmp_path):
    os.mkfifo(tmp_path / "p")
    with pytest.raises(NotRegularFileError, match="FIFO"):
        atomic_write(tmp_path / "p", b"x")
    assert stat.S_ISFIFO(os.lstat(tmp_path / "p").st_mode)
    (tmp_path / "t.txt").write_text("old")
    os.symlink("t.txt", tmp_path / "l.txt")
    atomic_write(tmp_path / "l.txt", "new")
    assert os.path.islink(tmp_path / "l.txt") and (tmp_path / "t.txt").read_text() == "new"


# -- bounded reads ---------------------------------------------------------------------
def test_a_file_above_the_cap_is_refused_before_reading_with_its_size_and_the_cap(tmp_path):
    big = tmp_path / "big.json"
    with open(big, "wb") as fh:
        fh.truncate(3 * 2**30)                       # sparse: no disk, no memory
    with pytest.raises(ValueError, match=r"big.json is 3.0 GiB, above the limit of 16.0 MiB"):
        read_text_bounded(big, what="curve file")


def test_a_file_that_grows_while_read_is_cut_at_the_cap(tmp_path, monkeypatch):
    path = tmp_path / "grows.json"
    path.write_bytes(b"x" * 100)
    real = os.fstat
    monkeypatch.setattr(fileio.os, "fstat", lambda fd: os.stat_result((*real(fd)[:6], 10, *real(fd)[7:])))
    with pytest.raises(ValueError, match="grew above the limit of 50 bytes"):
        read_bounded(path, 50)


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="no /dev/zero here")
def test_devices_and_fifos_as_inputs_are_refused_without_blocking(tmp_path):
    with pytest.raises(NotRegularFileError, match="character device"):
        read_bounded("/dev/zero", 100)
    os.mkfifo(tmp_path / "p")                        # no writer: a blocking open would never return
    with pytest.raises(NotRegularFileError, match="FIFO"):
        read_bounded(tmp_path / "p", 100)


@pytest.mark.parametrize("argv", [["fmu", "--curve", "IN", "-o", "d.fmu"],
                                  ["loop", "--curve", "IN", "--amplitude", "2e-6"],
                                  ["run", "IN"], ["upd", "frf", "--config", "IN"]])
def test_commands_refuse_a_huge_input_in_one_line(tmp_path, monkeypatch, capsys, argv):
    monkeypatch.chdir(tmp_path)
    with open("IN", "wb") as fh:
        fh.truncate(3 * 2**30)
    _refused(argv, tmp_path, capsys, "3.0 GiB, above the limit")


def test_garbage_as_npz_is_not_called_pickled_data(tmp_path):
    path = tmp_path / "m.npz"
    path.write_bytes(b"\x80\x04garbage that numpy would offer to unpickle")
    with pytest.raises(ValueError, match="is not an .npz archive of arrays") as err:
        open_npz(path, "model file")
    assert "pickle" not in str(err.value)


def test_forged_archives_are_refused_before_unpacking(tmp_path):
    arch = fx.forged_archives()
    for name in ("bomb.ssp", "many.ssp", "m_bomb.npz"):
        (tmp_path / name).write_bytes(arch[name])
    with pytest.raises(ValueError, match="unpack to 4.0 GiB, above the limit"):
        read_info(tmp_path / "bomb.ssp")
    with pytest.raises(ValueError, match="5000 members, above the limit"):
        read_info(tmp_path / "many.ssp")
    with pytest.raises(ValueError, match="unpack to .* GiB, above the limit"):
        open_npz(tmp_path / "m_bomb.npz")
    with zipfile.ZipFile(tmp_path / "bomb.ssp") as zf:   # the forgery declares what the check reads
        assert zf.infolist()[0].file_size > fileio.MAX_SSP_BYTES


def test_a_matrix_market_header_declaring_1e8_squared_is_refused_from_the_header(tmp_path, capsys):
    arch = fx.forged_archives()
    for name in ("big_M.mtx", "big_K.mtx", "upd_bigmtx.toml"):
        (tmp_path / name).write_bytes(arch[name])
    with pytest.raises(ValueError, match=r"100000000 x 100000000 matrix .* 71.1 PiB"):
        check_matrix_market(tmp_path / "big_M.mtx", dense=True)
    _refused(["upd", "modes", "--config", str(tmp_path / "upd_bigmtx.toml")], tmp_path, capsys, "71.1 PiB")


# -- the cache -------------------------------------------------------------------------
@pytest.mark.parametrize("argv", [["cache", "clear"], ["normal", "--body", "sphere", "--radius", "0.01", "--force",
                                                       "100", "--model", "halfspace", "--grid", "5"]])
def test_a_folder_with_a_users_24_hex_npz_and_no_tag_is_not_taken_over(tmp_path, capsys, argv):
    user = tmp_path / "cd" / "0123456789abcdef01234567.npz"
    user.parent.mkdir()
    user.write_bytes(b"user data")
    _refused([*argv, "--cache-dir", str(user.parent)], tmp_path, capsys, "not a damper cache")
    assert user.read_bytes() == b"user data"


def test_a_fifo_named_like_a_cache_entry_is_a_miss_not_a_hang(tmp_path):
    warned = []
    s = Store(tmp_path / "c", warn=warned.append)
    path = s.put("k1", {"x": [1.0]}, {})
    path.unlink()
    os.mkfifo(path)
    assert s.get("k1") is None and s.misses == 1
    assert len(warned) == 1 and "not a regular file" in warned[0]


# -- modes and signals -----------------------------------------------------------------
def test_fmu_follows_the_umask(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    Path("c.json").write_text(CURVE)
    old = os.umask(0o077)
    try:
        assert damper(["fmu", "--curve", "c.json", "-o", "d.fmu"]) == 0
    finally:
        os.umask(old)
    assert stat.S_IMODE(os.stat("d.fmu").st_mode) == 0o600


def test_sigterm_exits_143_in_one_line_and_removes_temporary_folders(tmp_path, monkeypatch, capsys):
    made = []

    def work(args):
        with tempfile.TemporaryDirectory(prefix="damper_test_", dir=tmp_path) as tmp:
            made.append(tmp)
            os.kill(os.getpid(), signal.SIGTERM)
            signal.pause()                           # never reached: the handler raises first
        return 0

    monkeypatch.setattr(fmu_cli, "run", work)
    before = signal.getsignal(signal.SIGTERM)
    assert damper(["fmu", "--curve", "c.json", "-o", str(tmp_path / "d.fmu")]) == 143
    assert made and not os.path.exists(made[0])
    assert capsys.readouterr().err == "damper fmu: terminated (SIGTERM)\n"
    assert signal.getsignal(signal.SIGTERM) is before


def test_dask_workers_temporary_files_are_removed_by_close(tmp_path, monkeypatch):
    """A worker stopped in the middle of a task never cleans up: its TMPDIR is ours to remove."""
    from damper.tasks import executor

    monkeypatch.setenv("TMPDIR", str(tmp_path))
    monkeypatch.setattr(tempfile, "tempdir", None)            # this process re-reads TMPDIR
    submit, gather, close = executor(None, 1, serial=False)
    try:
        left = gather([submit(tempfile.mkdtemp)])[0]           # a worker's folder, never removed by it
        assert os.path.isdir(left) and Path(left).parent.name.startswith("damper_workers_")
    finally:
        close()
    assert not os.path.exists(left) and not list(tmp_path.iterdir())
