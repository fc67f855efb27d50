"""The scene's meshes (:mod:`tpee_ompl.viz.meshes`)."""

from __future__ import annotations


def test_a_robot_built_where_a_freed_one_was_gets_its_own_drawing(tmp_path):
    """The cache was keyed by id(robot): a robot freed and another built at its address got the old drawing (a
    helper drew a 1.0-m backpack model with the 1.6-m one's backpack, 8 times in 30)."""
    import gc

    from tpee_ompl.model.wearer_arm import WearerArm
    from tpee_ompl.resources import model_file
    from tpee_ompl.viz.meshes import scene_mesh

    text = model_file("wearer_arm.urdf").read_text(encoding="utf-8")
    backpack = '<box size="0.26 0.36 0.52"/>'
    assert text.count(backpack) == 1
    files = []
    for depth in ("0.26", "1.20"):
        f = tmp_path / f"backpack_{depth}.urdf"
        f.write_text(text.replace(backpack, f'<box size="{depth} 0.36 0.52"/>'), encoding="utf-8")
        files.append(f)
    tops = {}
    for k in range(12):
        f = files[k % 2]
        robot = WearerArm(f)
        top = -float(scene_mesh(robot).wearer_polys[..., 0].min())  # how far the backpack reaches back
        assert tops.setdefault(f.name, top) == top, f"{f.name} drawn with another model's wearer"
        del robot
        gc.collect()
    assert tops[files[0].name] < tops[files[1].name]
