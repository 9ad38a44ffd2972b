"""Is the validation table complete? Compare a test run's reference checks with the recorded table.

    python docs/tools/validation_check.py build/validation.json docs/data/validation.json

The first file is what this test run recorded (``DAMPER_VALIDATION_JSON``), the second
the data the documentation renders (``make validation``). Fails (exit 1) when a check
that the run made is missing from the table, or when the table lists a check of a test
that passed in this run without making it (renamed or removed): then the table no
longer describes the tests, and ``make validation`` regenerates it. Values are not
compared (they move with the code by less than their tolerances).
"""
from __future__ import annotations

import json
import sys
from pathlib import Path


def keys(records: list[dict]) -> set[tuple[str, str]]:
    return {(r["test"], r["quantity"]) for r in records}


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
    passed = set(run.get("passed_tests", []))
    missing = sorted(now - listed)
    stale = sorted(k for k in listed - now if k[0] in passed)
    for test, quantity in missing:
        print(f"not in the validation table: {test}: {quantity}", file=sys.stderr)
    for test, quantity in stale:
        print(f"in the validation table but no longer checked: {test}: {quantity}", file=sys.stderr)
    if missing or stale:
        print(f"validation check: {table_path} does not match the tests; run `make validation`", file=sys.stderr)
        return 1
    print(f"validation check: the table lists all {len(now)} reference checks of this run")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
