tissue_add_test(test_integrate LABELS unit SOURCES integrate/test_backward_euler.cpp integrate/test_galerkin_start.cpp)
# Counts operator new across steps; its own executable because it replaces the global allocator.
tissue_add_test(test_step_allocations LABELS unit SOURCES integrate/test_step_allocations.cpp)
tissue_add_test(test_backward_euler_large_turns LABELS unit SOURCES integrate/test_backward_euler_large_turns.cpp)
tissue_add_test(test_step_threads LABELS unit SOURCES integrate/test_step_threads.cpp)
tissue_add_test(test_evaluation_ahead LABELS unit SOURCES integrate/test_evaluation_ahead.cpp)
tissue_add_test(test_backward_euler_predicted_end LABELS unit SOURCES integrate/test_backward_euler_predicted_end.cpp)
