"""``greybox examples``: write the example axis and machine files (installed with the package) into a folder."""

from __future__ import annotations

import argparse
from importlib import resources
from pathlib import Path

from ..atomic import check_output_path, write_text_atomic
from ..errors import GreyboxError

#: The example files, in the order written: the X axis (linear), the C axis (rotary), a machine.
EXAMPLE_FILES = ("axis_x.toml", "axis_c.toml", "machine.toml")

#: The command that makes the synthetic logs of the walk-throughs (docs/predict.md), as shipped in data/.
DATA_COMMAND = "greybox synth --axis X Y --out data --seed 2024 --truth essential"


def add_parser(subparsers) -> None:
    parser = subparsers.add_parser(
        "examples",
        description="Write the example axis files (axis_x.toml: a linear ball-screw axis; axis_c.toml: a rotary "
        "axis) and machine file (machine.toml) that --axis-config and --machine take, installed with greybox, "
        f"into DIR, and print the command that makes the synthetic logs of the walk-throughs ({DATA_COMMAND}).",
    )
    parser.add_argument("out", metavar="DIR", nargs="?", default="examples",
                        help="folder to write into (default ./examples; made if missing)")
    parser.add_argument("--force", action="store_true", help="overwrite example files that exist in DIR")
    parser.set_defaults(run=run)


def example_text(name: str) -> str:
    """The text of one installed example file.

    Parameters
    ----------
    name : str
        One of :data:`EXAMPLE_FILES`.
    """
    return resources.files("greybox").joinpath("examples", name).read_text(encoding="utf-8")


def run(args: argparse.Namespace) -> int:
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise GreyboxError(f"{out}: is a file; give a folder for the example files")
    targets = [out / name for name in EXAMPLE_FILES]
    out.mkdir(parents=True, exist_ok=True)
    for target in targets:  # every file checked before any is written
        check_output_path(target, overwrite=args.force)
    for target in targets:
        write_text_atomic(target, example_text(target.name))
        print(f"wrote {target}")
    print(f"the synthetic logs of the walk-throughs: {DATA_COMMAND}")
    return 0
