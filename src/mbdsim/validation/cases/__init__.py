"""Validation cases: one module ``caseNN_slug.py`` per problem, each with ``CASE`` and ``run()``."""
