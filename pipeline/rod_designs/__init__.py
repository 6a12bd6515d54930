"""The five connecting-rod designs behind `make_designs.py`: built with gmsh's OpenCASCADE kernel,
calibrated to thesis Table 5.1, tessellated and written as STL (see `make_designs.py`'s doc)."""
