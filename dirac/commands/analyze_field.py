"""``dirac analyze FILE`` for a system file with a ``[field]`` table.

Mode by mode for a linear density (text, ``--json``, ``--latex``, ``--gauge`` in the
density's syntax); ``--lattice N [--spacing A]`` analyses the lattice Lagrangian
(:func:`dirac.fields.lattice.lattice`) with the engine as any mechanical system.
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable
from typing import Any

from dirac.errors import InputError
from dirac.fields.files import load_field_theory

__all__ = ["field_main", "parse_sites"]


def parse_sites(text: str) -> int | list[int]:
    """``"64"`` -> 64; ``"8,8"`` -> ``[8, 8]``."""
    try:
        values = [int(part) for part in str(text).split(",")]
    except ValueError:
        raise InputError(f"--lattice {text!r}: give the number of sites, e.g. --lattice 64 or --lattice 8,8") from None
    if any(v < 1 for v in values):
        raise InputError(f"--lattice {text!r}: the numbers of sites must be positive")
    return values[0] if len(values) == 1 else values


def field_main(args: argparse.Namespace, params: dict[str, float], report: Callable[[str], None] | None) -> int:
    """Analyse a field theory file as the arguments say (``params``: the ``--param`` values,
    ``report``: the stage printer); print the result."""
    if getattr(args, "cases", False) or args.assume or args.compare is not None:
        raise InputError("--cases, --assume and --compare are for mechanical systems: a field theory always reports its "
                         "special wave vectors as cases (drop the option)")
    theory = load_field_theory(args.system, **params)
    analysis: Any
    if args.lattice is not None:
        from dirac.analysis.components import analyze
        from dirac.fields.lattice import lattice

        lagrangian = lattice(theory, sites=parse_sites(args.lattice), spacing=args.spacing)
        analysis = analyze(lagrangian, progress=report)
        if args.gauge:
            analysis = analysis.fix_gauge(args.gauge)
    else:
        from dirac.fields.analysis import analyze_field_theory

        analysis = analyze_field_theory(theory, progress=report)
        if args.gauge:
            analysis = analysis.fix_gauge(args.gauge)
    if args.json:
        print(json.dumps(analysis.to_json(), indent=2))
    elif args.latex:
        print(analysis.to_latex())
    else:
        print(analysis.to_text())
    return 0
