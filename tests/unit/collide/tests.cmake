tissue_add_test(test_collide LABELS unit SOURCES collide/test_geometry.cpp collide/test_surface_bvh.cpp)
# Counts operator new around refit and queries; its own executable because it replaces the global allocator.
tissue_add_test(test_collide_allocations LABELS unit SOURCES collide/test_surface_bvh_allocations.cpp)
