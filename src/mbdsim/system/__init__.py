"""Tier 2: assembled equations (coordinates, constraints, Jacobians, mass matrix, forces)."""
from .assemble import System, assemble_system
from .equations import constraint_terms, phi

__all__ = ["System", "assemble_system", "constraint_terms", "phi"]
