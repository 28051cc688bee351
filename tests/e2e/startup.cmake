# Start-up (issue 14): the tools do not link OpenImageIO; its ~260 shared libraries come with the
# image module (libprizma_imageio.so), loaded the first time a PNG, TIFF or transfer-function image
# is read or written. tests/e2e/startup/check-loaded runs a tool under LD_DEBUG=files and checks
# what the dynamic loader loaded. And a module that cannot be found is one error line, exit 1.
if(NOT TARGET prizma-render OR NOT TARGET prizma-relight)
  return()
endif()
find_program(PRIZMA_SYSTEM_PYTHON3 NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
if(NOT PRIZMA_SYSTEM_PYTHON3)
  message(STATUS "tests/e2e/startup.cmake: /usr/bin/python3 not found, start-up tests skipped")
  return()
endif()
set(_startup_work ${PRIZMA_E2E_WORK}/startup)
file(MAKE_DIRECTORY ${_startup_work})
set(_startup_check ${PRIZMA_SYSTEM_PYTHON3} ${PRIZMA_E2E_DIR}/startup/check-loaded --workdir ${_startup_work})
set(_startup_tiny ${PRIZMA_E2E_DIR}/render/tiny.json)

# prizma_startup_e2e(NAME ARGS...): one check-loaded run.
function(prizma_startup_e2e name)
  add_test(NAME startup.e2e.${name} COMMAND ${_startup_check} ${ARGN})
  set_tests_properties(startup.e2e.${name} PROPERTIES LABELS startup RESOURCE_LOCK startup_e2e_work
                       ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}")
endfunction()

prizma_startup_e2e(render_version --not-loaded -- $<TARGET_FILE:prizma-render> --version)
prizma_startup_e2e(render_exr --not-loaded --output startup.exr -- $<TARGET_FILE:prizma-render> ${_startup_tiny} -q -o startup.exr)
prizma_startup_e2e(render_preview --loaded --output startup.png
                   -- $<TARGET_FILE:prizma-render> ${_startup_tiny} -q -o startup_p.exr --preview startup.png)
prizma_startup_e2e(relight_version --not-loaded -- $<TARGET_FILE:prizma-relight> --version)
prizma_startup_e2e(relight_png --loaded --output startup_relit.png
                   -- $<TARGET_FILE:prizma-relight> startup.exr -o startup_relit.png)
set_tests_properties(startup.e2e.render_exr PROPERTIES FIXTURES_SETUP startup_exr)
set_tests_properties(startup.e2e.relight_png PROPERTIES FIXTURES_REQUIRED startup_exr)

# No module where it is looked for: one line naming it, exit 1, no preview and no spectral file left.
add_test(NAME startup.e2e.module_missing
         COMMAND ${PRIZMA_SYSTEM_PYTHON3} ${PRIZMA_E2E_DIR}/errors/check-error --workdir ${_startup_work} --rc 1
                 --input "libprizma_imageio\\.so" --reason "cannot find the image module"
                 --output startup_missing.png -- $<TARGET_FILE:prizma-render> ${_startup_tiny} -q
                 -o startup_missing.exr --preview startup_missing.png)
set_tests_properties(startup.e2e.module_missing PROPERTIES LABELS startup RESOURCE_LOCK startup_e2e_work
                     ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR};PRIZMA_IMAGE_IO_MODULE=${_startup_work}/no/libprizma_imageio.so")
