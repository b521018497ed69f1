"""The symbolic Dirac–Bergmann engine (sympy): Legendre transform, constraint chain,
first/second class split, Poisson and Dirac brackets, reports."""
