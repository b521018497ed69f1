"""``dirac systems``: list the built-in systems with a one-line description each."""

from __future__ import annotations

import argparse


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    return subparsers.add_parser(
        "systems",
        help="list the built-in systems",
        description="List the built-in systems (usable by name in 'dirac analyze' and scene files).",
    )


def main(args: argparse.Namespace) -> int:
    from dirac.model.systems import builtin_systems

    systems = builtin_systems()
    try:
        from dirac.io.scene import SCENE_SYSTEMS  # numerical systems of scene files
    except ModuleNotFoundError:
        SCENE_SYSTEMS = {}
    width = max(map(len, [*systems, *SCENE_SYSTEMS]), default=0)
    print("Lagrangian systems (dirac analyze NAME; scene [system] name = NAME):")
    for name, description in systems.items():
        print(f"  {name:<{width}}  {description}")
    if SCENE_SYSTEMS:
        print("Flow systems (scene [system] name = NAME):")
        for name, description in SCENE_SYSTEMS.items():
            print(f"  {name:<{width}}  {description}")
    return 0
