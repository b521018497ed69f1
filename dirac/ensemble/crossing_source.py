"""The generated source of the Illinois regula falsi that locates a reduction's crossing.

A member's expression ``f`` changes sign between two steps: ``f_lo = f(state_a)`` at
``t_a`` and ``f_hi = f(state)`` at ``t_a + dt``. The zero is sought on the straight line
``state_a + s (state - state_a)``, ``s in [0, 1]``, by regula falsi with the Illinois
modification (the retained end's value halved when the same end is kept twice; Dowell &
Jarratt, BIT 11 (1971) 168), to ``|f| <= 1e-16 (|f_lo| + |f_hi|)`` or an interval of
1e-16. The general member loop (:mod:`dirac.ensemble.general_kernel`) and the heavy top's
(:mod:`dirac.ensemble.heavy_top_members`) differ only in the state they interpolate and
evaluate, which they pass as source lines.
"""

from __future__ import annotations

__all__ = ["locate_source"]


def locate_source(name: str, arguments: str, doc: str, interpolate: str, evaluate: str, trailing: str = "") -> str:
    """The source of ``@numba.njit def NAME(e, ..., flo, fhi, ...)`` returning the fraction ``s``.

    Parameters
    ----------
    name, arguments, doc
        The function's name, its parameters after ``e`` and before ``flo, fhi``, its docstring.
    trailing
        Parameters after ``flo, fhi`` (work arrays), with their leading comma.
    interpolate, evaluate
        Source lines (indented 8 spaces, each ending in a newline) that set the state at
        fraction ``s`` and then the expressions' values ``fs`` there.
    """
    return f'''

@numba.njit(cache=True)
def {name}(e, {arguments}, flo, fhi{trailing}):
    """{doc}"""
    lo = 0.0
    hi = 1.0
    side = 0
    size = abs(flo) + abs(fhi)
    s = flo / (flo - fhi)
    for _it in range(200):
{interpolate}{evaluate}        fm = fs[e]
        if fm == 0.0 or abs(fm) <= 1e-16 * size or hi - lo <= 1e-16:
            break
        if (fm < 0.0) == (flo < 0.0):
            lo = s
            flo = fm
            if side == 1:
                fhi *= 0.5
            side = 1
        else:
            hi = s
            fhi = fm
            if side == -1:
                flo *= 0.5
            side = -1
        s = (lo * fhi - hi * flo) / (fhi - flo)
        if not (lo <= s <= hi):
            s = 0.5 * (lo + hi)
    return s
'''
