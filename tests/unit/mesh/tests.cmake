tissue_add_test(test_mesh LABELS unit SOURCES mesh/test_mesh_io.cpp mesh/test_mesh_regions.cpp mesh/test_topology.cpp)
