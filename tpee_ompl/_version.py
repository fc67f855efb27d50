"""The package's version (one home: ``tpee_ompl.__version__``, the wheel's metadata and the benchmark logs read it)."""

__version__ = "0.1.0"
