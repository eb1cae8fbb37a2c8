tissue_add_test(test_cut LABELS unit SOURCES cut/test_convex_piece.cpp cut/test_cut_geometry.cpp cut/test_volume_cutter.cpp
                cut/test_stroke_fuzz.cpp cut/test_cut_surface_weld.cpp)
# Counts operator new across steps; its own executable because it replaces the global allocator.
tissue_add_test(test_cut_allocations LABELS unit SOURCES cut/test_cut_allocations.cpp)
