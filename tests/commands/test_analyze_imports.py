"""What ``dirac analyze`` imports: small systems never pay for ``scipy.sparse``.

``import scipy.sparse`` costs about 0.13 s of a fresh process (it pulls scipy's array-API
layer, ``numpy.f2py`` and ``numpy.testing``), a twentieth of ``dirac analyze`` on the
paper's rigid bodies. The analyses of a few coordinates hold their patterns as dense
arrays (graph searches in plain Python, block ranks by dense SVD), so the module is
imported only by large systems, sparse Jacobians and numeric Dirac brackets.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

_CODE = (
    "import sys, io, contextlib\n"
    "from dirac.cli import main\n"
    "with contextlib.redirect_stdout(io.StringIO()):\n"
    "    status = main(['analyze', {name!r}])\n"
    "print(status, sorted(m for m in ('scipy', 'scipy.sparse', 'scipy.linalg', 'numpy.f2py') if m in sys.modules))\n"
)


@pytest.mark.parametrize("name", ["pendulum", "rigid_body_matrix"])
def test_small_analysis_does_not_import_scipy(name: str, tmp_path) -> None:
    """The whole analysis and its report, in a fresh process: status 0 and no scipy module loaded."""
    env_code = _CODE.format(name=name)
    result = subprocess.run(
        [sys.executable, "-c", env_code], capture_output=True, text=True, timeout=300, cwd=tmp_path,
        env={**os.environ, "DIRAC_CACHE_DIR": str(tmp_path / "cache")},
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "0 []"
