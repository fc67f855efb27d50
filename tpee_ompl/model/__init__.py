"""The wearer and the TPEE maths: model loading and collision checks, the aiming IK, sectors, query files.

The lowest floor of the package: it imports nothing from ``planning``, ``library``, ``bench``,
``viz`` or ``cli``.
"""
