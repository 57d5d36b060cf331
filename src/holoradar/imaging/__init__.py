"""Imaging: migration (wave-front inversion) and what builds on it."""
