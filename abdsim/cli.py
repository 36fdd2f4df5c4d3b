"""The ``abdsim`` command line (also ``python -m abdsim``).

Subcommands live in their own modules and are listed in :data:`SUBCOMMANDS`: each module has
``add_parser(subparsers)``, which adds its parser and sets ``func`` (called with the parsed
arguments, returning an exit status). A module that is not installed is left out, so a new
subcommand (e.g. ``abdsim validate`` in ``abdsim.validation.cli``) is one line here and one
module there. Registration must stay cheap: heavy imports belong inside ``func``.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
from collections.abc import Sequence

#: Subcommand name -> module providing ``add_parser(subparsers)``.
SUBCOMMANDS: dict[str, str] = {
    "log": "abdsim.bridges.cli",
    "validate": "abdsim.validation.cli",
}


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every installed subcommand."""
    from abdsim import __version__

    parser = argparse.ArgumentParser(
        prog="abdsim", description="Affine Body Dynamics for robotics: command-line tools."
    )
    parser.add_argument("--version", action="version", version=f"abdsim {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    for module_name in SUBCOMMANDS.values():
        try:
            module = importlib.import_module(module_name)
        except ModuleNotFoundError as e:
            if e.name is not None and module_name.startswith(e.name):
                continue  # this subcommand's module is not part of the installation
            raise
        module.add_parser(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    func = getattr(args, "func", None)
    if func is None:
        parser.print_help()
        return 2
    try:
        status = int(func(args) or 0)
        sys.stdout.flush()
        return status
    except BrokenPipeError:
        # The reader went away (``abdsim log info --json FILE | head``): stop quietly, and
        # point stdout at /dev/null so the interpreter's own flush at exit cannot fail again.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
        return 0
    except (FileNotFoundError, ValueError, KeyError) as e:
        message = e.args[0] if isinstance(e, KeyError) and e.args else e
        print(f"abdsim {args.command}: error: {message}", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
