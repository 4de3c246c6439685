"""The ``kcplan`` command: one module per subcommand, each with its parser and handler.

Exit codes: 0 success, 2 bad input (one line on stderr, no traceback).
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence

from kcplan.cli import (
    bench,
    bounds,
    import_map,
    pick_place,
    plan,
    robot,
    show,
    validate,
    verify,
)
from kcplan.cli.common import InputError, Parser

__all__ = ["build_parser", "main"]

SUBCOMMANDS = (bounds, validate, show, plan, verify, bench, pick_place, import_map, robot)
"""Subcommand modules, in the order of ``kcplan --help``."""


def build_parser() -> Parser:
    """The ``kcplan`` argument parser with every subcommand."""
    from kcplan import __version__

    parser = Parser(prog="kcplan", description="The kcplan command.")
    parser.add_argument("--version", action="version", version=f"kcplan {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    for command in SUBCOMMANDS:
        command.add_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``kcplan`` console script; returns the exit code."""
    try:
        args = build_parser().parse_args(argv)
        args.argv = list(sys.argv[1:] if argv is None else argv)
        return args.handler(args)
    except InputError as err:
        print(str(err), file=sys.stderr)
        return 2
    except BrokenPipeError:  # e.g. `kcplan plan ... | head`: the reader left
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 1
