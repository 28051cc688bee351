# End-to-end tests of prizma-relight's interactive shell: through a pipe, and in a real
# pseudo-terminal (tmux, label "terminal"): line editing, history, completion, status, undo.
if(NOT TARGET prizma-relight)
  return()
endif()

set(_shell_relight_work ${PRIZMA_E2E_WORK}/relight)  # where the relight_files fixture writes scene.exr

add_test(NAME relight.e2e.shell_piped
         COMMAND ${CMAKE_COMMAND} -DEXE=$<TARGET_FILE:prizma-relight> "-DARGS=scene.exr|-i"
                 -DWORKDIR=${_shell_relight_work} -DSTDIN=${PRIZMA_E2E_DIR}/shell/piped_session.txt
                 "-DMUST_EXIST=shell piped.png"
                 "-DOUT_REGEX=display     Display P3|light       key = A|adaptation  on|undone \\(2 more levels\\)|display     sRGB|error: undo: nothing to undo|error: line: unterminated \" quote|error: compare X2: 99999999999 is outside the [0-9]+×[0-9]+ image|error: compare R: 99999999999 is outside|error: probe X: not a whole number: \"1\\.5\"|▀|saved shell piped\\.png in [0-9.]+ ms|relit in [0-9.]+ ms"
                 -P ${PRIZMA_E2E_DIR}/relight/run_and_check.cmake)
set_tests_properties(relight.e2e.shell_piped PROPERTIES FIXTURES_REQUIRED relight_files
                     ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}" RESOURCE_LOCK relight_e2e_work)

# --show-every outside -i is a usage error.
add_test(NAME relight.e2e.shell_show_every_needs_i
         COMMAND ${CMAKE_COMMAND} -DEXE=$<TARGET_FILE:prizma-relight> "-DARGS=scene.exr|--show-every|-o|se.png"
                 -DWORKDIR=${_shell_relight_work} -DEXPECT_RC=2 "-DERR_REGEX=--show-every: only with -i" -DMUST_NOT_EXIST=se.png
                 -P ${PRIZMA_E2E_DIR}/relight/run_and_check.cmake)
set_tests_properties(relight.e2e.shell_show_every_needs_i PROPERTIES FIXTURES_REQUIRED relight_files
                     ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}" RESOURCE_LOCK relight_e2e_work)

# The real terminal: tmux (scripts/setup installs it) driven from Python's standard library.
find_program(PRIZMA_TMUX tmux)
find_program(PRIZMA_PYTHON3 python3 HINTS /usr/bin)
if(NOT PRIZMA_TMUX OR NOT PRIZMA_PYTHON3)
  prizma_missing_tool_test(relight.e2e.shell_terminal "tmux or python3 (scripts/setup installs them)")
  set_tests_properties(relight.e2e.shell_terminal PROPERTIES LABELS terminal)
  return()
endif()
set(_shell_mri "")
set(_shell_fixtures relight_files)
if(PRIZMA_E2E_MRI_EXR)
  set(_shell_mri --mri ${PRIZMA_E2E_MRI_EXR})
  list(APPEND _shell_fixtures mri_render)
endif()
if(TARGET prizma-render)  # the fluorescent render of tests/e2e/fluorescence.cmake
  list(APPEND _shell_mri --fluor ${PRIZMA_E2E_WORK}/fluorescence/dye.exr)
  list(APPEND _shell_fixtures fluorescence_merged)
endif()
add_test(NAME relight.e2e.shell_terminal
         COMMAND ${PRIZMA_PYTHON3} ${PRIZMA_E2E_DIR}/shell/tmux_shell_test.py $<TARGET_FILE:prizma-relight>
                 ${_shell_relight_work}/scene.exr ${PRIZMA_E2E_WORK}/shell_terminal ${PRIZMA_SOURCE_DATA_DIR}
                 ${_shell_mri})
set_tests_properties(relight.e2e.shell_terminal PROPERTIES FIXTURES_REQUIRED "${_shell_fixtures}" LABELS terminal
                     TIMEOUT 300)
