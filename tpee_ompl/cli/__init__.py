"""The ``tpee-ompl`` command line, one module per command group; the top floor of the package."""

from .main import main

__all__ = ["main"]
