"""Command-line interface (``mbdsim``)."""
