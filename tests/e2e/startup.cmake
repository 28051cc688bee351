# Start-up (issue 14): the tools link neither OpenImageIO nor OpenVDB; OpenImageIO's ~260 shared
# libraries come with the image module (libprizma_imageio.so), loaded the first time a PNG, TIFF or
# transfer-function image is read or written, and OpenVDB's with the VDB module (libprizma_vdb.so),
# loaded the first time a "vdb" volume is read. tests/e2e/startup/check-loaded runs a tool under
# LD_DEBUG=files and checks what the dynamic loader loaded. And a module that cannot be found is one
# error line, exit 1.
if(NOT TARGET prizma-render OR NOT TARGET prizma-relight)
  return()
endif()
find_program(PRIZMA_SYSTEM_PYTHON3 NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
if(NOT PRIZMA_SYSTEM_PYTHON3)
  prizma_missing_tool_test(startup.e2e.python "/usr/bin/python3 (the start-up tests' driver)")
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

prizma_startup_e2e(render_version --not-loaded image --not-loaded vdb -- $<TARGET_FILE:prizma-render> --version)
prizma_startup_e2e(render_exr --not-loaded image --not-loaded vdb --output startup.exr
                   -- $<TARGET_FILE:prizma-render> ${_startup_tiny} -q -o startup.exr)
prizma_startup_e2e(render_preview --loaded image --output startup.png
                   -- $<TARGET_FILE:prizma-render> ${_startup_tiny} -q -o startup_p.exr --preview startup.png)
# Raw and NIfTI volumes: no OpenVDB; a .vdb volume: the VDB module and OpenVDB, not OpenImageIO.
prizma_startup_e2e(render_raw --not-loaded vdb --not-loaded image --output startup_raw.exr
                   -- $<TARGET_FILE:prizma-render> ${PRIZMA_E2E_DIR}/startup/raw.json -q -o startup_raw.exr)
prizma_startup_e2e(render_nifti --not-loaded vdb --not-loaded image --output startup_nifti.exr
                   -- $<TARGET_FILE:prizma-render> ${PRIZMA_SOURCE_DATA_DIR}/scenes/bench_peer.json --spp 1 -q
                   -o startup_nifti.exr)
prizma_startup_e2e(render_vdb --loaded vdb --not-loaded image --output startup_vdb.exr
                   -- $<TARGET_FILE:prizma-render> ${PRIZMA_SOURCE_DATA_DIR}/scenes/cloud_vdb.json --spp 1 -q
                   -D camera.width=8 -D camera.height=8 -o startup_vdb.exr)
prizma_startup_e2e(relight_version --not-loaded image --not-loaded vdb -- $<TARGET_FILE:prizma-relight> --version)
prizma_startup_e2e(relight_png --loaded image --output startup_relit.png
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

# The same for the VDB module: a .vdb render without it is one line, exit 1, no file left.
add_test(NAME startup.e2e.vdb_module_missing
         COMMAND ${PRIZMA_SYSTEM_PYTHON3} ${PRIZMA_E2E_DIR}/errors/check-error --workdir ${_startup_work} --rc 1
                 --input "libprizma_vdb\\.so" --reason "cannot find the VDB module"
                 --output startup_vdb_missing.exr -- $<TARGET_FILE:prizma-render> ${PRIZMA_SOURCE_DATA_DIR}/scenes/cloud_vdb.json
                 --spp 1 -q -D camera.width=8 -D camera.height=8 -o startup_vdb_missing.exr)
set_tests_properties(startup.e2e.vdb_module_missing PROPERTIES LABELS startup RESOURCE_LOCK startup_e2e_work
                     ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR};PRIZMA_VDB_MODULE=${_startup_work}/no/libprizma_vdb.so")

# The VDB module under address-space limits: each run a success or one "out of memory" line, exit 1
# (below 200 MB left the module is not loaded: near 100 MB log4cplus's initialiser gave up on its
# thread, and one run hung). Not in sanitizer builds: ASan reserves terabytes of address space.
if(NOT PRIZMA_SANITIZE AND NOT PRIZMA_FUZZ)
  add_test(NAME startup.e2e.vdb_out_of_memory
           COMMAND ${PRIZMA_SYSTEM_PYTHON3} ${PRIZMA_E2E_DIR}/errors/check-memory-limits --workdir ${_startup_work}
                   --output startup_vdb_mem.exr --limits-mb 30,60,100,150,250,400
                   -- $<TARGET_FILE:prizma-render> ${PRIZMA_SOURCE_DATA_DIR}/scenes/cloud_vdb.json --spp 1 -q
                   -D camera.width=8 -D camera.height=8 -o startup_vdb_mem.exr)
  set_tests_properties(startup.e2e.vdb_out_of_memory PROPERTIES LABELS startup RESOURCE_LOCK startup_e2e_work
                       ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}")
endif()
