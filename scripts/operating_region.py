"""The operating region's rules and shares outside it (record ``operating-region``).

Prints the tables of :mod:`studies.operating_region` (the rule of the grid, the rule of the reversals' window,
each case's shares outside the region of its training runs), then the same figures as one JSON object last
(the record ``operating-region`` of ``scripts/record.py``).

Usage::

    python scripts/operating_region.py
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # studies/ is beside greybox/, not installed

from studies.operating_region import figures, print_figures


def main() -> int:
    found = figures()
    print_figures(found)
    print(json.dumps(found, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
