tissue_add_test(test_tissue LABELS unit SOURCES tissue/test_tissue.cpp tissue/test_tissue_state.cpp
                tissue/test_tissue_robustness.cpp tissue/test_settings_schema.cpp)
