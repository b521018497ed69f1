"""The order in which pytest-xdist hands out the test files: the long ones first.

With ``--dist loadfile`` (pyproject.toml) each file runs on one worker, and pytest-xdist
queues the files by their number of tests, most first. A file of few tests that take long
(each compiles kernels of its own) would start last and keep one worker busy long after the
other has run out of files. :func:`long_files_first_scheduler` moves the files of
:data:`LONG_FILES` to the front of that queue; the rest keep pytest-xdist's order.

A plain module (not a conftest), so that its test imports it by one name.
"""

from __future__ import annotations

#: Test files of few tests that take long (kernel compilations; seconds of CPU of each file,
#: its tests and their child processes on a cold cache of generated code, in the comments), longest first.
LONG_FILES = (
    "tests/ensemble/test_heavy_top_impulse_ensemble.py",  # about 125 s
    "tests/ensemble/test_heavy_top_driven_ensemble.py",  # about 100 s
    "tests/docs/test_docs_examples.py",  # about 75 s
    "tests/docs/test_page_ensembles_general.py",  # about 70 s
    "tests/ensemble/test_heavy_top_ensemble.py",  # about 40 s
    "tests/docs/test_page_field_theories.py",
    "tests/docs/test_docs_build.py",  # about 18 s (sphinx in a child process)
)


def long_files_first_scheduler(config, log):
    """pytest-xdist's ``--dist loadfile`` scheduler with :data:`LONG_FILES` handed out first
    (None for any other ``--dist`` mode: pytest-xdist chooses)."""
    if config.getvalue("dist") != "loadfile":
        return None
    from xdist.scheduler import LoadFileScheduling

    class LongFilesFirst(LoadFileScheduling):
        """Before the first file is given out, the long files move to the front of the queue."""

        ordered = False

        def _assign_work_unit(self, node):
            if not self.ordered:
                self.ordered = True
                for scope in reversed([name for name in LONG_FILES if name in self.workqueue]):
                    self.workqueue.move_to_end(scope, last=False)
            super()._assign_work_unit(node)

    return LongFilesFirst(config, log)
