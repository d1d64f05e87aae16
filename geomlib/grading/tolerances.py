"""Every grading tolerance and limit, in one place.

A check that needs a tolerance takes its default from here, so a student (and an instructor) can
read in one file how close is close enough, and why.
"""

#: Arithmetic that should agree to round-off: subdivision weights, quadrics, matrix identities.
EXACT = 1e-10

#: Positions produced by a longer chain of float operations (several levels, solves).
GEOMETRY = 1e-8

#: Surface distances (Hausdorff, Chamfer, RMS) relative to the bounding-box diagonal, for outputs
#: whose exact vertices are not part of the spec (simplification, baking).
SURFACE_REL = 1e-3

#: Images in [0, 1]: a pixel counts as different above this absolute difference.
IMAGE_PIXEL = 2.0 / 255.0

#: Images: fraction of pixels allowed to differ by more than IMAGE_PIXEL (edges, ties in the z-buffer).
IMAGE_BAD_FRACTION = 0.005

#: Images: minimum peak signal-to-noise ratio, in dB, where a PSNR comparison is used.
IMAGE_PSNR = 40.0

#: Quantised maps: one quantisation step of an 8-bit / 16-bit image.
QUANT_8 = 1.0 / 255.0
QUANT_16 = 1.0 / 65535.0

#: Wall-clock seconds one call into student code may take before it is stopped.
TIME_LIMIT_S = 30.0

#: Extra address space, in MiB, one call into student code may allocate.
MEMORY_LIMIT_MB = 4096

#: Characters of a student's printed output shown in feedback.
OUTPUT_CHARS = 1500
