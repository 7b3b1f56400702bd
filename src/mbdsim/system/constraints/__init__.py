"""Constraint equations: vectorised primitives and one small class per joint type."""
