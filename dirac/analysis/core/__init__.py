"""Shared tools of the analysis: exact normal forms, the phase space and its Poisson bracket,
numerical decisions at surface points, weak linear solves."""
