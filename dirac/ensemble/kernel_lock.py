"""The lock around the ensembles' parallel kernels (one module, imported by both chunk kinds)."""

from __future__ import annotations

import threading

__all__ = ["KERNEL_LOCK"]

#: Serialises the parallel kernel within one process: numba's default ("workqueue")
#: threading layer must not be entered by two threads at once (threaded dask workers),
#: and one call already uses every thread numba is allowed.
KERNEL_LOCK = threading.Lock()
