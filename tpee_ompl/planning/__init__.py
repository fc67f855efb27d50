"""Planning in OMPL: path conversions and motion states, the OMPL set-up, the grouped space,
the generic dimension-RRT planner and its TPEE factory, query generation.

Imports only :mod:`tpee_ompl.model` below it.
"""
