"""Interrupted runs lose no data (the result file keeps its samples, ``meta["complete"] = false``).

A real ``dirac run`` process is interrupted with SIGINT (Ctrl-C) or SIGTERM while it
integrates. Its stderr is a pseudo-terminal, so the progress bar appears exactly when the
integration loop starts: the signal is sent after that, never during start-up.
Expected (dirac/commands/run.py): exit status 130, one ``error:`` line, the samples
computed so far saved with ``meta["complete"] = false``; into ``--out`` when it did not
exist, otherwise into ``<name>.partial.npz`` while the existing file stays byte for byte
the same; no temporary files left behind.
"""

from __future__ import annotations

import fcntl
import os
import pty
import select
import signal
import struct
import subprocess
import sys
import termios
import time
from pathlib import Path

import numpy as np
import pytest

T_END = 1.0e4
# 1e8 steps of lie-poisson-2: far longer than the test waits; 0.1 time units per sample
SCENE = f"""
[system]
name = "rigid_body"
inertia = [1.0, 2.0, 2.5]

[initial]
M = [1.0, 0.2, 0.1]

[run]
t_end = {T_END}
method = "lie-poisson-2"
dt = 1e-4
samples = 100001
outputs = ["M", "energy"]
"""


def _read(fd: int, seconds: float) -> bytes:
    """Whatever the child writes to the pseudo-terminal within ``seconds``."""
    data = b""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        ready, _, _ = select.select([fd], [], [], 0.05)
        if ready:
            try:
                chunk = os.read(fd, 65536)
            except OSError:  # the child closed its side
                break
            if not chunk:
                break
            data += chunk
    return data


def _interrupt_run(tmp_path: Path, out: Path, signum: int) -> tuple[int, str]:
    scene = tmp_path / "long.toml"
    scene.write_text(SCENE)
    master, slave = pty.openpty()
    # a terminal of zero columns would get an empty bar from tqdm: give it a real size
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 160, 0, 0))
    # A terminal's Ctrl-C reaches a process whose SIGINT is at its default; a test runner
    # started in the background of a non-interactive shell passes SIGINT on as ignored, and
    # Python would then never raise KeyboardInterrupt. Give the child the terminal's default.
    child = subprocess.Popen(
        [sys.executable, "-m", "dirac", "run", str(scene), "--out", str(out)],
        stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=slave, cwd=tmp_path,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    os.close(slave)
    try:
        seen = b""
        deadline = time.monotonic() + 120.0
        while b"lie-poisson-2" not in seen:  # tqdm's bar, drawn when the loop starts
            assert child.poll() is None, seen.decode(errors="replace")
            assert time.monotonic() < deadline, "the integration loop never started"
            seen += _read(master, 0.2)
        seen += _read(master, 1.0)  # let it integrate a while
        child.send_signal(signum)
        while child.poll() is None and time.monotonic() < deadline + 60.0:
            seen += _read(master, 0.2)
        seen += _read(master, 0.5)
        status = child.wait(timeout=5)
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
        os.close(master)
    text = seen.decode(errors="replace").replace("\r", "\n")
    return status, text


def _assert_partial(path: Path) -> None:
    from dirac.io.results import read_results

    arrays, meta = read_results(path)
    assert meta["complete"] is False
    t = arrays["t"]
    assert 2 <= t.shape[0] < 100001
    assert t[0] == 0.0 and np.all(np.diff(t) > 0) and t[-1] < T_END
    assert arrays["M"].shape == (t.shape[0], 3) and np.all(np.isfinite(arrays["M"]))
    # the free body keeps |M|: the saved samples are real states, not garbage
    assert np.allclose(np.sum(arrays["M"] ** 2, axis=1), 1.05, rtol=1e-12)
    assert "interrupted" in meta.get("message", "")


def _error_lines(text: str) -> list[str]:
    return [line.strip() for line in text.splitlines() if line.strip().startswith("error:")]


@pytest.mark.parametrize(("signum", "existing"), [(signal.SIGINT, False), (signal.SIGTERM, True)],
                         ids=["SIGINT-new-file", "SIGTERM-existing-file"])
def test_interrupted_run_saves_what_it_computed_and_never_touches_an_existing_result(tmp_path, signum, existing):
    out = tmp_path / "result.npz"
    before = b"an earlier result that must survive byte for byte\n" * 100
    if existing:
        out.write_bytes(before)
    status, text = _interrupt_run(tmp_path, out, signum)
    assert status == 130, text
    assert "Traceback" not in text, text
    errors = _error_lines(text)
    assert len(errors) == 1 and "interrupted" in errors[0], text
    if existing:
        assert out.read_bytes() == before
        partial = tmp_path / "result.partial.npz"
        assert partial.name in errors[0]
        _assert_partial(partial)
    else:
        _assert_partial(out)
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]
