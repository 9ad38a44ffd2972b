"""Main job of ``make demo`` (extended issue by issue)."""
import argparse
import sys


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--out", default="out")
    parser.parse_args(argv)
    print("demo: nothing to run yet", file=sys.stderr)
    return 1


if __name__ == "__main__":
    sys.exit(main())
