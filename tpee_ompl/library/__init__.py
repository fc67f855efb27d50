"""The real-time layer: DMP maths, the cross-sector path library (demos, build, storage, queries,
evaluation) and the tracker.

Modules: :mod:`~tpee_ompl.library.dmp` (DMP maths), :mod:`~tpee_ompl.library.demos` (query sampler,
demo planners, demos per pair), :mod:`~tpee_ompl.library.build` (build settings, DMP learning),
:mod:`~tpee_ompl.library.path_library` (:class:`PathLibrary`, queries), :mod:`~tpee_ompl.library.storage`
(library files), :mod:`~tpee_ompl.library.evaluation` (benchmark rows), :mod:`~tpee_ompl.library.tracker`
(Fig. 10 target tracking).  Imports :mod:`tpee_ompl.model` and :mod:`tpee_ompl.planning` below it.
"""

from .build import LIBRARY_DMP_OPTIONS, LibraryBuildOptions
from .demos import (
    DEMO_MARGINS,
    N_FAKE_TIME_STEPS,
    POINTING_LINKS,
    DemoPlanner,
    PairDemos,
    dimension_rrt_planner,
    query_sampler,
)
from .dmp import DMP, DMPOptions, generate, generate_blended, learn_dmp, min_samples
from .evaluation import benchmark_queries
from .path_library import PathLibrary, QueryResult
from .planner import LibraryDimensionRRT, infer_sector
from .storage import FORMAT_VERSION, LibraryFileError
from .tracker import Tracker, TrackerOptions, make_default_planner

__all__ = [
    "LibraryDimensionRRT",
    "infer_sector",
    "DEMO_MARGINS",
    "DMP",
    "DMPOptions",
    "FORMAT_VERSION",
    "LIBRARY_DMP_OPTIONS",
    "LibraryBuildOptions",
    "LibraryFileError",
    "N_FAKE_TIME_STEPS",
    "POINTING_LINKS",
    "DemoPlanner",
    "PairDemos",
    "PathLibrary",
    "QueryResult",
    "Tracker",
    "TrackerOptions",
    "benchmark_queries",
    "dimension_rrt_planner",
    "generate",
    "generate_blended",
    "learn_dmp",
    "make_default_planner",
    "min_samples",
    "query_sampler",
]
