# `cmake --install build --prefix DIR` installs:
#   DIR/bin/gilab                         the command (its own shaders are embedded)
#   DIR/lib/libgilab_core.so*             the core, shared with technique modules
#   DIR/lib/gilab/techniques/             where gilab looks for modules beside itself
#   DIR/include/gilab/core/...            the core's headers (and the generated build facts)
#   DIR/share/gilab/shaders/common/       the shared shaders, for `#include "common/..."`
#   DIR/lib/cmake/gilab/                  find_package(gilab): gilab::core, gilab::gilab (the
#                                         command) and gilab_add_technique()
#   DIR/share/gilab/gilab_report/         the report's Python package (experiments/cli)
#   DIR/share/gilab/techniques/<id>/      each technique's paper.json, read by the report
# so that a technique in its own repository builds against DIR (docs/tutorial.md, "Your
# technique in your own repository"; tests/out_of_tree_test.sh).
include(CMakePackageConfigHelpers)
set(GILAB_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/gilab)

install(TARGETS gilab EXPORT gilabTargets RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS gilab_core EXPORT gilabTargets
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/gilab)
install(DIRECTORY ${CMAKE_SOURCE_DIR}/core/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/gilab/core
        FILES_MATCHING PATTERN "*.h")
install(FILES ${CMAKE_BINARY_DIR}/generated/core/util/build_info.h
              ${CMAKE_BINARY_DIR}/generated/core/util/git_commit.h
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/gilab/core/util)
install(DIRECTORY ${CMAKE_SOURCE_DIR}/shaders/common/
        DESTINATION ${CMAKE_INSTALL_DATADIR}/gilab/shaders/common)
install(DIRECTORY DESTINATION ${CMAKE_INSTALL_LIBDIR}/gilab/techniques)
install(EXPORT gilabTargets NAMESPACE gilab:: DESTINATION ${GILAB_INSTALL_CMAKEDIR})
configure_package_config_file(${CMAKE_SOURCE_DIR}/cmake/gilabConfig.cmake.in
    ${CMAKE_BINARY_DIR}/gilabConfig.cmake INSTALL_DESTINATION ${GILAB_INSTALL_CMAKEDIR}
    PATH_VARS CMAKE_INSTALL_DATADIR)
# A module must match the exact version (and commit, core/technique/module_abi.h).
write_basic_package_version_file(${CMAKE_BINARY_DIR}/gilabConfigVersion.cmake
    VERSION ${PROJECT_VERSION} COMPATIBILITY ExactVersion)
install(FILES ${CMAKE_BINARY_DIR}/gilabConfig.cmake ${CMAKE_BINARY_DIR}/gilabConfigVersion.cmake
              ${CMAKE_SOURCE_DIR}/cmake/GilabTechnique.cmake
              ${CMAKE_SOURCE_DIR}/cmake/GilabShaders.cmake
              ${CMAKE_SOURCE_DIR}/cmake/GilabEmbedText.cmake
              ${CMAKE_SOURCE_DIR}/cmake/gilab_module_abi.cpp
        DESTINATION ${GILAB_INSTALL_CMAKEDIR})

# The report's Python package (modules, templates/, static/), found relative to the binary and
# run as `PYTHONPATH=DIR/share/gilab python3 -m gilab_report` (experiments/cli/run_command.cpp).
install(DIRECTORY ${CMAKE_SOURCE_DIR}/scripts/gilab_report/
        DESTINATION ${CMAKE_INSTALL_DATADIR}/gilab/gilab_report
        FILES_MATCHING PATTERN "*.py" PATTERN "*.j2" PATTERN "*.css" PATTERN "*.js"
        PATTERN "__pycache__" EXCLUDE)
# Each technique's paper facts (techniques/<id>/paper.json), read by the report's
# gilab_report/paper_facts.py from DIR/share/gilab/techniques.
install(DIRECTORY ${CMAKE_SOURCE_DIR}/techniques/ DESTINATION ${CMAKE_INSTALL_DATADIR}/gilab/techniques
        FILES_MATCHING PATTERN "paper.json" PATTERN "tests" EXCLUDE PATTERN "shaders" EXCLUDE
        PATTERN "configs" EXCLUDE)
