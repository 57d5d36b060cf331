"""Scene model: targets, receiver apertures and the forward simulation."""
