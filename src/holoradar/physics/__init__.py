"""Physics layer: media, sources and propagators (forward and adjoint)."""
