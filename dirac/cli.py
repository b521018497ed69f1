"""The ``dirac`` command line: one dispatcher, one module per sub-command.

Each sub-command lives in ``dirac/commands/<name>.py`` and provides

* ``register(subparsers) -> argparse.ArgumentParser`` — declare its arguments (cheap:
  no sympy, numba or scipy imports at module level, so ``dirac --help`` stays fast);
* ``main(args: argparse.Namespace) -> int`` — do the work and return the exit status.

Every command takes ``-q/--quiet`` and ``-v/--verbose`` (handled here once): the
commands read the level from ``args.verbosity`` (-1 quiet, 0 default, 1 verbose) through
:func:`verbosity`. Warnings (``warning:`` lines) are shown at every level.

Exit status (docs/cli.md): 0 success; 2 bad input, with one ``error:`` line on stderr;
1 an internal failure.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence
from typing import NoReturn

from dirac.errors import DiracError, install_warning_printer, quiet_information

#: sub-command name -> its module (which declares its arguments and help text)
COMMANDS: dict[str, str] = {
    "demo": "dirac.commands.demo",
    "systems": "dirac.commands.systems",
    "analyze": "dirac.commands.analyze",
    "run": "dirac.commands.run",
    "bench": "dirac.commands.bench",
    "ensemble": "dirac.commands.ensemble",
    "ensemble-plot": "dirac.commands.ensemble_plot",
}


class _ErrorExitParser(argparse.ArgumentParser):
    """argparse with the project's error format: one ``error:`` line, exit status 2."""

    def error(self, message: str) -> NoReturn:
        print(f"error: {message} (see '{self.prog} --help')", file=sys.stderr)
        raise SystemExit(2)


def _add_verbosity_options(parser: argparse.ArgumentParser) -> None:
    """``-q/--quiet`` and ``-v/--verbose``; SUPPRESS so a sub-command's default keeps the top-level value."""
    group = parser.add_argument_group("output")
    group.add_argument(
        "-q", "--quiet", action="count", default=argparse.SUPPRESS,
        help="no progress bars or informational lines on stderr (warnings and errors stay); "
        "no summary when the results go to an --out file",
    )
    group.add_argument(
        "-v", "--verbose", action="count", default=argparse.SUPPRESS,
        help="more detail on stderr: the stages of long analyses, with timings",
    )


def verbosity(args: argparse.Namespace) -> int:
    """-1 with ``-q``, 1 with ``-v``, else 0 (the last of -q/-v given wins over none; -q beats -v)."""
    level = getattr(args, "verbosity", None)
    if level is not None:
        return int(level)
    if getattr(args, "quiet", 0):
        return -1
    return 1 if getattr(args, "verbose", 0) else 0


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("dirac-mechanics")
    except PackageNotFoundError:  # running from a source tree that is not installed
        return "unknown"


class _VersionAction(argparse.Action):
    """``--version``: print ``dirac X.Y.Z`` and exit, the version read only when asked.

    argparse's own ``action="version"`` takes the text when the parser is built, so
    every command paid for the look-up of the installed distribution: 5 to 10 ms in a
    fresh process (``importlib.metadata.version``, measured five times on this package),
    before any work. The text printed is the same (the same line on stdout, exit status 0).
    """

    def __init__(self, option_strings: Sequence[str], dest: str = argparse.SUPPRESS,
                 default: str = argparse.SUPPRESS, help: str = "show program's version number and exit") -> None:
        super().__init__(option_strings=option_strings, dest=dest, default=default, nargs=0, help=help)

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace, values: object,
                 option_string: str | None = None) -> NoReturn:
        sys.stdout.write(f"{parser.prog} {_version()}\n")
        parser.exit()


def build_parser() -> argparse.ArgumentParser:
    """The full argument parser, with every available sub-command registered."""
    parser = _ErrorExitParser(
        prog="dirac",
        description="Constrained Hamiltonian mechanics: the Dirac-Bergmann algorithm, "
        "Dirac brackets and structure-preserving flows.",
    )
    parser.add_argument("--version", action=_VersionAction)
    _add_verbosity_options(parser)
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_ErrorExitParser)
    for name, module_name in COMMANDS.items():
        try:
            module = importlib.import_module(module_name)
        except ModuleNotFoundError as exc:
            if exc.name != module_name:
                raise
            sub = subparsers.add_parser(name, help="(not available in this version yet)")
            sub.add_argument("rest", nargs=argparse.REMAINDER, help=argparse.SUPPRESS)
            sub.set_defaults(handler=_not_available(name))
            continue
        sub = module.register(subparsers)
        _add_verbosity_options(sub)
        sub.set_defaults(handler=module.main)
    return parser


def _not_available(name: str):
    def handler(args: argparse.Namespace) -> int:
        print(f"error: 'dirac {name}' is not available in this version yet", file=sys.stderr)
        return 2

    return handler


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``dirac`` console script and of ``python -m dirac``."""
    install_warning_printer()
    parser = build_parser()
    args = parser.parse_args(argv)
    args.verbosity = verbosity(args)
    if getattr(args, "handler", None) is None:
        parser.print_help()
        print(f"error: no command given: choose one of {', '.join(COMMANDS)}", file=sys.stderr)
        return 2
    try:
        if args.verbosity < 0:  # -q: not even the line that announces a compilation
            with quiet_information():
                return int(args.handler(args) or 0)
        return int(args.handler(args) or 0)
    except DiracError as exc:
        message = " ".join(str(exc).split())
        print(f"error: {message}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("error: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return 0
