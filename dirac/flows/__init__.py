"""Numerical flows: problems, methods, the one ``integrate`` loop, solutions, scenes and
result files."""
