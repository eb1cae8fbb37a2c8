tissue_add_test(test_fem LABELS unit SOURCES fem/test_tet_element.cpp fem/test_rotation.cpp fem/test_corotational.cpp fem/test_regions.cpp fem/test_stable_neo_hookean.cpp fem/test_neo_hookean_body.cpp
                 fem/test_block_frames.cpp)
# The XFEM (core/fem/deformable_body.*, xfem_*): enriched unknowns, their growth, pieces and regions.
tissue_add_test(test_xfem LABELS unit SOURCES fem/test_xfem.cpp fem/test_xfem_growth.cpp fem/test_xfem_beam.cpp
                fem/test_xfem_pieces.cpp fem/test_xfem_regions.cpp)
# Counts operator new across steps; its own executable because it replaces the global allocator.
tissue_add_test(test_xfem_allocations LABELS unit SOURCES fem/test_xfem_allocations.cpp)
