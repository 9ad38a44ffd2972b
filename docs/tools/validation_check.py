"""Is the validation table complete and still true? Compare a test run's reference checks with the recorded table.

    python docs/tools/validation_check.py build/validation.json docs/data/validation.json

The first file is what this test run recorded (``DAMPER_VALIDATION_JSON``), the second
the data the documentation renders (``make validation``). Fails (exit 1) when a check
that the run made is missing from the table, when the table lists a check of a test
that passed in this run without making it (renamed or removed), or when a check's error
``|value - reference|`` grew past its growth factor (``refcheck.check(growth=...)``,
10 by default) times the recorded error: then the table no longer describes the tests.
A regression well inside a test's tolerance shows here. Errors at round-off level move
freely below a floor (:data:`ROUNDOFF_RTOL` of the reference, :data:`BOUND_SHARE` of
the check's bound). ``make validation`` regenerates the table after a deliberate change.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

#: Errors below this share of |reference| are round-off, free to move between machines
#: (BLAS builds, thread counts, compilers).
ROUNDOFF_RTOL = 1e-12
#: Errors below this share of the check's own bound are noise for the comparison: the
#: assert in the test is the stricter check there.
BOUND_SHARE = 1e-3
#: Growth factor of records that do not state one (tables written before it was recorded).
DEFAULT_GROWTH = 10.0


def keys(records: list[dict]) -> set[tuple[str, str]]:
    return {(r["test"], r["quantity"]) for r in records}


def error(record: dict) -> float:
    """The recorded error |value - reference| (from the values when not recorded)."""
    if "error" in record:
        return float(record["error"])
    return abs(float(record["value"]) - float(record["reference"]))


def allowed(run: dict, table: dict) -> float:
    """Largest error the run may show for a check recorded in the table."""
    growth = float(run.get("growth", table.get("growth", DEFAULT_GROWTH)))
    floor = max(ROUNDOFF_RTOL * abs(float(run["reference"])), BOUND_SHARE * float(run.get("bound", 0.0)))
    return growth * error(table) + floor


def grown(run: list[dict], table: list[dict]) -> list[tuple[dict, dict]]:
    """The (run, table) record pairs whose error grew past what :func:`allowed` lets."""
    recorded = {(r["test"], r["quantity"]): r for r in table}
    out = []
    for r in run:
        t = recorded.get((r["test"], r["quantity"]))
        if t is not None and error(r) > allowed(r, t):
            out.append((r, t))
    return out


def main(argv: list[str]) -> int:
    if len(argv) != 2:
        print(__doc__.strip().splitlines()[2].strip(), file=sys.stderr)
        return 2
    run_path, table_path = map(Path, argv)
    if not run_path.exists():
        print(f"validation check: no records of this run in {run_path}", file=sys.stderr)
        return 2
    run = json.loads(run_path.read_text())
    table = json.loads(table_path.read_text()) if table_path.exists() else {"records": []}
    now, listed = keys(run["records"]), keys(table["records"])
    if listed and not now:   # a run that collected or passed nothing checks nothing
        print(f"validation check: the run in {run_path} recorded no reference check "
              f"({len(listed)} in the table): did the tests run?", file=sys.stderr)
        return 1
    passed = set(run.get("passed_tests", []))
    missing = sorted(now - listed)
    stale = sorted(k for k in listed - now if k[0] in passed)
    worse = grown(run["records"], table["records"])
    for test, quantity in missing:
        print(f"not in the validation table: {test}: {quantity}", file=sys.stderr)
    for test, quantity in stale:
        print(f"in the validation table but no longer checked: {test}: {quantity}", file=sys.stderr)
    for r, t in worse:
        print(f"error grew: {r['test']}: {r['quantity']}: {error(r):.3g} against {error(t):.3g} recorded "
              f"(allowed {allowed(r, t):.3g})", file=sys.stderr)
    if missing or stale or worse:
        print(f"validation check: {table_path} does not match the tests; find the cause of a grown error, "
              f"then run `make validation`", file=sys.stderr)
        return 1
    print(f"validation check: the table lists all {len(now)} reference checks of this run, "
          f"no error grew past its factor")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
