"""What a failed ``damper`` command leaves on stdout: nothing, or with ``--json`` its one
error object (``damper.cli``: exit codes)."""
import json


def no_result(out: str, err: str, code: int) -> bool:
    """True when ``out`` holds no result: empty, or the JSON error object of a ``--json``
    run, ``{"error": <the last line on stderr>, "exit_code": code}``."""
    if out == "":
        return True
    try:
        obj = json.loads(out)
    except ValueError:
        return False
    return obj == {"error": err.strip().splitlines()[-1], "exit_code": code}
