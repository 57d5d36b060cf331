"""Applications: command line, plots, demo."""
