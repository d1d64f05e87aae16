"""Graded tests of the denoise lab (Laplacian displacement denoising)."""
