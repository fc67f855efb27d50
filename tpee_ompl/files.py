"""Writing files safely: atomically (a crash never leaves half a file) and never over an existing one unless asked.

Every file the project writes (libraries, databases, campaign files, figures) goes through
:func:`atomic_path` / :func:`atomic_write`, or :func:`write_new_file` for a file that must not exist
yet: the data go to a temporary file in the target's folder, are flushed to disk, then ``os.replace``
(or a hard link) puts them in place in one step.  :func:`check_output_path` is called before any work
starts, so a refused target costs nothing and leaves nothing behind.
"""

from __future__ import annotations

import contextlib
import errno
import itertools
import os
import tempfile
import time
from collections.abc import Callable, Iterator
from pathlib import Path

__all__ = ["OutputExistsError", "atomic_path", "atomic_write", "atomic_write_text", "write_new_file",
           "check_output_path", "check_writable_folder"]


class OutputExistsError(FileExistsError):
    """The output file exists and overwriting was not asked for (``--force``)."""


def check_output_path(path: str | os.PathLike, *, force: bool = False, what: str = "output file") -> Path:
    """Check that ``path`` can be written: not a folder, its folder exists or can be made, no file there
    unless ``force``.  Nothing is created.

    Raises
    ------
    OutputExistsError
        The file exists and ``force`` is False.
    ValueError
        ``path`` is a folder or not a regular file (a device, a pipe), a parent is a file, or its folder
        cannot be written to.
    """
    p = Path(path)
    _check_replaceable(p, what)
    _check_nearest_folder((Path(os.path.realpath(p)) if p.is_symlink() else p).parents,  # a link: where it is written
                          f"{what} {p}")
    if p.exists() and not force:
        raise OutputExistsError(f"{what} {p} exists; pass --force (in Python: force=True) to replace it")
    return p


def check_writable_folder(folder: str | os.PathLike, what: str = "folder") -> Path:
    """``folder`` is, or can become, a writable folder (ValueError naming ``what`` otherwise); nothing is created."""
    p = Path(folder)
    if p.exists() and not p.is_dir():
        raise ValueError(f"{what} {folder}: is a file, not a folder")
    _check_nearest_folder((p, *p.parents), f"{what} {folder}")
    return p


def _check_nearest_folder(candidates, label: str) -> None:
    """The first of ``candidates`` (a path and its parents) that exists is a folder this process can write in."""
    for parent in candidates:
        if parent.exists():
            if not parent.is_dir():
                raise ValueError(f"{label}: {parent} is a file, not a folder")
            if not os.access(parent, os.W_OK | os.X_OK):
                raise ValueError(f"{label}: folder {parent} is not writable")
            try:  # access() says yes to root everywhere, also in /proc and /sys: a file made and gone at once
                tempfile.TemporaryFile(dir=parent).close()
            except OSError as exc:
                raise ValueError(f"{label}: folder {parent} is not writable ({exc.strerror or exc})") from None
            return


def _check_replaceable(p: Path, what: str) -> None:
    """Refuse a target that replacing would destroy rather than write: anything but a regular file (a folder, a
    device, a pipe, a socket; also when a symbolic link points to one).  A link to a file is written through
    (:func:`atomic_path` replaces the file it points to and keeps the link)."""
    if p.is_dir():
        raise ValueError(f"{what} {p} is a folder; give a file name")
    if p.exists() and not p.is_file():
        raise ValueError(f"{what} {p} is not a regular file (a device, pipe or socket); give a file name")


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike, *, force: bool = True, suffix_last: bool = False) -> Iterator[Path]:
    """A temporary path beside ``path`` to write to; on success it replaces ``path`` in one step.

    On an exception (or KeyboardInterrupt) the temporary file is removed and ``path`` is unchanged, and the folders
    made for it are removed again, deepest first, each only while empty (an interrupted ``-o new/dir/f.png`` left them).
    The file gets the mode a plain ``open`` would give (0666 less the umask), not ``mkstemp``'s 0600.
    ``suffix_last`` ends the temporary name with ``path``'s suffix (``.m.gif.XXXX.part.gif``) for
    writers that choose the format by the file name and cannot be told otherwise (Pillow, ffmpeg).
    With ``force=False`` an existing ``path`` raises :class:`OutputExistsError` before anything is written, and one
    that appeared while the caller wrote (another process) when the file is put in place: it is not replaced.  A
    ``path`` that is a symbolic link is written through: the file it points to is replaced, the link stays;
    a device, pipe or socket is refused (ValueError), never replaced by a file.
    """
    target = Path(path)
    _check_replaceable(target, "output file")
    if target.exists() and not force:
        raise OutputExistsError(f"{target} exists; pass --force (in Python: force=True) to replace it")
    if target.is_symlink():  # the file it points to is replaced, the link stays
        target = Path(os.path.realpath(target))
    made = list(itertools.takewhile(lambda f: not f.exists(), (target.parent, *target.parent.parents)))  # deepest first
    target.parent.mkdir(parents=True, exist_ok=True)
    done = False
    suffix = ".part" + target.suffix if suffix_last else target.suffix + ".part"
    # at most 100 bytes of the name: one near the 255-byte limit still leaves room for the temporary's
    prefix = "." + os.fsencode(target.name)[:100].decode(errors="ignore") + "."
    tmp: Path | None = None
    try:
        fd, tmp_name = tempfile.mkstemp(prefix=prefix, suffix=suffix, dir=target.parent)
        os.close(fd)
        tmp = Path(tmp_name)
        os.chmod(tmp, 0o666 & ~_umask())
        yield tmp
        with open(tmp, "rb+") as f:
            os.fsync(f.fileno())
        if force:
            os.replace(tmp, target)
        else:
            _place_new(tmp, target)
        done = True
    except OSError as exc:
        names_temporary = exc.filename is not None and Path(exc.filename).name.startswith(prefix)
        if names_temporary or exc.filename is None and exc.errno is not None:
            # the error names the temporary file, or no file (a write past a full disk or `ulimit -f`): name the
            # file the caller asked for
            raise type(exc)(exc.errno, exc.strerror, str(target)) from exc
        raise
    finally:
        if tmp is not None:
            with contextlib.suppress(FileNotFoundError):
                tmp.unlink()
        if not done:
            _remove_empty(made)


def _remove_empty(folders: list[Path]) -> None:
    """Remove ``folders`` (deepest first) while each is empty: the first that is not (something else wrote there
    meanwhile) stays, and so do the folders above it."""
    for folder in folders:
        try:
            folder.rmdir()
        except FileNotFoundError:  # removed meanwhile, or never made
            continue
        except OSError:
            return


_NO_HARD_LINKS = {errno.EPERM, errno.EOPNOTSUPP, errno.ENOTSUP, errno.ENOSYS, errno.EMLINK, errno.EXDEV}
"""What ``link()`` answers on a file system without hard links (vfat, exFAT, some network and FUSE mounts)."""


def _place_new(tmp: Path, target: Path) -> None:
    """Put the written ``tmp`` at ``target`` only where no name is yet (a file written meanwhile by another process
    stays): a hard link, created only at a free name; where the file system has none, the name is reserved with an
    exclusive create first, then replaced."""
    try:
        os.link(tmp, target)
        return
    except FileExistsError:
        pass
    except OSError as exc:
        if exc.errno not in _NO_HARD_LINKS:
            raise
        try:
            os.close(os.open(target, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o666))
        except FileExistsError:
            pass
        else:
            os.replace(tmp, target)
            return
    what = "a link to itself" if target.is_symlink() else "written while this ran"
    raise OutputExistsError(f"{target} exists ({what}); pass --force (in Python: force=True) to replace it")


def atomic_write(path: str | os.PathLike, write: Callable[[Path], object], *, force: bool = True) -> Path:
    """Call ``write(tmp_path)`` and move the result to ``path`` atomically; returns ``path``."""
    with atomic_path(path, force=force) as tmp:
        write(tmp)
    return Path(path)


def atomic_write_text(path: str | os.PathLike, text: str, *, force: bool = True) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    return atomic_write(path, lambda tmp: tmp.write_text(text, encoding="utf-8"), force=force)


def write_new_file(target: str | os.PathLike, text: str) -> bool:
    """Write ``text`` (UTF-8) to ``target`` atomically and never over an existing file.

    The text goes to a unique ``.part`` file first, then is hard-linked to ``target`` (which fails
    if ``target`` exists, even when two processes race, unlike a check before :func:`atomic_path`).
    Returns False when ``target`` existed.
    """
    target = Path(target)
    tmp = target.with_name(f"{target.name}.{os.getpid()}.{time.monotonic_ns()}.part")
    try:
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.link(tmp, target)
        return True
    except FileExistsError:
        return False
    finally:
        with contextlib.suppress(FileNotFoundError):  # (open failed: nothing to remove)
            tmp.unlink()
