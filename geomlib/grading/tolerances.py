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

#: Wall-clock seconds for grading a whole submission. Gradescope stops an autograder after 10 minutes
#: by default and then keeps no result at all, so once this budget is spent the remaining tests fail
#: at once with a message saying so, and results.json is still written (env GEOMLIB_TIME_BUDGET).
TIME_BUDGET_S = 480.0

#: Seconds one feedback picture may take to draw (it is skipped after that).
PICTURE_TIME_S = 20.0

#: Largest result one call may send back: the larger of this many MiB and RESULT_INPUT_FACTOR times
#: the size of the call's inputs. Checked by the grader before it allocates anything.
RESULT_MIN_MB = 256
RESULT_INPUT_FACTOR = 64

#: Largest rows x cols of a returned sparse matrix (checks densify small ones; the largest stored
#: reference matrix has 5.1e6 entries).
SPARSE_MAX_DENSE = 2**25

#: Characters of one message from student code (exception text, printed output) kept by the grader.
MESSAGE_CHARS = 4000
