"""The wheel works outside the source tree: package data (model, query sets, default library) and the CLI.

Builds the wheel, installs it into a fresh virtual environment in a temporary directory, and runs the
commands a new user runs first from another directory.  The fresh environment takes the heavy
dependencies (OMPL, Pinocchio, Coal) from the running environment's site-packages through a ``.pth``
line placed AFTER its own, so the installed wheel - not the source tree - provides ``tpee_ompl``
(asserted below).
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import sysconfig
import venv
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

pytestmark = pytest.mark.slow


def _run(cmd: list[str], cwd: Path, timeout: float = 300) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env["MPLBACKEND"] = "Agg"
    proc = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    assert proc.returncode == 0, f"{cmd} failed ({proc.returncode}):\n{proc.stdout}\n{proc.stderr}"
    return proc


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> tuple[Path, Path]:
    """(python of a fresh venv with the wheel installed, an empty working directory elsewhere)."""
    tmp = tmp_path_factory.mktemp("wheel")
    dist = tmp / "dist"
    _run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q", "-w", str(dist), str(ROOT)],
         cwd=tmp)
    wheels = list(dist.glob("tpee_ompl-*.whl"))
    assert len(wheels) == 1, wheels
    env_dir = tmp / "venv"
    venv.EnvBuilder(with_pip=True).create(env_dir)
    py = env_dir / "bin" / "python"
    site = Path(_run([str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"], cwd=tmp).stdout.strip())
    deps = sysconfig.get_paths()["purelib"]  # this environment's packages, processed as a site dir (cmeel's .pth)
    (site / "zz_deps.pth").write_text(f"import site; site.addsitedir({deps!r})\n")
    _run([str(py), "-m", "pip", "install", "-q", "--no-deps", "--no-index", str(wheels[0])], cwd=tmp)
    work = tmp / "elsewhere"
    work.mkdir()
    return py, work


def test_wheel_imports_from_its_install_not_the_source_tree(installed):
    py, work = installed
    out = _run([str(py), "-c", "import tpee_ompl; print(tpee_ompl.__file__); print(tpee_ompl.__version__)"], cwd=work)
    path, version = out.stdout.split()
    assert Path(path).resolve().is_relative_to(py.parent.parent.resolve()), path
    assert not Path(path).resolve().is_relative_to(ROOT.resolve())
    assert version.count(".") >= 2


def test_wheel_ships_the_named_query_sets(installed):
    py, work = installed
    code = ("from tpee_ompl import load_queries; qs = load_queries('planning_necessary'); "
            "pr = load_queries('paper_random'); print(len(qs), len(pr))")
    assert _run([str(py), "-c", code], cwd=work).stdout.split() == ["120", "120"]


def test_installed_cli_plans_and_reads_the_packaged_library(installed):
    py, work = installed
    cli = str(py.parent / "tpee-ompl")
    plan = _run([cli, "plan", "--from", "1", "--to", "4", "--time", "0.2", "--json"], cwd=work)
    result = json.loads(plan.stdout)
    assert result["valid"] is True and result["exact"] is True
    stats = _run([cli, "library", "stats"], cwd=work)
    assert "240 demonstrations" in stats.stdout
    assert str(py.parent.parent.resolve()) in stats.stdout.splitlines()[0]
    assert _run([str(py), "-m", "tpee_ompl", "--version"], cwd=work).stdout.startswith("tpee-ompl ")


def test_installed_wheel_lists_the_problems_and_benchmarks_a_generic_one(installed):
    py, work = installed
    cli = str(py.parent / "tpee-ompl")
    listing = _run([cli, "bench", "--list-problems"], cwd=work).stdout
    rows = {line.split()[0]: line.split()[2] for line in listing.splitlines()[1:] if line.strip()}
    assert rows["wearer"] == "120" and rows["arm6"] == "10" and rows["panda-shelf"] == "30"  # packaged sets
    assert rows["kinova-posts"] == "30"  # its packaged SRDF and query set
    out = _run([cli, "bench", "--problem", "arm4", "--max-queries", "1", "--samples", "200", "--anytime", "0.1",
                "--workers", "1", "--no-progress", "--out", str(work / "results")], cwd=work, timeout=600).stdout
    assert "benchmark.db" in out
    assert len(list((work / "results").glob("*/benchmark.db"))) == 1


_CONTINUOUS_ARM = """
import math, sys
from ompl import base as ob, geometric as og, util as ou
from tpee_ompl import DimensionRRT, RobotChecker, make_simple_setup
from tpee_ompl.model.obstacles import box
from tpee_ompl.planning.space_layout import RealVectorLayout
open("arm.urdf", "w").write('''<robot name="arm"><link name="base"/>
<link name="a"><collision><origin xyz="0.25 0 0"/><geometry><box size="0.36 0.05 0.05"/></geometry></collision></link>
<link name="b"><collision><origin xyz="0.2 0 0"/><geometry><box size="0.26 0.05 0.05"/></geometry></collision></link>
<joint name="j1" type="continuous"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/></joint>
<joint name="j2" type="revolute"><parent link="a"/><child link="b"/><origin xyz="0.5 0 0"/><axis xyz="0 0 1"/>
<limit lower="-2" upper="2" effort="1" velocity="1"/></joint></robot>''')
ou.setLogLevel(ou.LOG_NONE)
robot = RobotChecker("arm.urdf", obstacles=[box("post", (0.05, 0.05, 0.3), (0.3, 0.0, 0.0))])  # no way through 0
for make in (og.RRTConnect, lambda si: DimensionRRT(si, seed=1, max_samples=300)):
    ss = make_simple_setup(robot, [3.0, 0.0], [-3.0, 0.0])
    si = ss.getSpaceInformation()
    ss.setPlanner(make(si))
    assert ss.solve(5.0) == ob.PlannerStatus.EXACT_SOLUTION and ss.getSolutionPath().check()
    ss.simplifySolution(1.0)
    layout = RealVectorLayout(si.getStateSpace())
    W = layout.from_path(ss.getSolutionPath())
    print("space", type(si.getStateSpace()).__name__, round(float(abs(layout.delta(W[:-1], W[1:])[:, 0]).sum()), 3))
"""


def test_installed_wheel_plans_a_continuous_joint_the_short_way_round(installed):
    py, work = installed
    rows = [line.split()[1:] for line in _run([str(py), "-c", _CONTINUOUS_ARM], cwd=work).stdout.splitlines()
            if line.startswith("space ")]
    assert [r[0] for r in rows] == ["CompoundStateSpace"] * 2
    assert all(float(r[1]) < math.pi for r in rows)  # the first joint's travel: the short way round is 0.28 rad
