"""geomlib."""
