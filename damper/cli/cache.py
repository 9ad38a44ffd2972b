"""``damper cache``: the content-addressed cache every stage shares.

Examples::

    damper cache info [--json]
    damper cache clear

Location: ``--cache-dir``, else ``$DAMPER_CACHE_DIR``, else ``.damper_cache``; size
limit ``--cache-max-mb``, else ``$DAMPER_CACHE_MAX_MB``, else 4096 MiB (least recently
used entries are evicted first). The folder holds a ``CACHEDIR.TAG``; ``clear`` removes
only ``entry-*.damper-cache`` files of a tagged folder and refuses any other folder.
"""
from __future__ import annotations

import argparse


def add_cache_options(p) -> None:
    """``--cache-dir`` and ``--cache-max-mb`` (shared by every command that uses the cache)."""
    p.add_argument("--cache-dir", default=None, help="cache folder (default $DAMPER_CACHE_DIR or .damper_cache)")
    p.add_argument("--cache-max-mb", type=float, default=None,
                   help="cache size limit [MiB] (default $DAMPER_CACHE_MAX_MB or 4096)")


def store_from_args(args):
    """The Store the options name."""
    from damper import limits
    from damper.cache import Store

    limit = getattr(args, "cache_max_mb", None)
    size = None if limit is None else limits.cache_bytes("--cache-max-mb", limit)
    return Store(args.cache_dir, size, memory=getattr(args, "no_cache", False))


def register(subparsers) -> None:
    """Add the ``cache`` subcommand."""
    p = subparsers.add_parser("cache", help="show or clear the shared result cache", description=__doc__,
                              formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("action", choices=("info", "clear"))
    p.add_argument("--json", action="store_true", help="print one JSON object")
    add_cache_options(p)
    p.set_defaults(func=run)


def run(args) -> int:
    from .common import print_json

    store = store_from_args(args)
    if args.action == "clear":
        n = store.clear()
        if args.json:
            print_json({"removed": n, "folder": str(store.folder)})
        else:
            print(f"removed {n} entries from {store.folder}")
        return 0
    info = store.info()
    if args.json:
        print_json(info)
    elif not store.owned():
        print(f"{info['folder']}: not a damper cache (no CACHEDIR.TAG)")
    else:
        print(f"{info['folder']}: {info['entries']} entries, {info['bytes'] / 2**20:.1f} MiB "
              f"of {info['max_bytes'] / 2**20:.0f} MiB"
              + (f", last used {info['newest_use']}" if info["entries"] else ""))
    return 0
