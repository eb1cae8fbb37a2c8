# The Tissue FMU's variable table (value references, types, starts, ranges): plain C++, no FMI
# headers, shared by the FMU and the test that keeps it equal to modelDescription/Tissue.xml.
add_library(tissue_fmi3_variables STATIC ${CMAKE_CURRENT_LIST_DIR}/variables.cpp)
add_library(tissue::fmi3_variables ALIAS tissue_fmi3_variables)
target_include_directories(tissue_fmi3_variables PUBLIC ${PROJECT_SOURCE_DIR}/fmu_src)
target_compile_features(tissue_fmi3_variables PUBLIC cxx_std_20)
target_link_libraries(tissue_fmi3_variables PRIVATE tissue::warnings)
