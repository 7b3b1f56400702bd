"""Small math helpers: rotations and skew matrices."""
