# Shared by the Blender test scripts: makes Debian's Blender 3.4 glTF add-on work with the numpy
# it ships beside. The add-on still uses `np.bool`, which numpy removed in 1.24; without this alias
# every glTF import or export stops with an AttributeError. Exits with code 3 when numpy is
# missing (callers treat that as "skip").
import sys
import warnings

try:
    import numpy
except ImportError:
    print("numpy is missing (Debian: python3-numpy)", file=sys.stderr)
    sys.exit(3)

with warnings.catch_warnings():
    # numpy 1.24 warns on the very look-up that finds the alias gone.
    warnings.simplefilter("ignore")
    if not hasattr(numpy, "bool"):
        numpy.bool = bool
