"""Benchmark campaigns on ``ompl.tools.Benchmark``: configuration, planners, experiments, executors,
the Planner-Arena database, results files, the Table-4 report and plots.
"""
