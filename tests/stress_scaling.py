"""How long the slow stress tests run.

``@pytest.mark.slow`` tests scale their step counts by :func:`stress_scale`: the full
runs with ``DIRAC_FULL_STRESS=1`` (``dirac bench --stress`` runs them too), a small
fraction otherwise, so CI still runs every slow test in a bounded form.

This is a plain module (not a conftest) so that every test folder imports the same
function: conftest modules of folders without ``__init__.py`` share one module name.
"""

from __future__ import annotations

import os


def stress_scale() -> float:
    """1.0 for the full stress runs (``DIRAC_FULL_STRESS=1``), else 0.01."""
    return 1.0 if os.environ.get("DIRAC_FULL_STRESS") == "1" else 0.01
