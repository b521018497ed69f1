"""The cache of generated code is used only when it is safe: a folder owned by someone
else, or writable by others, would let them run code as this user (generated modules are
imported, numba's cache files unpickled), so it is refused with a warning."""

from __future__ import annotations

import os
import stat
import tempfile
from pathlib import Path

import pytest

from dirac.codegen import numba_backend
from dirac.errors import DiracWarning


@pytest.fixture
def fresh(monkeypatch, tmp_path):
    """No cache folder chosen yet, a home of its own, no DIRAC_CACHE_DIR."""
    monkeypatch.setattr(numba_backend, "_private", None)
    monkeypatch.setattr(numba_backend, "_refused", set())
    monkeypatch.delenv("DIRAC_CACHE_DIR", raising=False)
    home = tmp_path / "home"
    home.mkdir()
    monkeypatch.setattr(Path, "home", classmethod(lambda cls: home))
    return tmp_path


def test_a_cache_folder_writable_by_others_is_not_used(fresh, monkeypatch) -> None:
    shared = fresh / "shared"
    shared.mkdir()
    shared.chmod(0o777)
    monkeypatch.setenv("DIRAC_CACHE_DIR", str(shared))
    with pytest.warns(DiracWarning, match="writable by others"):
        chosen = numba_backend.cache_directory()
    assert chosen == fresh / "home" / ".cache" / "dirac" / "generated"
    assert not any(shared.iterdir())  # nothing written there


def test_a_cache_folder_owned_by_someone_else_is_not_used(fresh, monkeypatch) -> None:
    theirs = fresh / "theirs"
    theirs.mkdir(mode=0o700)
    monkeypatch.setenv("DIRAC_CACHE_DIR", str(theirs))
    real = os.getuid()
    monkeypatch.setattr(os, "getuid", lambda: real + 1)  # the folder now belongs to another user
    with pytest.warns(DiracWarning, match="owned by another user"):
        chosen = numba_backend.cache_directory()
    assert chosen != theirs
    assert chosen.lstat().st_uid == real


def test_a_shared_temporary_folder_is_replaced_by_a_private_one(fresh, monkeypatch) -> None:
    """Home not writable: the fallback dirac-generated-<uid> in the temporary directory was
    made writable by all (as another user could have prepared it): a private folder instead."""
    monkeypatch.setattr(Path, "home", classmethod(lambda cls: fresh / "a-file"))
    (fresh / "a-file").write_text("not a directory")
    temporary = fresh / "tmp"
    temporary.mkdir()
    monkeypatch.setattr(tempfile, "gettempdir", lambda: str(temporary))
    planted = temporary / f"dirac-generated-{os.getuid()}"
    planted.mkdir()
    planted.chmod(0o777)
    with pytest.warns(DiracWarning, match="dirac-generated"):
        chosen = numba_backend.cache_directory()
    assert chosen != planted and chosen.is_dir()
    assert chosen.lstat().st_uid == os.getuid()
    assert stat.S_IMODE(chosen.lstat().st_mode) & 0o077 == 0  # private: no one else may read or write
    assert numba_backend.cache_directory() == chosen  # the same private folder for the rest of the process


def test_a_folder_of_ones_own_is_used_without_a_warning(fresh, monkeypatch, recwarn) -> None:
    mine = fresh / "mine"
    mine.mkdir(mode=0o755)
    monkeypatch.setenv("DIRAC_CACHE_DIR", str(mine))
    assert numba_backend.cache_directory() == mine
    assert not [w for w in recwarn if issubclass(w.category, DiracWarning)]
