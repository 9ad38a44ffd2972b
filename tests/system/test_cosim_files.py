"""Files of ``damper system`` / ``damper cosim``: the archive follows the umask, and SIGTERM
(like Ctrl-C) removes the unpacked archive on the way out."""
import os
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

import pytest

#: Seconds to wait for the unpacked archive to appear (libcosim loading eight FMUs takes ~1 s).
#: The run asks for 10000 periods (2.5e7 steps, below the step bound, hours): SIGTERM comes first.
UNPACK_WAIT_S = 120


def test_system_archive_follows_the_umask(tmp_path):
    from damper.cli import main as damper

    old = os.umask(0o077)
    try:
        assert damper(["system", "--cf", "120", "--f0", "30", "-o", str(tmp_path / "r.ssp")]) == 0
    finally:
        os.umask(old)
    assert stat.S_IMODE(os.stat(tmp_path / "r.ssp").st_mode) == 0o600


def test_sigterm_during_cosim_removes_the_unpacked_archive(ring_ssp, tmp_path):
    pytest.importorskip("libcosimpy", reason="libcosimpy (PyPI) runs the co-simulation")
    env = dict(os.environ, TMPDIR=str(tmp_path))
    p = subprocess.Popen([str(Path(sys.executable).parent / "damper"), "cosim", str(ring_ssp), "--frequency-hz", "430",
                          "--periods", "10000", "--tol", "0"], env=env, stdout=subprocess.DEVNULL,
                         stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + UNPACK_WAIT_S
    while not list(tmp_path.glob("damper_cosim_*")) and p.poll() is None and time.monotonic() < deadline:
        time.sleep(0.1)
    if not list(tmp_path.glob("damper_cosim_*")):
        p.kill()
        pytest.fail(f"the run never unpacked its archive: {p.communicate()[1][-300:]}")
    p.send_signal(signal.SIGTERM)
    err = p.communicate(timeout=UNPACK_WAIT_S)[1]
    assert p.returncode == 143 and err.strip().splitlines()[-1] == "damper cosim: terminated (SIGTERM)"
    assert not [q for q in Path(tmp_path).iterdir() if q.name.startswith("damper_")]
