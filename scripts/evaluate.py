"""Test saved models on axis logs, overall and per operating regime: the same as ``greybox evaluate``.

Example::

    python scripts/evaluate.py x_gms.gbm x_gmssvr.gbm --test data/X_C.mcap data/X_D.mcap --out report

``python scripts/evaluate.py --help`` lists every option.
"""

from __future__ import annotations

import sys

from greybox.cli import main

if __name__ == "__main__":
    sys.exit(main(["evaluate", *sys.argv[1:]]))
