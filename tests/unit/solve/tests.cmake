tissue_add_test(test_solve LABELS unit SOURCES solve/test_pcg.cpp solve/test_cholmod.cpp
                solve/test_cholesky_pcg.cpp)
