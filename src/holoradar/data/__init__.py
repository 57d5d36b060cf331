"""Data types: holograms and images with physical coordinates."""
