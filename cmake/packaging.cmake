# The Debian packages (issue 43; docs/INSTALL.md), from the install rules' two components:
#   tissue      (runtime) tissue-host, the benches, the FMUs, the SSP, the meshes, the scenarios and
#               `import tissue` for Debian's python3, under /usr;
#   tissue-dev  (dev)     the headers, the static libraries and the CMake package Tissue.
# `cpack -G DEB` in the build folder writes tissue_<version>_amd64.deb and tissue-dev_<version>_amd64.deb.
# The runtime's Depends come from dpkg-shlibdeps over its binaries (Debian's library package names);
# the FMUs' libraries sit inside zip files that dpkg-shlibdeps cannot read, but link nothing the Python
# module does not (both are the core over the same Debian libraries).
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME tissue)
set(CPACK_PACKAGE_VENDOR "tissue")
set(CPACK_PACKAGE_CONTACT "tissue engineers <tissue@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Real-time virtual dissection engine: co-rotational FEM tissue cut with XFEM, as FMI 3.0 FMUs")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_COMPONENTS_ALL runtime dev)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)

set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME tissue)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_DESCRIPTION
    "Real-time virtual dissection engine (programs, FMUs, meshes, Python module)\n tissue-host runs the Tissue and HapticLoop FMI 3.0 co-simulation FMUs in real time next to a\n 1 kHz haptic loop; `import tissue` drives the core from python3.")
# The module is built for Debian 12's python3 (3.11); pybind11's Eigen arrays are numpy's.
if(DEFINED TISSUE_PYTHON_MINOR_VERSION)
  math(EXPR next_minor "${TISSUE_PYTHON_MINOR_VERSION} + 1")
  set(CPACK_DEBIAN_RUNTIME_PACKAGE_DEPENDS
      "python3 (>= 3.${TISSUE_PYTHON_MINOR_VERSION}), python3 (<< 3.${next_minor}), python3-numpy")
endif()
# CHOLMOD's supernodal factorization of a 52.8k-tet box: 0.50 s on OpenBLAS, 4.0 s on the reference BLAS
# (measured for issue 42). What the setup script installs.
set(CPACK_DEBIAN_RUNTIME_PACKAGE_RECOMMENDS libopenblas0-serial)
set(CPACK_DEBIAN_DEV_PACKAGE_NAME tissue-dev)
set(CPACK_DEBIAN_DEV_PACKAGE_SHLIBDEPS OFF)
set(CPACK_DEBIAN_DEV_PACKAGE_DESCRIPTION
    "Real-time virtual dissection engine (headers, static libraries, CMake package)\n find_package(Tissue CONFIG REQUIRED) gives tissue::core, tissue::haptic_core and\n tissue::fmi_importer.")
set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS
    "tissue (= ${PROJECT_VERSION}), cmake (>= 3.25), pkg-config, libeigen3-dev, libsuitesparse-dev, libsundials-dev, libbullet-dev, libpugixml-dev, libzip-dev")

include(CPack)
