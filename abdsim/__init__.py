"""abdsim."""
