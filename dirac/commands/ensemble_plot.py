"""``python -m dirac.commands.ensemble_plot DIR --out FILE.png``: the flip-time figure of an ensemble.

Draws :func:`dirac.ensemble.plot.plot_flip_times` of the ensemble in ``DIR`` and prints a
one-line summary (members, flipped, median flip time, largest deviation from the
separatrix prediction).
"""

from __future__ import annotations

import argparse
import sys


def build_parser() -> argparse.ArgumentParser:
    """The arguments: the ensemble's folder and ``--out FILE.png``."""
    parser = argparse.ArgumentParser(
        prog="python -m dirac.commands.ensemble_plot",
        description="Plot the flip times of an ensemble.",
    )
    parser.add_argument("out", metavar="DIR", help="the ensemble's output folder")
    parser.add_argument("--out", dest="image", metavar="FILE.png", required=True, help="image to write")
    return parser


def main(argv: list[str] | None = None) -> int:
    """Draw the figure; return 0, or 2 with one ``error:`` line on stderr for bad input."""
    from dirac.ensemble.plot import plot_flip_times
    from dirac.errors import DiracError, install_warning_printer

    install_warning_printer()
    args = build_parser().parse_args(argv)
    try:
        summary = plot_flip_times(args.out, args.image)
    except DiracError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(", ".join(f"{key} = {value:.6g}" for key, value in summary.items()), file=sys.stdout)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
