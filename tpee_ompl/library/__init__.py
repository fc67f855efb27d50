"""The real-time layer: DMP maths, the cross-sector path library (demos, storage, queries) and the tracker.

Imports :mod:`tpee_ompl.model` and :mod:`tpee_ompl.planning` below it.
"""
