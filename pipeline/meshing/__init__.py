"""The gmsh adapter behind `mesh_rod.py`: it executes the meshing policy rodstudy hands over
(`src/mesher/policy.rs`) and defines none; one concept per module (see `mesh_rod.py`'s doc)."""
