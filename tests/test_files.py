"""Atomic writes: a failed write leaves the old file and no temporary behind; nothing is replaced without force."""

from __future__ import annotations

import os
import stat

import pytest

from tpee_ompl.files import (OutputExistsError, atomic_path, atomic_write_text, check_output_path, check_writable_folder,
                             write_new_file)


def test_atomic_write_replaces_the_file_in_one_step(tmp_path):
    target = tmp_path / "a.txt"
    atomic_write_text(target, "one")
    atomic_write_text(target, "two")
    assert target.read_text() == "two" and [p.name for p in tmp_path.iterdir()] == ["a.txt"]


def test_failed_write_keeps_the_old_file_and_leaves_no_temporary(tmp_path):
    target = tmp_path / "lib.npz"
    target.write_bytes(b"old")
    with pytest.raises(KeyboardInterrupt), atomic_path(target) as tmp:
        tmp.write_bytes(b"half")
        raise KeyboardInterrupt
    assert target.read_bytes() == b"old" and [p.name for p in tmp_path.iterdir()] == ["lib.npz"]


def test_a_failed_write_names_the_output_not_its_temporary_file(tmp_path):
    target = tmp_path / "scene.png"
    with pytest.raises(FileNotFoundError) as exc, atomic_path(target) as tmp:
        raise FileNotFoundError(2, "No such file or directory", str(tmp))  # as a writer that cannot open it
    assert exc.value.filename == str(target) and ".part" not in str(exc.value)
    assert list(tmp_path.iterdir()) == []


def test_a_write_past_a_full_disk_names_the_output(tmp_path):
    """A failed write() carries no file name: "[Errno 28] No space left on device" named no file."""
    import errno

    target = tmp_path / "traj.csv"
    with pytest.raises(OSError) as exc, atomic_path(target):
        raise OSError(errno.ENOSPC, "No space left on device")
    assert exc.value.errno == errno.ENOSPC and exc.value.filename == str(target)
    assert list(tmp_path.iterdir()) == []


def test_existing_file_is_not_replaced_without_force(tmp_path):
    target = tmp_path / "r.json"
    target.write_text("keep")
    with pytest.raises(OutputExistsError, match="--force"):
        atomic_write_text(target, "new", force=False)
    with pytest.raises(OutputExistsError, match="--force"):
        check_output_path(target)
    assert target.read_text() == "keep"
    assert check_output_path(target, force=True) == target


def test_output_path_that_is_a_folder_or_under_a_file_is_refused_naming_it(tmp_path):
    with pytest.raises(ValueError, match="is a folder"):
        check_output_path(tmp_path)
    (tmp_path / "f").write_text("x")
    with pytest.raises(ValueError, match="is a file"):
        check_output_path(tmp_path / "f" / "out.png")
    assert check_output_path(tmp_path / "new" / "out.png").name == "out.png"
    assert not (tmp_path / "new").exists()  # checking creates nothing


def test_a_pipe_is_refused_even_with_force_and_a_symlink_is_written_through(tmp_path):
    """Replacing a pipe or device with a file would destroy it (``--force`` once did, and replaced links too)."""
    fifo = tmp_path / "fifo.csv"
    os.mkfifo(fifo)
    to_fifo = tmp_path / "to_fifo.csv"
    to_fifo.symlink_to(fifo)
    for target in (fifo, to_fifo):
        with pytest.raises(ValueError, match="not a regular file"):
            check_output_path(target, force=True)
        with pytest.raises(ValueError, match="not a regular file"):
            atomic_write_text(target, "new", force=True)
    assert stat.S_ISFIFO(fifo.lstat().st_mode) and to_fifo.is_symlink()
    real = tmp_path / "sub" / "real.csv"
    real.parent.mkdir()
    real.write_text("old")
    link = tmp_path / "link.csv"
    link.symlink_to(real)
    assert check_output_path(link, force=True) == link
    atomic_write_text(link, "new", force=True)
    assert link.is_symlink() and real.read_text() == "new"  # the file it points to, replaced; the link kept
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["fifo.csv", "link.csv", "real.csv", "sub", "to_fifo.csv"]


def test_a_folder_that_can_be_written_but_not_entered_is_refused(tmp_path):
    folder = tmp_path / "noexec"
    folder.mkdir()
    folder.chmod(0o600)  # writable, not searchable
    try:
        if os.access(folder / ".", os.X_OK):
            pytest.skip("running with the permission to enter any folder (root)")
        with pytest.raises(ValueError, match="not writable"):
            check_output_path(folder / "out.png")
    finally:
        folder.chmod(0o700)


def test_atomic_files_get_the_mode_a_plain_open_gives(tmp_path):
    import os

    mask = os.umask(0o022)
    try:
        atomic_write_text(tmp_path / "r.csv", "x")
        (tmp_path / "plain.csv").write_text("x")
    finally:
        os.umask(mask)
    assert (tmp_path / "r.csv").stat().st_mode & 0o777 == (tmp_path / "plain.csv").stat().st_mode & 0o777 == 0o644


def test_write_new_file_never_overwrites(tmp_path):
    target = tmp_path / "a.log"
    assert write_new_file(target, "first")
    assert not write_new_file(target, "second")
    assert target.read_text() == "first" and [p.name for p in tmp_path.iterdir()] == ["a.log"]


def test_writing_to_a_folder_says_it_is_a_folder(tmp_path):
    with pytest.raises(ValueError, match="is a folder"):
        atomic_write_text(tmp_path, "x", force=True)
    with pytest.raises(ValueError, match="is a folder"):
        atomic_write_text(tmp_path, "x", force=False)


def test_a_folder_that_exists_or_can_be_made_passes_and_a_file_in_the_way_is_named(tmp_path):
    assert check_writable_folder(tmp_path / "new" / "deeper", "out") == tmp_path / "new" / "deeper"
    assert not (tmp_path / "new").exists()  # nothing is created
    (tmp_path / "f").write_text("")
    with pytest.raises(ValueError, match=r"^out .*f: is a file, not a folder"):
        check_writable_folder(tmp_path / "f", "out")
    with pytest.raises(ValueError, match=r"^out .*: .*f is a file, not a folder"):
        check_writable_folder(tmp_path / "f" / "below", "out")


def test_a_failed_write_of_a_new_file_leaves_no_part_file(tmp_path):
    with pytest.raises(UnicodeEncodeError):
        write_new_file(tmp_path / "x.txt", "a\ud800")  # a lone surrogate cannot be written as UTF-8
    assert list(tmp_path.iterdir()) == []
    assert write_new_file(tmp_path / "y.txt", "é") and (tmp_path / "y.txt").read_text(encoding="utf-8") == "é"


def test_a_file_written_by_someone_else_while_this_wrote_is_not_replaced_without_force(tmp_path):
    """The existence check ran before the work only: a file appearing meanwhile was replaced without --force."""
    from tpee_ompl.files import OutputExistsError, atomic_path

    out = tmp_path / "out.png"
    with pytest.raises(OutputExistsError, match="written while this ran"):
        with atomic_path(out, force=False) as tmp:
            tmp.write_text("mine")
            out.write_text("precious")  # another process, during the work
    assert out.read_text() == "precious" and [p.name for p in tmp_path.iterdir()] == ["out.png"]
    loop = tmp_path / "loop.png"
    loop.symlink_to(loop.name)  # a link to itself: no file behind it
    with pytest.raises(OutputExistsError):
        with atomic_path(loop, force=False) as tmp:
            tmp.write_text("mine")
    assert loop.is_symlink()


def test_a_name_near_the_file_systems_limit_can_be_written(tmp_path):
    """The temporary name added ~19 bytes to the output's: a 245-byte name failed with 'File name too long'."""
    out = tmp_path / ("b" * 245 + ".png")
    atomic_write_text(out, "x")
    assert out.read_text() == "x" and len(list(tmp_path.iterdir())) == 1


def test_a_file_system_without_hard_links_still_gets_new_files_without_force(tmp_path, monkeypatch):
    """os.link fails with EPERM on vfat and some network mounts: every write without --force failed after the work."""
    import errno

    from tpee_ompl.files import OutputExistsError

    def no_links(src, dst):
        raise OSError(errno.EPERM, "Operation not permitted", str(dst))

    monkeypatch.setattr(os, "link", no_links)
    out = tmp_path / "new.png"
    atomic_write_text(out, "mine", force=False)
    assert out.read_text() == "mine"
    with pytest.raises(OutputExistsError):
        with atomic_path(tmp_path / "other.png", force=False) as tmp:
            tmp.write_text("mine")
            (tmp_path / "other.png").write_text("precious")
    assert (tmp_path / "other.png").read_text() == "precious"


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="needs Linux's /proc")
def test_a_folder_no_file_can_be_made_in_is_refused_before_any_work_even_for_root() -> None:
    """A helper, running as root, had ``library build --library /sys/x.npz`` build for minutes and then fail:
    ``os.access`` says yes to root everywhere.  A file is made and removed in the folder instead."""
    with pytest.raises(ValueError, match="^--output /proc/x.csv: folder /proc is not writable"):
        check_output_path("/proc/x.csv", what="--output")
    with pytest.raises(ValueError, match="^--out /proc/runs: folder /proc is not writable"):
        check_writable_folder("/proc/runs", what="--out")


def test_an_interrupted_write_removes_the_folders_it_made_and_only_those(tmp_path):
    """``-o new/dir/f`` interrupted left ``new/dir`` empty (the pictures removed them themselves; the library, query
    sets, ``plan --json`` and the campaign files did not)."""
    (tmp_path / "old").mkdir()
    for path in (tmp_path / "old" / "new" / "dir" / "f.txt", tmp_path / "new" / "f.txt"):
        with pytest.raises(KeyboardInterrupt), atomic_path(path) as tmp:
            tmp.write_text("half")
            raise KeyboardInterrupt
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["old"]
    with pytest.raises(RuntimeError), atomic_path(tmp_path / "a" / "b" / "f.txt") as tmp:
        (tmp_path / "a" / "other.txt").write_text("written meanwhile by someone else")
        raise RuntimeError("stop")
    assert sorted(p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*")) == ["a", "a/other.txt", "old"]
    with atomic_path(tmp_path / "c" / "d" / "f.txt") as tmp:
        tmp.write_text("whole")
    assert (tmp_path / "c" / "d" / "f.txt").read_text() == "whole"
