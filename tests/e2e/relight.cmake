# End-to-end tests of prizma-relight: single images, batch, an interactive session through a pipe,
# and bad input (one-line error, exit 2, no output left behind, existing outputs untouched).
if(NOT TARGET prizma-relight)
  return()
endif()

add_executable(prizma_relight_make_fixture ${PRIZMA_E2E_DIR}/relight/make_fixture.cpp
               ${PROJECT_SOURCE_DIR}/relight/examples/colorchecker_chart.cpp)
target_include_directories(prizma_relight_make_fixture PRIVATE ${PROJECT_SOURCE_DIR}/relight/examples)
target_link_libraries(prizma_relight_make_fixture PRIVATE prizma::spectral PkgConfig::OIIO)
prizma_set_warnings(prizma_relight_make_fixture)

set(_relight_work ${PRIZMA_E2E_WORK}/relight)
add_test(NAME relight.e2e.fixture COMMAND prizma_relight_make_fixture ${_relight_work})
set_tests_properties(relight.e2e.fixture PROPERTIES FIXTURES_SETUP relight_files)

# prizma_relight_e2e(NAME ARGS <a|b|c> [key value]...): one run_and_check.cmake invocation.
function(prizma_relight_e2e name args)
  set(defs -DEXE=$<TARGET_FILE:prizma-relight> "-DARGS=${args}" -DWORKDIR=${_relight_work})
  set(extra ${ARGN})
  while(extra)
    list(POP_FRONT extra key value)
    list(APPEND defs "-D${key}=${value}")
  endwhile()
  add_test(NAME relight.e2e.${name}
           COMMAND ${CMAKE_COMMAND} ${defs} -P ${PRIZMA_E2E_DIR}/relight/run_and_check.cmake)
  set_tests_properties(relight.e2e.${name} PROPERTIES FIXTURES_REQUIRED relight_files
                       ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}" RESOURCE_LOCK relight_e2e_work)
endfunction()

# Working runs.
prizma_relight_e2e(help "--help" OUT_REGEX "--light|--batch|--interactive")
prizma_relight_e2e(png "scene.exr|--light|key=D65|--light|back=off|--exposure|0|-o|single.png" MUST_EXIST single.png)
prizma_relight_e2e(png16_adapt "scene.exr|--light|A|--adapt|--bit-depth|16|-o|single16.png" MUST_EXIST single16.png)
prizma_relight_e2e(tiff "scene.exr|--cmf|2012-10|-o|single.tif" MUST_EXIST single.tif)
prizma_relight_e2e(exr_xyz "scene.exr|--light|back=gaussian:550:5*2|-o|single.exr" MUST_EXIST single.exr)
prizma_relight_e2e(show "scene.exr|--show" OUT_REGEX "▀")
# One value per --light: a file after it is the input, not a second spectrum (issue 15).
prizma_relight_e2e(light_before_input "--light|D65|scene.exr|-o|light_first.png" MUST_EXIST light_first.png)
# The 2012 observers on the default 380–780 nm bins (their table starts at 390 nm): zero below it.
prizma_relight_e2e(cmf2012_below_table "colorchecker.exr|--cmf|2012-2|--verbose|-o|cmf2012.png" MUST_EXIST cmf2012.png
  STDERR_MATCH "note: bins .* reach outside the cie2012-2 colour matching table \\(390–830 nm\\)")
# A reflective file from the JCGT reference writer sampled every 100 nm from 400 nm: its inferred
# first edge (350 nm) is clamped to the tables and -v says so (issue 25 item 13).
prizma_relight_e2e(reference_writer_file "reference400.exr|--verbose|-o|reference400.png" MUST_EXIST reference400.png
  STDERR_MATCH "note: .*reference400\\.exr: the inferred first bin edge 350 nm is outside the colour matching tables \\(360–830 nm\\): clamped to 360 nm")
prizma_relight_e2e(batch "scene.exr|--batch|batch.json" MUST_EXIST "batch_d65.png|batch_a16.png|batch_xyz.exr")
prizma_relight_e2e(interactive "scene.exr|-i|--preview|session_preview.png"
  STDIN ${PRIZMA_E2E_DIR}/relight/session.txt
  MUST_EXIST "session_preview.png|session_final.png|session_final.exr"
  OUT_REGEX "key: D65|back: A|probe 2 3|XYZ [0-9.]+ 0\\.500000 |dE2000 0\\.000000|dE2000 [1-9]|no light \"fill\" in scene\\.exr \\(its lights: key, back\\)|error: light key:.*D66|XYZ [0-9.]+ 1\\.000000 |relit in [0-9.]+ ms")

# Bad input: one line on stderr, exit 2, nothing written.
prizma_relight_e2e(err_missing_file "nowhere.exr|-o|err1.png" EXPECT_RC 2 ERR_REGEX "nowhere\\.exr" MUST_NOT_EXIST err1.png)
prizma_relight_e2e(err_not_exr "fake.exr|-o|err2.png" EXPECT_RC 2 ERR_REGEX "fake\\.exr" MUST_NOT_EXIST err2.png)
prizma_relight_e2e(err_no_spectral_layers "rgb.exr|-o|err3.png" EXPECT_RC 2 ERR_REGEX "rgb\\.exr" MUST_NOT_EXIST err3.png)
prizma_relight_e2e(err_unknown_light "scene.exr|--light|fill=D65|-o|err4.png" EXPECT_RC 2
  ERR_REGEX "--light: no light \"fill\" in scene\\.exr \\(its lights: key, back\\)" MUST_NOT_EXIST err4.png)
prizma_relight_e2e(err_bad_spec "scene.exr|--light|key=D66|-o|err5.png" EXPECT_RC 2 ERR_REGEX "D66" MUST_NOT_EXIST err5.png)
prizma_relight_e2e(err_bad_scale "scene.exr|--light|key=D65*-2|-o|err6.png" EXPECT_RC 2 ERR_REGEX "scale" MUST_NOT_EXIST err6.png)
prizma_relight_e2e(err_unwritable "scene.exr|-o|no/such/folder/out.png" EXPECT_RC 2 ERR_REGEX "--output: folder \"no/such/folder\"")
prizma_relight_e2e(err_unknown_format "scene.exr|-o|err7.bmp" EXPECT_RC 2 ERR_REGEX "unknown output format" MUST_NOT_EXIST err7.bmp)
prizma_relight_e2e(err_bad_cmf "scene.exr|--cmf|1955|-o|err8.png" EXPECT_RC 2 ERR_REGEX "--cmf" MUST_NOT_EXIST err8.png)
prizma_relight_e2e(err_bad_display "scene.exr|--display|NoSuchDisplay|-o|err9.png" EXPECT_RC 2 ERR_REGEX "NoSuchDisplay" MUST_NOT_EXIST err9.png)
# The live page's options without --serve (errors.md, "Options that nothing would use").
foreach(opt --bind|127.0.0.1 --port|8123 --save-dir|.)
  string(REGEX REPLACE "\\|.*" "" _name "${opt}")
  string(REPLACE "--" "" _short "${_name}")
  string(REPLACE "-" "_" _short "${_short}")
  prizma_relight_e2e(err_${_short}_needs_serve "scene.exr|${opt}|-o|serve_${_short}.png" EXPECT_RC 2
    ERR_REGEX "^prizma-relight: error: ${_name}: only with --serve" MUST_NOT_EXIST serve_${_short}.png)
endforeach()
prizma_relight_e2e(err_existing_output_survives "scene.exr|--light|key=nope|-o|existing.png" EXPECT_RC 2
  ERR_REGEX "nope" KEEP_FILE existing.png KEEP_CONTENT "keep me")
prizma_relight_e2e(err_light_twice "scene.exr|--light|key=D65|--light|key=A|-o|err10.png" EXPECT_RC 2
  ERR_REGEX "--light: light \"key\" is given twice" MUST_NOT_EXIST err10.png)
prizma_relight_e2e(err_bad_batch "scene.exr|--batch|fake.exr" EXPECT_RC 2 ERR_REGEX "fake\\.exr: not valid JSON")
