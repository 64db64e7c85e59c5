"""The reference C library's Python face (library), and the geometry, imaging and oracle
built on it."""
