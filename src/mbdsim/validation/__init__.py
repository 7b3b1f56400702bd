"""The validation suite: 30 textbook problems, their runner and the report."""
