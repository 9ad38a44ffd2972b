"""Whether the running command printed its one JSON object on stdout.

:func:`damper.cli.common.print_json` sets it; ``damper.cli.main`` clears it when a
command starts (tests run several in one process) and, on a failure with ``--json``,
prints the error object only when the command printed none (one JSON object on stdout,
whatever happens). A module of its own: both import it, neither imports the other.
"""

#: ``printed``: the command's JSON object is on stdout.
STATE = {"printed": False}
