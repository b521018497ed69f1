"""Composition coefficient tables: symmetric compositions of a symmetric base step.

A symmetric method ``S(h)`` of order 2 (Strang splitting, RATTLE, the kick + free-flow
step of the heavy top) composed as ``S(gamma_s h) ... S(gamma_1 h)`` with palindromic
fractions ``gamma`` summing to 1 is again symmetric, of the order given by the table
(Hairer, Lubich & Wanner, Geometric Numerical Integration, 2nd ed., Sect. V.3).
Each row is plain data: the name suffix of the methods that use it (``lie-poisson-4``,
``rattle-4``, ``exact-kick-4``), the order, the fractions and where they come from, so a
new scheme is a new row of :data:`COMPOSITIONS`.
"""

from __future__ import annotations

import math
from typing import NamedTuple

__all__ = ["Composition", "COMPOSITIONS", "MAIN_SUFFIXES", "palindrome"]


class Composition(NamedTuple):
    """One composition scheme.

    Attributes
    ----------
    suffix : str
        Name suffix of the methods composed with it, e.g. ``"4"`` or ``"8-s15"``.
    order : int
        Classical order of the composed method (base step of order 2).
    coefficients : tuple of float
        Step fractions ``gamma_1, ..., gamma_s`` (palindromic, ``sum = 1``).
    reference : str
        Source of the coefficients.
    """

    suffix: str
    order: int
    coefficients: tuple[float, ...]
    reference: str

    @property
    def stages(self) -> int:
        """Number of base steps per composed step."""
        return len(self.coefficients)


def palindrome(half: tuple[float, ...]) -> tuple[float, ...]:
    """Complete ``gamma_1..gamma_k`` to ``gamma_1..gamma_k, gamma_mid, gamma_k..gamma_1``,
    with ``gamma_mid = 1 - 2 sum(half)`` so that the fractions sum to 1."""
    middle = 1.0 - 2.0 * math.fsum(half)
    return tuple(half) + (middle,) + tuple(reversed(half))


_CBRT2 = 2.0 ** (1.0 / 3.0)
# Yoshida, Phys. Lett. A 150 (1990) 262; Creutz & Gocksch, Phys. Rev. Lett. 63 (1989) 9.
_YOSHIDA_4 = (1.0 / (2.0 - _CBRT2), -_CBRT2 / (2.0 - _CBRT2), 1.0 / (2.0 - _CBRT2))
# Suzuki, Phys. Lett. A 146 (1990) 319: five stages, the middle one negative.
_SUZUKI_G = 1.0 / (4.0 - 4.0 ** (1.0 / 3.0))
_SUZUKI_4_5 = (_SUZUKI_G, _SUZUKI_G, 1.0 - 4.0 * _SUZUKI_G, _SUZUKI_G, _SUZUKI_G)
# Kahan & Li, Math. Comp. 66 (1997) 1089; as printed in Hairer, Lubich & Wanner,
# Sect. V.3.2, methods p6 s9 and p8 s17.
_KAHAN_LI_6_9 = palindrome(
    (
        0.39216144400731413927925056,
        0.33259913678935943859974864,
        -0.70624617255763935980996482,
        0.08221359629355080023149045,
    )
)
_KAHAN_LI_8_17 = palindrome(
    (
        0.13020248308889008087881763,
        0.56116298177510838456196441,
        -0.38947496264484728640807860,
        0.15884190655515560089621075,
        -0.39590389413323757733623154,
        0.18453964097831570709183254,
        0.25837438768632204729397911,
        0.29501172360931029887096624,
    )
)
# Suzuki & Umeno (1993); McLachlan, SIAM J. Sci. Comput. 16 (1995) 151, p8 s15; as
# printed in Hairer, Lubich & Wanner, Sect. V.3.2.
_SUZUKI_UMENO_8_15 = palindrome(
    (
        0.74167036435061295344822780,
        -0.40910082580003159399730010,
        0.19075471029623837995387626,
        -0.57386247111608226665638773,
        0.29906418130365592384446354,
        0.33462491824529818378495798,
        0.31529309239676659663205666,
    )
)

#: Every composition scheme; the suffixes ``2, 4, 6, 8`` name the contract methods
#: (``lie-poisson-4``, ``rattle-4`` ...), the others extras.
COMPOSITIONS: tuple[Composition, ...] = (
    Composition("2", 2, (1.0,), "Strang (1968) symmetric splitting"),
    Composition("4", 4, _YOSHIDA_4, "Yoshida (1990) / Creutz & Gocksch triple jump"),
    Composition("4-suzuki", 4, _SUZUKI_4_5, "Suzuki (1990) 5-stage fractal composition"),
    Composition("6", 6, _KAHAN_LI_6_9, "Kahan & Li (1997) p6 s9"),
    Composition("8", 8, _KAHAN_LI_8_17, "Kahan & Li (1997) p8 s17"),
    Composition("8-s15", 8, _SUZUKI_UMENO_8_15, "Suzuki & Umeno (1993), McLachlan (1995) p8 s15"),
)

#: The suffixes of the compositions that RATTLE and the exact-kick heavy top use.
MAIN_SUFFIXES = ("2", "4", "6", "8")
