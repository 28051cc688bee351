# Man pages (share/man/man1) and bash completion (share/bash-completion/completions) of the tools,
# made from their --help texts at build time by cmake/make_tool_docs.py, and installed with them
# (prizma-installed builds them). Man pages need help2man (Debian help2man, scripts/setup installs
# it); without it they are left out with a note, and the docs test says so (tests/missing-tool).
find_program(PRIZMA_HELP2MAN help2man)
find_package(Python3 COMPONENTS Interpreter QUIET)
set(_tool_docs ${CMAKE_BINARY_DIR}/tool-docs)
set(_tool_docs_outputs)
# prizma_tool_docs(TOOL SUMMARY [SUBCOMMAND...]): its completion script and, with help2man, its man page.
function(prizma_tool_docs tool summary)
  if(NOT TARGET ${tool} OR NOT Python3_Interpreter_FOUND)
    return()
  endif()
  set(run ${CMAKE_COMMAND} -E env PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR} ${Python3_EXECUTABLE}
          ${PROJECT_SOURCE_DIR}/cmake/make_tool_docs.py)
  add_custom_command(OUTPUT ${_tool_docs}/completions/${tool}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${_tool_docs}/completions
    COMMAND ${run} completion $<TARGET_FILE:${tool}> ${tool} ${_tool_docs}/completions/${tool} ${ARGN}
    DEPENDS ${tool} ${PROJECT_SOURCE_DIR}/cmake/make_tool_docs.py VERBATIM)
  set(outputs ${_tool_docs}/completions/${tool})
  if(PRIZMA_HELP2MAN)
    add_custom_command(OUTPUT ${_tool_docs}/man1/${tool}.1
      COMMAND ${CMAKE_COMMAND} -E make_directory ${_tool_docs}/man1
      COMMAND ${run} man $<TARGET_FILE:${tool}> ${tool} "${summary}" ${_tool_docs}/man1/${tool}.1 ${ARGN}
      DEPENDS ${tool} ${PROJECT_SOURCE_DIR}/cmake/make_tool_docs.py VERBATIM)
    list(APPEND outputs ${_tool_docs}/man1/${tool}.1)
  endif()
  set(_tool_docs_outputs ${_tool_docs_outputs} ${outputs} PARENT_SCOPE)
endfunction()
prizma_tool_docs(prizma-render "path-trace a volume scene into a spectral OpenEXR file" merge inspect)
prizma_tool_docs(prizma-relight "relight a spectral OpenEXR file under any light spectra" compress)
prizma_tool_docs(prizma-metamer "design metamers and lights that hide or reveal a difference"
                 metamer light delta-e weights tabulate)
if(NOT PRIZMA_HELP2MAN)
  message(STATUS "help2man not found: no man pages (scripts/setup installs Debian's help2man)")
endif()
add_custom_target(prizma_tool_docs ALL DEPENDS ${_tool_docs_outputs})
add_dependencies(prizma-installed prizma_tool_docs)
install(DIRECTORY ${_tool_docs}/man1 DESTINATION ${CMAKE_INSTALL_MANDIR} COMPONENT docs OPTIONAL)
install(DIRECTORY ${_tool_docs}/completions DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion COMPONENT docs
        OPTIONAL)
