"""Process checks shared by the tests that kill a hung child."""
import time
from pathlib import Path

#: Polls of a killed process before it counts as left running, POLL_S apart: SIGKILL takes
#: effect once the kernel schedules the process, which on a busy machine can follow the
#: killer's return by a moment; 10 s in all, far below the hung children's 60 s sleep, so a
#: child that was not killed still fails.
POLLS, POLL_S = 200, 0.05


def running(pid: int) -> bool:
    """Is process ``pid`` still there (a zombie, dead but not reaped, is not running)?"""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except FileNotFoundError:
        return False
    return state not in ("Z", "X")


def gone_after_kill(pid: int) -> bool:
    """Has the killed process ``pid`` left (polled, see POLLS)?"""
    for _ in range(POLLS):
        if not running(pid):
            return True
        time.sleep(POLL_S)
    return not running(pid)
