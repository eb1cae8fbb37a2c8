tissue_add_test(test_xfem LABELS unit SOURCES xfem/test_xfem.cpp xfem/test_xfem_growth.cpp xfem/test_xfem_beam.cpp xfem/test_xfem_pieces.cpp xfem/test_xfem_regions.cpp
                xfem/test_point_spring.cpp)
# Counts operator new across steps; its own executable because it replaces the global allocator.
tissue_add_test(test_xfem_allocations LABELS unit SOURCES xfem/test_xfem_allocations.cpp)
