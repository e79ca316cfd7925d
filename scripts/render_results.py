"""Render the result tables of the README and the docs' pages from the measured records.

Every stretch a page marks with ``<!-- record NAME: VIEW -->`` ... ``<!-- end record -->`` is replaced by
the view of record ``docs/results/<name>.json`` (:mod:`studies.result_pages`); ``--check`` only lists the
pages that differ from their records and exits with status 1 if any does.

Usage::

    python scripts/render_results.py [--check]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # studies/ is beside greybox/, not installed

from greybox.errors import GreyboxError
from studies.records import ROOT
from studies.result_pages import render_pages


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="write nothing; list the pages that would change")
    args = parser.parse_args(argv)
    try:
        changed = render_pages(check=args.check)
    except GreyboxError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    for page in changed:
        print(f"{'differs from its records' if args.check else 'rendered'}: {page.relative_to(ROOT)}")
    return 1 if args.check and changed else 0


if __name__ == "__main__":
    sys.exit(main())
