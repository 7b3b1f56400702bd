"""Tier 4: results (time histories, measures, events)."""
from .result import Result

__all__ = ["Result"]
