"""Allow ``python -m greybox``."""

import sys

from .cli import main

sys.exit(main())
