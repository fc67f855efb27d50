"""Pictures of the wearer and the arm: scene meshes, figures, animations, workspace plots and the meshcat viewer.

Imports :mod:`tpee_ompl.model` only.
"""
