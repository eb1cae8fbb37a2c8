tissue_add_test(test_fem LABELS unit SOURCES fem/test_tet_element.cpp fem/test_rotation.cpp fem/test_corotational.cpp fem/test_regions.cpp fem/test_stable_neo_hookean.cpp fem/test_neo_hookean_body.cpp
                 fem/test_block_frames.cpp)
