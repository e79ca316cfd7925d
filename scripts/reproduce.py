"""Run the paper's two experiments on the shipped data and write the report: the same as ``greybox reproduce``.

Example::

    python scripts/reproduce.py --out report

``python scripts/reproduce.py --help`` lists every option.
"""

from __future__ import annotations

import sys

from greybox.cli import main

if __name__ == "__main__":
    sys.exit(main(["reproduce", *sys.argv[1:]]))
