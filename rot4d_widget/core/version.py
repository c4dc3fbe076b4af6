"""The package's version, the same as pyproject.toml's (tests/project/test_wheel.py checks it).

A module that imports nothing, so that what records the version (a state file,
`rot4d_widget.keep.statefile`) takes it from here and never imports the root package, whose
``__init__`` re-exports it as ``rot4d_widget.__version__``.
"""

__version__ = "0.1.0"
