"""Property-based tests (hypothesis) of the wearer model (checks, files): adversarial inputs work or raise one
documented error."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from helpers.strategies import (
    FEW,
    SETTINGS,
    configs,
    names_bad_value,
    numbers,
    resolve_target,
    targets,
)
from hypothesis import assume, given
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from tpee_ompl.model.wearer_arm import MAX_TARGET_DISTANCE, WearerArm
from tpee_ompl.resources import model_file as find_model_file


@SETTINGS
@given(q=configs)
def test_single_configuration_queries_answer_or_raise_value_error_naming_it(robot: WearerArm, q: np.ndarray) -> None:
    for fn in (robot.is_valid, robot.clearance, robot.muzzle):
        try:
            out = fn(q)
        except ValueError as exc:
            assert q.shape != (4,) or not np.all(np.isfinite(q))
            assert names_bad_value(str(exc), q), str(exc)
            continue
        assert q.shape == (4,) and np.all(np.isfinite(q))
        if fn == robot.is_valid:
            assert out == bool(robot.are_valid(q[None])[0])
            if not robot.within_limits(q):
                assert out is False  # out of limits is never valid
        elif fn == robot.clearance:
            assert math.isfinite(out)
        else:
            p, u = out
            assert np.all(np.isfinite(p)) and np.linalg.norm(u) == pytest.approx(1.0)


@SETTINGS
@given(Q=hnp.arrays(float, st.tuples(st.integers(0, 6), st.sampled_from([3, 4, 5])), elements=numbers))
def test_batched_validity_matches_single_checks_or_raises(robot: WearerArm, Q: np.ndarray) -> None:
    try:
        ok = robot.are_valid(Q)
    except ValueError as exc:
        assert Q.shape[1] != 4 or not np.all(np.isfinite(Q))
        assert names_bad_value(str(exc), Q), str(exc)
        return
    assert ok.shape == (len(Q),) and ok.dtype == bool
    assert [robot.is_valid(q) for q in Q] == ok.tolist()


@SETTINGS
@given(t=targets, q=hnp.arrays(float, (4,), elements=st.floats(-1.5, 1.5)))
def test_line_of_sight_answers_or_raises_value_error_naming_target(robot: WearerArm, t, q: np.ndarray) -> None:
    t = resolve_target(robot, t)
    try:
        clear = robot.line_of_sight_clear(q, t)
    except ValueError as exc:
        assert not np.all(np.isfinite(t)) or np.max(np.abs(t)) > MAX_TARGET_DISTANCE
        assert names_bad_value(str(exc), t), str(exc)
        return
    assert isinstance(clear, bool)


@FEW
@given(margin=st.one_of(numbers, st.integers(-3, 3), st.sampled_from([None, "0.02", True, [0.02]])))
def test_wearer_arm_security_margin_is_validated(margin) -> None:
    try:
        arm = WearerArm(security_margin=margin)
    except ValueError as exc:
        assert "security_margin" in str(exc)
        return
    assert arm.security_margin == float(margin) and 0 <= arm.security_margin <= 1.0



URDF_TEXT = find_model_file("wearer_arm.urdf").read_text()
SRDF_TEXT = find_model_file("wearer_arm.srdf").read_text()


@FEW
@given(cut=st.integers(0, len(URDF_TEXT) - 1))
def test_truncated_urdf_raises_value_error_naming_the_file(tmp_path_factory, cut: int) -> None:
    p = tmp_path_factory.mktemp("urdf") / "cut.urdf"
    p.write_text(URDF_TEXT[:cut])
    with pytest.raises(ValueError, match=re.escape(str(p))):
        WearerArm(p, False)


@FEW
@given(cut=st.integers(0, len(SRDF_TEXT) - 20))
def test_truncated_srdf_raises_value_error_naming_the_file(tmp_path_factory, cut: int) -> None:
    p = tmp_path_factory.mktemp("srdf") / "cut.srdf"
    p.write_text(SRDF_TEXT[:cut])
    with pytest.raises(ValueError, match=re.escape(str(p))):
        WearerArm(find_model_file("wearer_arm.urdf"), p)


@FEW
@given(link=st.text(st.characters(min_codepoint=97, max_codepoint=122), min_size=1, max_size=12))
def test_srdf_with_unknown_link_raises_value_error_naming_it(tmp_path_factory, robot: WearerArm, link: str) -> None:
    assume(link not in {f.name for f in robot.model.frames})
    p = tmp_path_factory.mktemp("srdf") / "bad.srdf"
    p.write_text(f'<robot name="x"><disable_collisions link1="link1" link2="{link}"/></robot>')
    with pytest.raises(ValueError, match=f"unknown link '{link}'"):
        WearerArm(find_model_file("wearer_arm.urdf"), p)


@pytest.mark.parametrize(
    ("edit", "match"),
    [
        (lambda s: s.replace('name="j2"', 'name="jx"'), "j2"),
        (lambda s: s.replace('<joint name="j3" type="revolute"', '<joint name="j3" type="continuous"'), "j3"),
        (lambda s: s.replace('lower="-3.300000000000" upper="3.300000000000"', 'lower="3.3" upper="-3.3"'), "j3"),
        (lambda s: re.sub(r'radius="([0-9.]+)"', r'radius="-\1"', s, count=1), "size of -"),
        (lambda s: s.replace('<link name="muzzle"', '<link name="nozzle"').replace('"muzzle"', '"nozzle"'), "muzzle"),
        (lambda s: "\ufeff\x00" + s, "URDF"),
    ],
)
def test_urdf_with_wrong_joints_or_shapes_raises_value_error(tmp_path: Path, edit, match: str) -> None:
    p = tmp_path / "bad.urdf"
    p.write_text(edit(URDF_TEXT))
    with pytest.raises(ValueError, match=match):
        WearerArm(p, False)


@pytest.mark.parametrize("which", ["urdf", "srdf"])
def test_missing_or_binary_model_files_raise_documented_errors(tmp_path: Path, which: str) -> None:
    urdf, srdf = find_model_file("wearer_arm.urdf"), find_model_file("wearer_arm.srdf")
    missing = tmp_path / "nope.xml"
    with pytest.raises(FileNotFoundError, match="nope.xml"):
        WearerArm(missing, srdf) if which == "urdf" else WearerArm(urdf, missing)
    binary = tmp_path / "bin.xml"
    binary.write_bytes(b"\xff\xfe\x00\x81garbage")
    with pytest.raises(ValueError, match="bin.xml"):
        WearerArm(binary, srdf) if which == "urdf" else WearerArm(urdf, binary)
