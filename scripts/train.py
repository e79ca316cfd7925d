"""Fit a current model to axis logs and save it: the same as ``greybox train``.

Example::

    python scripts/train.py --model gms --train data/X_A.mcap data/X_B.mcap --out x_gms.gbm
    python scripts/train.py --model gmssvr --train data/X_A.mcap --stage2 data/X_B.mcap --out x_gmssvr.gbm

``python scripts/train.py --help`` lists every option.
"""

from __future__ import annotations

import sys

from greybox.cli import main

if __name__ == "__main__":
    sys.exit(main(["train", *sys.argv[1:]]))
