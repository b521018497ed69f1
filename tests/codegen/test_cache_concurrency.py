"""The cache of generated code shared by several writers at once (test workers, a user's
parallel runs, threaded dask workers): each gets the configured folder and whole files.

Every writer of the cache uses names of its own before an atomic ``os.replace``
(POSIX rename(2): readers see the old file or the new one, never a part). Regression
tests for two shared names: the write probe ``.write-test``, whose removal by one writer
failed another's probe, which then fell silently to the next candidate folder (the home
cache instead of ``$DIRAC_CACHE_DIR``), and the temporary file of a source, shared by the
threads of one process.
"""

from __future__ import annotations

import sys
import threading

from dirac.codegen import numba_backend


def _in_threads(work, count: int = 4) -> None:
    """Run ``work(k)`` in ``count`` threads at once, switching between them as often as possible."""
    interval = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)
    try:
        threads = [threading.Thread(target=work, args=(k,)) for k in range(count)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
    finally:
        sys.setswitchinterval(interval)


def test_concurrent_callers_all_get_the_configured_folder(tmp_path, monkeypatch) -> None:
    monkeypatch.setenv("DIRAC_CACHE_DIR", str(tmp_path))
    chosen: list[str] = []

    def work(_: int) -> None:
        chosen.extend(str(numba_backend.cache_directory()) for _ in range(1000))

    _in_threads(work)
    assert len(chosen) == 4000 and set(chosen) == {str(tmp_path)}
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # no probe left behind


def test_concurrent_writers_of_one_source_leave_one_whole_file(tmp_path, monkeypatch) -> None:
    monkeypatch.setenv("DIRAC_CACHE_DIR", str(tmp_path))
    sources = [f"# source {k} of a concurrency test\nVALUE = {k}\n" + "# padding\n" * 20000 for k in range(150)]
    errors: list[BaseException] = []

    def work(_: int) -> None:
        try:
            for source in sources:
                numba_backend.write_source(source)
        except BaseException as error:  # collected: a thread's exception would not fail the test
            errors.append(error)

    _in_threads(work, 6)
    assert errors == []
    for source in sources:
        assert numba_backend.source_path(source).read_text(encoding="utf-8") == source
    assert len(list(tmp_path.iterdir())) == len(sources)  # no temporary file left behind


def test_threads_importing_one_source_get_one_module(tmp_path, monkeypatch) -> None:
    """import_source from several threads at once: each gets the module of that source."""
    monkeypatch.setenv("DIRAC_CACHE_DIR", str(tmp_path))
    source = f"# imported by four threads in {tmp_path.name}\nVALUE = 17\n"
    modules: list = []
    _in_threads(lambda _: modules.append(numba_backend.import_source(source)))
    assert [m.VALUE for m in modules] == [17] * 4
    assert modules[0].__name__ == numba_backend.source_path(source).stem
