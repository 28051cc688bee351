# install(): `cmake --install build --prefix X` gives a working tree, relocatable as a whole:
#   X/bin/prizma-render, prizma-relight, prizma-metamer
#   X/lib/prizma/libprizma_imageio.so, libprizma_vdb.so  the modules loaded on first use
#   X/share/prizma/{spectra,ocio,scenes}   the data the tools read (found relative to the executable)
#   X/share/prizma/examples/colorchecker.exr  the spectral image relight.md's examples relight
#   X/share/doc/prizma/                    README.md and docs/ (the user guide runs against this tree)
#   X/share/man/man1/prizma-*.1, X/share/bash-completion/completions/prizma-*  (PrizmaToolDocs.cmake)
include(GNUInstallDirs)

set(PRIZMA_INSTALL_DATADIR "${CMAKE_INSTALL_DATADIR}/prizma" CACHE STRING
    "Where the data tables, OCIO config and example scenes go, relative to the prefix")
# The executables find the data and the modules from their own location, so the tree works wherever
# it is moved ($PRIZMA_DATA_DIR still overrides): the path from bin/ up to the prefix and from the
# prefix to the data folder, compiled in (libspectral installed_prefix.h, data_path.h).
if(IS_ABSOLUTE "${CMAKE_INSTALL_BINDIR}" OR IS_ABSOLUTE "${PRIZMA_INSTALL_DATADIR}")
  file(RELATIVE_PATH _prizma_prefix_rel "${CMAKE_INSTALL_FULL_BINDIR}" "${CMAKE_INSTALL_PREFIX}")
  file(RELATIVE_PATH _prizma_data_rel "${CMAKE_INSTALL_PREFIX}" "${CMAKE_INSTALL_PREFIX}/${PRIZMA_INSTALL_DATADIR}")
  if(IS_ABSOLUTE "${PRIZMA_INSTALL_DATADIR}")
    file(RELATIVE_PATH _prizma_data_rel "${CMAKE_INSTALL_PREFIX}" "${PRIZMA_INSTALL_DATADIR}")
  endif()
else()
  file(RELATIVE_PATH _prizma_prefix_rel "/prefix/${CMAKE_INSTALL_BINDIR}" "/prefix")
  file(RELATIVE_PATH _prizma_data_rel "/prefix" "/prefix/${PRIZMA_INSTALL_DATADIR}")
endif()
target_compile_definitions(prizma_spectral PRIVATE PRIZMA_INSTALL_PREFIX_FROM_BINDIR="${_prizma_prefix_rel}"
                                                   PRIZMA_INSTALL_DATA_FROM_PREFIX="${_prizma_data_rel}")

set(_prizma_tools)
foreach(tool prizma-render prizma-relight prizma-metamer)
  if(TARGET ${tool})
    list(APPEND _prizma_tools ${tool})
  endif()
endforeach()
install(TARGETS ${_prizma_tools} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT tools)
# Everything that is installed, and nothing else (no test suites): scripts/install and scripts/demo
# build this target. A new installed target (the Python module) adds itself with add_dependencies.
add_custom_target(prizma-installed)
add_dependencies(prizma-installed ${_prizma_tools})
# The modules the tools load on first use — the image module for PNG/TIFF/JPEG (imageio/) and the
# VDB module for OpenVDB volumes (vdb/), both installed into lib/prizma — and the Python module
# (python/; its own install rule): all are installed, so all are built.
foreach(module prizma_imageio prizma_vdb prizma_python prizma_colorchecker_example)
  if(TARGET ${module})
    add_dependencies(prizma-installed ${module})
  endif()
endforeach()

install(DIRECTORY ${PROJECT_SOURCE_DIR}/data/spectra ${PROJECT_SOURCE_DIR}/data/ocio ${PROJECT_SOURCE_DIR}/data/scenes
        DESTINATION ${PRIZMA_INSTALL_DATADIR} COMPONENT data)
# The example spectral image relight.md relights (written at build time: relight/CMakeLists.txt).
install(FILES ${PRIZMA_COLORCHECKER_EXR} DESTINATION ${PRIZMA_INSTALL_DATADIR}/examples COMPONENT data)

install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR} COMPONENT docs)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR} COMPONENT docs)

# The Python module (`import prizma`): its own CMakeLists has its install() rule (COMPONENT python);
# prizma-installed depends on it (above), so scripts/install builds and installs it too.

# Man pages and bash completion, made from the tools' --help (cmake/PrizmaToolDocs.cmake).
include(${CMAKE_CURRENT_LIST_DIR}/PrizmaToolDocs.cmake)
