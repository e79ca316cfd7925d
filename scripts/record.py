"""Measure records and render the pages' tables from them.

Each name is a record of :data:`studies.records.SPECS`; its command runs from the repository's root, and
the record (figures, command, commit, date, cores, load, versions) is written to ``docs/results/<name>.json``.
The pictures drawn from a measured record are redrawn (``scripts/record_figures.py``), then every page's
marked tables are rendered anew (``scripts/render_results.py``).

Usage::

    python scripts/record.py reproduce default-tests
    python scripts/record.py --list
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # studies/ is beside greybox/, not installed

from record_figures import DRAWN_FROM  # noqa: E402 (beside this script)

from greybox.errors import GreyboxError
from studies.records import ROOT, SPECS, measure, record_path, write_record
from studies.result_pages import render_pages


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", metavar="NAME", help=f"records to measure: {', '.join(SPECS)}")
    parser.add_argument("--list", action="store_true", help="list the records, their commands and what they measure")
    parser.add_argument("--allow-dirty", action="store_true",
                        help="measure with uncommitted changes in what a record depends on (the record says so, "
                             "and the pages' test refuses it)")
    args = parser.parse_args(argv)
    if args.list or not args.names:
        for spec in SPECS.values():
            print(f"{spec.name}: {spec.what}\n    python {' '.join(spec.command)}\n"
                  f"    depends on {', '.join(spec.depends_on)}")
        return 0
    unknown = [name for name in args.names if name not in SPECS]
    if unknown:
        parser.error(f"no record {', '.join(map(repr, unknown))}; records: {', '.join(SPECS)}")
    try:
        for name in args.names:
            print(f"measuring {name}: python {' '.join(SPECS[name].command)}", file=sys.stderr, flush=True)
            record = measure(SPECS[name], allow_dirty=args.allow_dirty)
            path = write_record(record)
            print(f"wrote {path.relative_to(ROOT)} ({record['seconds']:.0f} s, load {record['load_before'][0]:.1f} "
                  f"before and {record['load_after'][0]:.1f} after, {record['cores']} cores)")
            if name in DRAWN_FROM:
                print(f"drew {DRAWN_FROM[name](ROOT / 'docs' / 'figures').relative_to(ROOT)}")
        missing = tuple(name for name in SPECS if not record_path(name).is_file())
        for page in render_pages(keep=missing):
            print(f"rendered {page.relative_to(ROOT)}")
        if missing:
            print(f"left as they stand: the stretches of {', '.join(missing)} (not measured yet)")
    except GreyboxError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
