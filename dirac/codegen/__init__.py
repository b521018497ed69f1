"""The one boundary from sympy expressions to numbers (numpy and numba functions)."""
