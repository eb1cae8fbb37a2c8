tissue_add_test(test_solve LABELS unit SOURCES solve/test_pcg.cpp solve/test_cholmod.cpp
                solve/test_cholesky_pcg.cpp solve/test_half_matrix.cpp solve/test_two_level_pcg.cpp
                solve/test_part_translations.cpp solve/test_block_cholesky.cpp solve/test_compact_rows.cpp)
# test_cholmod reaches CholmodFactor (internal to core/solve) for the BLAS paths: CHOLMOD's header.
target_link_libraries(test_solve PRIVATE SuiteSparse::CHOLMOD)
