"""``dirac analyze SYSTEM``: run the Dirac–Bergmann algorithm and print the chain.

Text by default (stage by stage, with counts), ``--json`` (docs/file_formats.md) or ``--latex``.
``--param NAME=VALUE`` fixes parameters (the others stay symbolic); ``--gauge EXPR``
(repeatable) adds gauge conditions (:mod:`dirac.analysis.gauge.fixing`); ``--compare SPEC``
compares two brackets of the result (see :mod:`dirac.commands.analyze_compare`).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Callable

from dirac.errors import DiracError, InputError


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    parser = subparsers.add_parser(
        "analyze",
        help="run the Dirac-Bergmann algorithm on a system",
        description="Run the Dirac-Bergmann algorithm on a built-in system or a system file and print "
        "the constraint chain stage by stage, the first/second class split, the solved multipliers, "
        "the physical degrees of freedom and how Dirac brackets are computed.",
    )
    parser.add_argument("system", metavar="SYSTEM", help="built-in name (see 'dirac systems') or path to a .toml/.py system file")
    parser.add_argument(
        "--param",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="fix a parameter to a number (repeatable); the others stay symbolic",
    )
    parser.add_argument(
        "--gauge",
        action="append",
        default=[],
        metavar="EXPR",
        help="add the gauge condition EXPR = 0 (repeatable; names as in the phase space, e.g. z, y, p_z, and "
        "the time t unless t is a coordinate) and "
        "analyse the gauge-fixed system: Dirac bracket in that gauge, first-class constraints left",
    )
    parser.add_argument(
        "--assume",
        action="append",
        default=[],
        metavar="CONDITION",
        help='analyse the part of the phase space where CONDITION holds (repeatable): "EXPR != 0" keeps the points '
        'where ranks are decided away from EXPR = 0, "EXPR = 0" imposes EXPR (a phase-space function) as a '
        'constraint without a multiplier; e.g. --assume "am1**2 + am2**2 + am3**2 != 0"',
    )
    parser.add_argument(
        "--cases",
        action="store_true",
        help="also analyse every special parameter set (and special sets of those): the case tree, generic case first "
        "(JSON key parameter_cases)",
    )
    parser.add_argument(
        "--lattice",
        metavar="N",
        default=None,
        help="for a field theory ([field] system file): analyse it on a periodic lattice of N sites per direction "
        "(or N1,N2,... one per direction), forward differences; needed for a density that is not quadratic",
    )
    parser.add_argument("--spacing", metavar="A", type=float, default=1.0,
                        help="lattice spacing with --lattice (default 1)")
    output = parser.add_mutually_exclusive_group()
    output.add_argument("--json", action="store_true", help="print one JSON object (stages, classes, multipliers, degrees of freedom)")
    output.add_argument("--latex", action="store_true", help="print the analysis as LaTeX")
    parser.add_argument("--compare", metavar="SPEC", default=None, help="compare two Poisson brackets of the system on sampled points of the constraint surface: "
                        "FIRST,SECOND[:N], names out of dirac, canonical, chetaev, lie_poisson_so3, N points "
                        "(default 20); e.g. --compare dirac,chetaev")
    return parser


def parse_params(items: list[str]) -> dict[str, float]:
    """``["m=2", "g=9.81"]`` -> ``{"m": 2.0, "g": 9.81}``; :class:`InputError` for malformed items."""
    values: dict[str, float] = {}
    for item in items:
        name, sep, text = item.partition("=")
        name = name.strip()
        if not sep or not name or not text.strip():
            raise InputError(f"--param {item!r} is malformed: write NAME=VALUE, e.g. --param m=2.0")
        try:
            value = float(text)
        except ValueError:
            raise InputError(f"--param {item!r}: {text.strip()!r} is not a number") from None
        if not math.isfinite(value):
            raise InputError(f"--param {item!r}: the value must be a finite number")
        if name in values:
            raise InputError(f"--param {name} is given twice: give each parameter once")
        values[name] = value
    return values


def stage_printer(level: int) -> Callable[[str], None] | None:
    """Stage lines on stderr with ``-v``, or when stderr is a terminal (not with ``-q``); else None.

    Pipes and captured output stay clean at the default level.
    """
    if level < 0 or (level == 0 and not sys.stderr.isatty()):
        return None

    def report(message: str) -> None:
        print(f"analyze: {message}", file=sys.stderr, flush=True)

    return report


def _at_special(system: str, params: dict[str, float], report: Callable[[str], None] | None):
    """The analysis at ``--param`` values that lie on a special parameter value, else None.

    The parameters are first kept symbolic, with the given values as their defaults, to
    find the special values (:func:`dirac.analysis.constraint_analysis.at_given_values`
    then analyses at the given values and warns); when none is hit the caller analyses
    with the parameters fixed, as ``--param`` promises.
    """
    import dataclasses

    from dirac.analysis.constraint_analysis import analyze
    from dirac.model.systems import load_system

    free = load_system(system)
    if not set(params) <= set(free.parameter_values):
        return None
    generic = dataclasses.replace(free, parameters={p: params.get(p.name, v) for p, v in free.parameters.items()})
    try:
        analysis = analyze(generic, progress=report)
    except DiracError:  # no generic analysis: the analysis at the given values decides alone
        return None
    return analysis if analysis.lagrangian.fixed_values else None


def main(args: argparse.Namespace) -> int:
    from dirac.analysis.components import analyze
    from dirac.fields.files import is_field_file
    from dirac.model.systems import load_system

    if is_field_file(args.system):  # a [field] table: the field-theory road (dirac.fields)
        from dirac.commands.analyze_field import field_main

        return field_main(args, parse_params(args.param), stage_printer(getattr(args, "verbosity", 0)))
    if getattr(args, "lattice", None) is not None:
        raise InputError(f"--lattice needs a field theory (a system file with a [field] table); {args.system!r} is not one")
    if getattr(args, "cases", False) and args.latex:
        raise InputError("--cases works with the text and the --json output, not with --latex: drop one of them")
    if getattr(args, "cases", False) and args.gauge:
        raise InputError("--cases analyses the system without gauge conditions: drop --gauge or --cases")
    params = parse_params(args.param)
    lagrangian = load_system(args.system, **params)
    report = stage_printer(getattr(args, "verbosity", 0))
    analysis = _at_special(args.system, params, report) if params and not args.assume else None
    if analysis is None:
        analysis = analyze(lagrangian, progress=report, assume=args.assume)
    if args.gauge:
        analysis = analysis.fix_gauge(args.gauge)
        if report is not None:
            report(f"gauge fixed by {', '.join(args.gauge)}: {len(analysis.first_class)} first-class constraint(s) left")
    if args.compare is not None:
        from dirac.commands.analyze_compare import cli_compare

        print(cli_compare(analysis, args.compare, as_json=args.json, progress=report))
        return 0
    cases = None
    if getattr(args, "cases", False):
        from dirac.analysis.cases import parameter_cases

        cases = parameter_cases(analysis, progress=report)
    if args.json:
        data = analysis.to_json()
        if cases is not None:
            data["parameter_cases"] = [case.to_json() for case in cases]
        print(json.dumps(data, indent=2))
    elif args.latex:
        print(analysis.to_latex())
    else:
        print(analysis.to_text())
        if cases is not None:
            from dirac.analysis.cases import cases_text

            print()
            print(cases_text(cases))
    return 0
