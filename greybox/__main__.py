"""Allow ``python -m greybox``."""

import sys

from .cli import main

if __name__ == "__main__":  # importing the module (e.g. the API reference of the docs) runs nothing
    sys.exit(main())
