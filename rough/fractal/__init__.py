"""Fractal characterisation and synthesis: power-law spectra, D and C."""
