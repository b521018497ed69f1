"""``dirac bench``: work-precision benchmarks against baselines measured in the same run."""
