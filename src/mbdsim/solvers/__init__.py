"""Tier 3: analyses (assembly, kinematic, dynamic, static)."""
