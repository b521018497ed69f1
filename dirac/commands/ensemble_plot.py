"""``dirac ensemble-plot DIR --out FILE.png``: the picture of an ensemble.

A general system's ensemble (:mod:`dirac.ensemble.general_scene`): a two-dimensional
grid's reduction as a map (e.g. the double pendulum's flip-time fractal, log colour
scale), or a Poincaré section as a scatter (``--x``, ``--y``: a coordinate or ``p_<q>``).
A rigid-body ensemble: the flip-time figure of :func:`dirac.ensemble.plot.plot_flip_times`
and a one-line summary (members, flipped, median flip time, largest deviation from the
separatrix prediction). Also ``python -m dirac.commands.ensemble_plot DIR --out FILE.png``.
"""

from __future__ import annotations

import argparse
import sys


def _arguments(parser: argparse.ArgumentParser) -> argparse.ArgumentParser:
    parser.add_argument("out", metavar="DIR", help="the ensemble's output folder")
    parser.add_argument("--out", dest="image", metavar="FILE.png", required=True, help="image to write")
    parser.add_argument("--array", metavar="NAME", help="the reduction to draw (default: the first map-able one)")
    parser.add_argument("--x", metavar="NAME", help="Poincaré section: horizontal axis (a coordinate or p_<q>)")
    parser.add_argument("--y", metavar="NAME", help="Poincaré section: vertical axis (a coordinate or p_<q>)")
    parser.add_argument("--linear", action="store_true", help="map: linear colour scale (default: logarithmic)")
    return parser


def build_parser() -> argparse.ArgumentParser:
    """The arguments: the ensemble's folder and ``--out FILE.png``."""
    return _arguments(argparse.ArgumentParser(prog="python -m dirac.commands.ensemble_plot",
                                              description="Draw the picture of an ensemble."))


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Declare ``dirac ensemble-plot``."""
    return _arguments(subparsers.add_parser(
        "ensemble-plot", help="draw an ensemble: a 2-D grid as a map, a Poincaré section as a scatter",
        description="Draw the results of 'dirac ensemble': a reduction over a two-dimensional grid as a map "
        "(colour = value, log scale), a Poincaré section as a scatter, or a rigid-body ensemble's flip times. "
        "See docs/ensembles.md.",
    ))


def _draw(args: argparse.Namespace) -> str:
    import json
    from pathlib import Path

    from dirac.ensemble.plot import picture_data, plot_flip_times
    from dirac.plots.ensemble_maps import draw_grid_map, draw_section

    try:  # a general system's ensemble names its ensemble variables; a rigid body's does not
        general = "variables" in json.loads((Path(args.out) / "meta.json").read_text()).get("scene", {})
    except (OSError, ValueError, AttributeError):
        general = False
    if not general:
        summary = plot_flip_times(args.out, args.image)
        return ", ".join(f"{key} = {value:.6g}" for key, value in summary.items())
    data = picture_data(args.out, args.array, args.x, args.y)
    if data["kind"] == "section":
        draw_section(data["x"], data["y"], data["xlabel"], data["ylabel"], args.image, data["title"])
        return f"{data['title']} -> {args.image}"
    values = data["values"]
    draw_grid_map(values, data["x"], data["y"], data["label"], args.image, log=not args.linear)
    finite = values[values == values]
    return (f"map of {data['label']}: {values.shape[0]} x {values.shape[1]} members, {finite.size} with a value "
            f"(from {finite.min():.4g} to {finite.max():.4g}) -> {args.image}" if finite.size else "")


def main(argv: list[str] | argparse.Namespace | None = None) -> int:
    """Draw the picture; return 0, or 2 with one ``error:`` line on stderr for bad input."""
    from dirac.errors import DiracError, install_warning_printer

    install_warning_printer()
    args = argv if isinstance(argv, argparse.Namespace) else build_parser().parse_args(argv)
    try:
        line = _draw(args)
    except DiracError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(line, file=sys.stdout)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
