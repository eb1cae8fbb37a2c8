tissue_add_test(test_contact LABELS unit SOURCES contact/test_point_contact.cpp contact/test_contact_stiffness.cpp contact/test_background_contact_stiffness.cpp
                contact/test_quasi_static_poke.cpp contact/test_contact_dynamics.cpp contact/test_point_spring.cpp
                contact/test_pad_contact.cpp)
