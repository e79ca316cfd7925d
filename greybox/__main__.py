"""Allow ``python -m greybox``."""

from .cli import run

if __name__ == "__main__":  # importing the module (e.g. the API reference of the docs) runs nothing
    run()
