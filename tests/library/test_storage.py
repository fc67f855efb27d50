"""Tests of library files (:mod:`tpee_ompl.library.storage`): round trip, damaged files, other model or version."""

from __future__ import annotations

import re

import numpy as np
import pytest
from helpers.hostile_files import LIBRARY_DEFECTS, make_unreadable, write_library_file
from helpers.library_standins import RRT_PAIRS, necessary_queries

from tpee_ompl.files import OutputExistsError
from tpee_ompl.library import LibraryFileError, PathLibrary
from tpee_ompl.model.wearer_arm import WearerArm


def test_library_round_trips_through_disk(robot: WearerArm, library: PathLibrary, tmp_path) -> None:
    f = library.save(tmp_path / "lib.npz")
    loaded = PathLibrary.load(f, robot)
    assert set(loaded.pairs) == set(library.pairs) and len(loaded) == len(library)
    (i, j), pd = next(iter(library.pairs.items()))
    rng = np.random.default_rng(0)
    start = pd.starts[0] + np.r_[0, 0, rng.uniform(-0.1, 0.1, 2)]
    goal = pd.goals[-1]
    for k in range(len(pd.starts)):
        assert np.array_equal(loaded.generate(start, goal, i, j, k), library.generate(start, goal, i, j, k))


def test_truncated_library_file_is_refused(robot: WearerArm, library: PathLibrary, tmp_path) -> None:
    f = library.save(tmp_path / "lib.npz")
    data = f.read_bytes()
    f.write_bytes(data[: len(data) // 2])
    with pytest.raises(LibraryFileError, match="truncated"):
        PathLibrary.load(f, robot)


def test_a_file_that_is_no_archive_is_refused_without_numpys_pickle_advice(robot: WearerArm, tmp_path) -> None:
    f = tmp_path / "notes.npz"
    f.write_text("not a library\n")
    with pytest.raises(LibraryFileError, match="not an .npz archive") as exc:
        PathLibrary.load(f, robot)
    assert "pickle" not in str(exc.value)


def test_library_from_another_model_or_version_is_refused(robot: WearerArm, library: PathLibrary, tmp_path, monkeypatch) -> None:
    import tpee_ompl.library.storage as storage

    f = library.save(tmp_path / "lib.npz")

    class OtherModel:
        model_hash = "0123456789abcdef"

    with pytest.raises(LibraryFileError, match="built for model"):
        PathLibrary.load(f, OtherModel())  # type: ignore[arg-type]
    monkeypatch.setattr(storage, "FORMAT_VERSION", storage.FORMAT_VERSION + 1)
    with pytest.raises(LibraryFileError, match="format version"):
        PathLibrary.load(f, robot)


@pytest.mark.slow
def test_build_parameters_survive_the_round_trip(robot: WearerArm, rrt_library: PathLibrary, tmp_path) -> None:
    loaded = PathLibrary.load(rrt_library.save(tmp_path / "lib.npz"), robot)
    assert loaded.build_params == rrt_library.build_params and loaded.query_stride == rrt_library.query_stride
    q = necessary_queries(RRT_PAIRS, 1)[0]
    for k in range(2):
        assert np.array_equal(loaded.generate(q.start, q.goal, q.from_sector, q.to_sector, k, stride=10),
                              rrt_library.generate(q.start, q.goal, q.from_sector, q.to_sector, k, stride=10))


# ---------------------------------------------------------------------------------------- hostile files
@pytest.mark.parametrize("defect", sorted(LIBRARY_DEFECTS))
def test_a_malformed_library_file_is_refused_naming_the_field(robot: WearerArm, tmp_path, defect: str) -> None:
    change, name = LIBRARY_DEFECTS[defect]
    f = write_library_file(tmp_path / "lib.npz", change)
    with pytest.raises(LibraryFileError, match=re.escape(name)) as exc:
        PathLibrary.load(f, robot)
    assert str(f) in str(exc.value)


def test_the_one_pair_library_the_defects_start_from_loads(robot: WearerArm, tmp_path) -> None:
    lib = PathLibrary.load(write_library_file(tmp_path / "lib.npz"), robot)
    assert list(lib.pairs) == [(1, 2)] and len(lib) == 20 and lib.n_candidates == 3


def test_save_without_force_refuses_an_existing_file_and_leaves_it(library: PathLibrary, tmp_path) -> None:
    f = tmp_path / "lib.npz"
    f.write_bytes(b"precious")
    with pytest.raises(OutputExistsError, match="--force"):
        library.save(f, force=False)
    assert f.read_bytes() == b"precious"
    library.save(f, force=True)
    assert f.read_bytes()[:2] == b"PK"


def test_an_interrupted_save_leaves_the_old_file_and_no_temporary(library: PathLibrary, tmp_path, monkeypatch) -> None:
    import tpee_ompl.library.storage as storage

    f = library.save(tmp_path / "lib.npz")
    before = f.read_bytes()

    def interrupted(fh, **arrays):
        fh.write(b"PK half a zip")
        raise KeyboardInterrupt

    monkeypatch.setattr(storage.np, "savez_compressed", interrupted)
    with pytest.raises(KeyboardInterrupt):
        library.save(f)
    assert f.read_bytes() == before and [p.name for p in tmp_path.iterdir()] == ["lib.npz"]


def test_a_library_its_loader_would_refuse_is_not_saved(robot: WearerArm, library: PathLibrary, tmp_path) -> None:
    """Weights beyond the loader's limit (a DMP with a huge alpha_x gives them) are refused when saving too."""
    (i, j), pd = next(iter(library.pairs.items()))
    dmp = pd.forward[0]
    kept = dmp.weights.copy()
    try:
        dmp.weights[...] = 0.0
        dmp.weights.flat[0] = 1e12
        with pytest.raises(ValueError, match=r"fwd_weights.*beyond .*not saved"):
            library.save(tmp_path / "lib.npz")
    finally:
        dmp.weights[...] = kept
    assert not (tmp_path / "lib.npz").exists() and not list(tmp_path.iterdir())


@pytest.mark.parametrize("array, row, dof, by, match", [
    ("waypoints", 3, 2, 10.0, r"pair 1->2: array 'p12_waypoints' leaves the robot's joint limits: not saved"),
    ("starts", 0, 0, 0.05, r"pair 1->2: array 'p12_starts' does not start at sector 1's Table-1 preset .*not saved"),
    ("goals", 1, 3, 0.01, r"pair 1->2: array 'p12_waypoints' does not run from the query's start to its goal: not "
                          r"saved"),
    ("waypoints", 2, 3, np.nan, r"pair 1->2: array 'p12_waypoints' holds NaN or inf: not saved"),
])
def test_demonstrations_its_loader_would_refuse_are_not_saved(robot: WearerArm, library: PathLibrary, tmp_path, array,
                                                              row, dof, by, match: str) -> None:
    """save() wrote demonstrations off the joint limits or the presets; load() then refused the file."""
    pd = library.pairs[(1, 2)]
    x = getattr(pd, array)
    kept = x.copy()
    try:
        x[row, ..., dof] += by
        with pytest.raises(ValueError, match=match):
            library.save(tmp_path / "lib.npz")
    finally:
        x[...] = kept
    assert not list(tmp_path.iterdir())
    assert len(PathLibrary.load(library.save(tmp_path / "lib.npz"), robot)) == len(library)


def _add_member(path, name: str, shape: tuple[int, ...]) -> None:
    """Append to the .npz file at ``path`` a member ``name`` whose header declares ``shape`` (float64) over 8 bytes."""
    import io
    import zipfile

    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False, "shape": shape})
    with zipfile.ZipFile(path, "a", compression=zipfile.ZIP_DEFLATED) as z:
        z.writestr(name + ".npy", header.getvalue() + bytes(8))


def test_an_array_declaring_a_huge_shape_is_refused_before_it_is_unpacked(robot: WearerArm, tmp_path) -> None:
    """A header declaring 745 GiB gave a MemoryError naming neither the file nor the array."""
    f = write_library_file(tmp_path / "lib.npz", lambda a: a.pop("p12_goals"))
    _add_member(f, "p12_goals", (10**11, 4))
    with pytest.raises(LibraryFileError, match="p12_goals.*GiB") as exc:
        PathLibrary.load(f, robot)
    assert str(f) in str(exc.value)
    other = write_library_file(tmp_path / "other.npz", lambda a: a.pop("p12_goals"))
    _add_member(other, "p12_goals", (21, 4))  # the data holds one float: refused by its declared shape alone
    with pytest.raises(LibraryFileError, match="p12_goals.*shape \\(21, 4\\), expected"):
        PathLibrary.load(other, robot)


def test_members_the_reader_does_not_use_are_never_unpacked(robot: WearerArm, tmp_path) -> None:
    """Every member used to be unpacked: a 3 MB file with 800 MB of zeros in an extra member took 900 MB to load."""
    f = write_library_file(tmp_path / "lib.npz")
    _add_member(f, "junk", (10**12,))  # 8 TB declared: unpacking it would fail at once
    assert len(PathLibrary.load(f, robot)) == len(PathLibrary.load(write_library_file(tmp_path / "plain.npz"), robot))


def test_a_pipe_is_refused_at_once_instead_of_read(robot: WearerArm, tmp_path) -> None:
    """np.load on a FIFO waits for a writer forever."""
    import os

    fifo = tmp_path / "lib.npz"
    os.mkfifo(fifo)
    with pytest.raises(LibraryFileError, match="not a regular file"):
        PathLibrary.load(fifo, robot)


def test_a_file_it_may_not_read_raises_permission_error_naming_it(robot: WearerArm, tmp_path, monkeypatch) -> None:
    """A file of mode 000 was a LibraryFileError "unreadable (truncated or not a library file): not an .npz
    archive" (zipfile.is_zipfile says False for a file it cannot open).  Root reads any file: its open is made to
    refuse as the system does for another user."""
    from tpee_ompl.library.storage import library_model_hash

    f = write_library_file(tmp_path / "lib.npz")
    make_unreadable(f, monkeypatch)
    for read in (lambda: PathLibrary.load(f, robot), lambda: library_model_hash(f)):
        with pytest.raises(PermissionError, match=re.escape(f"path library {f} cannot be read (Permission denied)")):
            read()


def test_a_corrupt_compressed_array_is_a_library_file_error(robot: WearerArm, tmp_path) -> None:
    """A damaged deflate stream escaped as zlib.error ("unexpected error" from the command line, no file named)."""
    import zipfile

    f = write_library_file(tmp_path / "lib.npz")
    with zipfile.ZipFile(f) as z:
        info = z.getinfo("p12_waypoints.npy")
    raw = bytearray(f.read_bytes())
    start = info.header_offset + 30 + len(info.filename) + len(info.extra)  # the member's compressed data
    for k in range(200, 400):
        raw[start + k] ^= 0x55
    f.write_bytes(bytes(raw))
    with pytest.raises(LibraryFileError, match="unreadable"):
        PathLibrary.load(f, robot)


def test_a_file_without_query_stride_gets_one_its_rollouts_allow(robot: WearerArm, tmp_path) -> None:
    """The default stride 10 was taken unchecked: with per_step 1 (rollouts of 6 steps) the constructor refused it."""
    def change(a: dict) -> None:
        a["meta"].pop("query_stride", None)
        a["meta"].update(per_step=1, pairs=[])
        for key in [k for k in a if k.startswith("p12_")]:
            a.pop(key)

    lib = PathLibrary.load(write_library_file(tmp_path / "lib.npz", change), robot)
    assert lib.per_step == 1 and lib.query_stride == 6
