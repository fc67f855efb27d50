"""Planning in OMPL.

- :mod:`~tpee_ompl.planning.paths`: states <-> arrays, motion states, the whole-path check, lengths
- :mod:`~tpee_ompl.planning.setup`: the wearer-arm OMPL set-up (validity checker, batched motion validator)
- :mod:`~tpee_ompl.planning.grouped_space`: the fake-time, DOF-grouped view of a problem
- :mod:`~tpee_ompl.planning.dimension_search`, :mod:`~tpee_ompl.planning.dimension_rrt`: the generic
  dimension-RRT search and its ``ob.Planner`` (settings: :mod:`~tpee_ompl.planning.dimension_rrt_options`;
  goal regions: :mod:`~tpee_ompl.planning.goal_runs`); :mod:`~tpee_ompl.planning.tpee`: its TPEE factory
- :mod:`~tpee_ompl.planning.query_generation`: cross-sector benchmark queries

Imports only :mod:`tpee_ompl.model` (and the top-level ``validation``/``resources``) below it.
"""
