"""The registry of integration methods: every name ``dirac run`` and a scene accept.

Each family module exports its methods as data (a module-level tuple ``METHODS``); this
module imports each family once and builds :data:`METHODS` from those tuples, so the
registry is complete as soon as it is imported and no module registers anything as a
side effect. The family modules never import this one.

The ``lie-poisson-*`` methods integrate the free body (:mod:`~dirac.flows.methods.lie_poisson`)
and, with gravity kicks, the heavy top (:mod:`~dirac.flows.methods.heavy_top`): the two
factories are joined here, so neither of those modules imports the other.
"""

from __future__ import annotations

from dirac.errors import InputError
from dirac.flows.methods import exact, forced, forced_ordinary, heavy_top, lie_poisson, midpoint, rattle, scipy_rk
from dirac.flows.methods.base import Method
from dirac.validate import unknown_name_error

__all__ = ["METHODS", "CONTRACT_NAMES", "get_method", "method_names", "driven_method_names"]

#: The names every user sees first, ``auto`` included; the others are extras.
CONTRACT_NAMES: tuple[str, ...] = (
    "auto", "exact", "lie-poisson-2", "lie-poisson-4", "lie-poisson-6", "lie-poisson-8",
    "rattle-2", "rattle-4", "midpoint", "scipy-RK45", "scipy-DOP853",
)


def _collect(*families: tuple[Method, ...]) -> dict[str, Method]:
    """name -> Method over all families; a name given twice is a programming error."""
    methods: dict[str, Method] = {}
    for family in families:
        for method in family:
            if method.name in methods:
                raise ValueError(f"method {method.name!r} defined twice")
            methods[method.name] = method
    return methods


#: name -> Method, every method but ``auto`` (which chooses one of these:
#: :mod:`dirac.flows.methods.auto`).
METHODS: dict[str, Method] = _collect(
    exact.METHODS,
    tuple(method.with_factories(heavy_top.LIE_POISSON_FACTORIES) for method in lie_poisson.METHODS),
    heavy_top.METHODS,
    # the ordinary names take forced systems too (rattle-2/4 as forced-rattle-2/4)
    tuple(method.with_factories(forced_ordinary.forced_factories(method.name))
          for method in (*midpoint.METHODS, *rattle.METHODS, *scipy_rk.METHODS)),
    forced.METHODS,
)


def method_names() -> list[str]:
    """Every method name: :data:`CONTRACT_NAMES` first (``auto`` leading), then the extras sorted."""
    extras = sorted(name for name in METHODS if name not in CONTRACT_NAMES)
    return [*CONTRACT_NAMES, *extras]


def driven_method_names(kind: str) -> list[str]:
    """The methods that integrate external torques and angular impulses on a problem of
    ``kind`` (``auto`` first): the kick compositions of :mod:`~dirac.flows.methods.torqued`
    and the scipy baselines."""
    from dirac.flows.methods.torqued import DRIVEN_METHOD_PREFIXES

    return ["auto"] + [name for name in method_names()
                       if name in METHODS and METHODS[name].accepts(kind) and name.startswith(DRIVEN_METHOD_PREFIXES)]


def get_method(name: str | Method) -> Method:
    """The method called ``name`` (a :class:`Method` is returned as it is).

    Raises
    ------
    InputError
        Unknown name; the message lists the known names.
    """
    if isinstance(name, Method):
        return name
    if name == "auto":
        raise InputError(
            "'auto' is not one method: it chooses one for each problem when a run starts "
            "(integrate(problem, method='auto'), dirac.flows.methods.auto.choose_method); get_method needs a "
            f"named method: {', '.join(n for n in method_names() if n != 'auto')}"
        )
    if name not in METHODS:
        raise unknown_name_error("method", name, method_names())
    return METHODS[name]
