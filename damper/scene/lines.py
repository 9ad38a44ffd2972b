"""Line numbers of the keys of a TOML text, for error messages.

``tomllib`` returns values without positions; this scanner finds the line of each
table header and ``key = value`` line so that a validation error can name the file
line. It understands what scene files use (tables, arrays of tables, bare, quoted and
dotted keys, multi-line arrays and strings) and never fails: a key it cannot place
gets its table's line, or none.
"""
from __future__ import annotations

import re

_HEADER = re.compile(r"^\s*(\[\[?)\s*([^\]]+?)\s*\]\]?\s*(#.*)?$")
_KEY = re.compile(r"""^\s*((?:[A-Za-z0-9_-]+|"[^"]*"|'[^']*')(?:\s*\.\s*(?:[A-Za-z0-9_-]+|"[^"]*"|'[^']*'))*)\s*=""")


def _split_key(text: str) -> tuple[str, ...]:
    parts = re.findall(r"""[A-Za-z0-9_-]+|"[^"]*"|'[^']*'""", text)
    return tuple(p.strip("\"'") for p in parts)


def key_lines(text: str) -> dict[tuple, int]:
    """Map every key path (tuple of names; array-of-table items as an index) to its 1-based line."""
    lines: dict[tuple, int] = {}
    counts: dict[tuple, int] = {}
    table: tuple = ()
    depth = 0          # open brackets of a multi-line array / inline table
    in_string = None   # the delimiter of an open multi-line string
    for n, line in enumerate(text.splitlines(), start=1):
        if in_string:
            if in_string in line:
                in_string = None
            continue
        if depth == 0:
            m = _HEADER.match(line)
            if m:
                path = _split_key(m.group(2))
                if m.group(1) == "[[":
                    i = counts.get(path, 0)
                    counts[path] = i + 1
                    lines.setdefault(path, n)
                    table = path + (i,)
                else:
                    table = path
                lines.setdefault(table, n)
                continue
            m = _KEY.match(line)
            if m:
                lines.setdefault(table + _split_key(m.group(1)), n)
                rest = line[m.end():]
                for delim in ('"""', "'''"):
                    if rest.count(delim) % 2 == 1:
                        in_string = delim
                depth = max(depth + _brackets(rest), 0)
                continue
        else:
            depth = max(depth + _brackets(line), 0)
    return lines


def _brackets(text: str) -> int:
    """Net open brackets/braces outside strings and comments."""
    net, quote = 0, None
    for c in text:
        if quote:
            if c == quote:
                quote = None
        elif c in "\"'":
            quote = c
        elif c == "#":
            break
        elif c in "[{":
            net += 1
        elif c in "]}":
            net -= 1
    return net


def line_of(lines: dict[tuple, int], path: tuple) -> int | None:
    """Line of ``path``, else of its nearest enclosing table that has one."""
    for cut in range(len(path), 0, -1):
        if path[:cut] in lines:
            return lines[path[:cut]]
    return None
