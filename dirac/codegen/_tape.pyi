"""The tape machine's loop compiled at the install (dirac/codegen/_tape.c)."""

import numpy as np
import numpy.typing as npt

def run_tape(
    code: npt.NDArray[np.int64],
    reg: npt.NDArray[np.float64],
    mem: npt.NDArray[np.float64],
    base: npt.NDArray[np.int64],
    rows: npt.NDArray[np.int64],
    cols: npt.NDArray[np.int64],
) -> int: ...
