tissue_add_test(test_system LABELS unit SOURCES system/test_block_sparse_matrix.cpp system/test_assembly.cpp
                                                 system/test_background_policy.cpp
                                                 system/test_background_work.cpp)
