# The output rules of docs/errors.md ("Outputs") through the executables: failed writes (a file-size
# limit) exit 1 and keep the old file; devices, FIFOs, sockets and folders as outputs are refused
# before any work; links to files keep the link; two outputs in one file, and what can be checked
# before rendering, are refused at once; write errors on standard output exit 1.
# tests/e2e/outputs/check-outputs runs each case (ulimit, mkfifo and sockets need a harness).
prizma_e2e_require(outputs.cmake TARGETS prizma-render prizma-relight prizma-metamer PYTHON)

set(_outputs_work ${PRIZMA_E2E_WORK}/outputs)
# The failing-system-call library of the io_faults case. Not in sanitizer builds: their runtime
# defines close() in the executable, which an LD_PRELOAD library cannot replace.
if(NOT PRIZMA_SANITIZE AND NOT PRIZMA_FUZZ)
  add_library(prizma_test_io_faults MODULE ${PRIZMA_E2E_DIR}/outputs/io_faults.cpp)
  target_link_libraries(prizma_test_io_faults PRIVATE ${CMAKE_DL_LIBS})
  prizma_set_warnings(prizma_test_io_faults)
endif()
set(_outputs_cmd ${PRIZMA_SYSTEM_PYTHON3} ${PRIZMA_E2E_DIR}/outputs/check-outputs
    --render $<TARGET_FILE:prizma-render> --relight $<TARGET_FILE:prizma-relight>
    --metamer $<TARGET_FILE:prizma-metamer> --scene ${PRIZMA_E2E_DIR}/render/tiny.json --work ${_outputs_work})
add_test(NAME outputs.e2e.fixture COMMAND ${_outputs_cmd} fixture)
set_tests_properties(outputs.e2e.fixture PROPERTIES FIXTURES_SETUP outputs_files LABELS outputs
                     ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}")
set(_outputs_cases fsize_relight fsize_render fsize_metamer special_outputs symlink_outputs same_file prework_render stdout)
if(TARGET prizma_test_io_faults)
  list(APPEND _outputs_cases io_faults)
  list(APPEND _outputs_cmd --io-faults $<TARGET_FILE:prizma_test_io_faults>)
endif()
foreach(case ${_outputs_cases})
  add_test(NAME outputs.e2e.${case} COMMAND ${_outputs_cmd} ${case})
  set_tests_properties(outputs.e2e.${case} PROPERTIES FIXTURES_REQUIRED outputs_files LABELS outputs TIMEOUT 300
                       ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}")
endforeach()
# The run's outputs as a whole (tests/e2e/outputs/check-run-outputs): outputs that are inputs, empty
# paths, a full disk part way (a real tmpfs: needs mount; skipped, exit 77, where it cannot mount).
list(TRANSFORM _outputs_cmd REPLACE "/check-outputs$" "/check-run-outputs" OUTPUT_VARIABLE _run_outputs_cmd)
foreach(case inputs empty_paths disk_full)
  add_test(NAME outputs.e2e.${case} COMMAND ${_run_outputs_cmd} ${case})
  set_tests_properties(outputs.e2e.${case} PROPERTIES FIXTURES_REQUIRED outputs_files LABELS outputs TIMEOUT 300
                       SKIP_RETURN_CODE 77 ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}")
endforeach()
