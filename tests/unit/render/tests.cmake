tissue_add_test(test_render LABELS unit SOURCES render/test_embedded_surface.cpp render/test_cut_render_surface.cpp
                render/test_cut_render_fill.cpp)
