"""Atomic writes: a temporary file beside the output, renamed over it once complete, so an
interrupted run never leaves a half-written file."""
from __future__ import annotations

import os
from pathlib import Path


def _new_temporary(path: Path) -> str:
    """A new empty file beside ``path`` (".NAME.RANDOM.tmp"), made for this write alone
    and private until written, as tempfile.mkstemp makes it; tempfile is not imported (with
    the shutil and random it imports, a hundredth of a second of `vecfit render`)."""
    flags = os.O_RDWR | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_BINARY", 0)
    for _ in range(100):
        tmp = str(path.parent / f".{path.name}.{os.urandom(6).hex()}.tmp")
        try:
            os.close(os.open(tmp, flags, 0o600))
            return tmp
        except FileExistsError:
            continue  # (another name)
    raise FileExistsError(f"no free temporary name beside {path}")


def atomic_write(path: str | os.PathLike, write) -> None:
    """Calls write(tmp_path) for a temporary file next to path, then renames it over path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = _new_temporary(path)
    try:
        write(tmp)
        # the temporary file is private (0600); give it the permissions a plain open would
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def atomic_write_bytes(path: str | os.PathLike, payload: bytes) -> None:
    """Writes bytes atomically, as atomic_write."""
    def write(tmp):
        with open(tmp, "wb") as f:
            f.write(payload)
    atomic_write(path, write)


def atomic_write_text(path: str | os.PathLike, text: str) -> None:
    """Writes text (UTF-8, newlines as given) atomically, as atomic_write."""
    def write(tmp):
        with open(tmp, "w", encoding="utf-8", newline="") as f:
            f.write(text)
    atomic_write(path, write)
