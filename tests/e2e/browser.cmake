# prizma-relight --serve: the HTTP server through plain sockets (label "serve"), and the live page in
# headless Chromium against prizma-relight -o and against pages of other origins (label "browser";
# skipped, exit 77, when chromium, chromium-driver or python3-selenium are missing, failed then with
# CI=true: tests/missing-tool). Driver: browser/live_page_test.py. The page's state handling
# (relight/serve/web/state.js) under node's test runner (Debian's nodejs): relight.live.page_state.
if(NOT TARGET prizma-relight)
  return()
endif()

add_executable(prizma_live_page_fixture ${PRIZMA_E2E_DIR}/browser/make_fixture.cpp)
target_link_libraries(prizma_live_page_fixture PRIVATE prizma::spectral)
prizma_set_warnings(prizma_live_page_fixture)

set(_live_work ${PRIZMA_E2E_WORK}/live_page)
add_test(NAME relight.live.fixture COMMAND prizma_live_page_fixture ${_live_work})
set_tests_properties(relight.live.fixture PROPERTIES FIXTURES_SETUP live_page_files)

set(_live_mri "")
set(_live_fixtures live_page_files)
if(PRIZMA_E2E_MRI_EXR)
  set(_live_mri --mri ${PRIZMA_E2E_MRI_EXR})
  list(APPEND _live_fixtures mri_render)
endif()
# The fluorescent render of tests/e2e/fluorescence.cmake (16×16, bispectral channels), when registered.
if(TARGET prizma-render)
  list(APPEND _live_mri --fluor ${PRIZMA_E2E_WORK}/fluorescence/dye.exr)
  list(APPEND _live_fixtures fluorescence_merged)
  # A denoised render (tests/e2e/denoise.cmake): its title says so.
  list(APPEND _live_mri --denoised ${PRIZMA_E2E_WORK}/denoise/clean.exr)
  list(APPEND _live_fixtures denoise_raw denoise_clean)
endif()
foreach(mode server browser)
  add_test(NAME relight.live.${mode}
           COMMAND /usr/bin/python3 ${PRIZMA_E2E_DIR}/browser/live_page_test.py ${mode}
                   $<TARGET_FILE:prizma-relight> ${_live_work} ${_live_mri})
  set_tests_properties(relight.live.${mode} PROPERTIES FIXTURES_REQUIRED "${_live_fixtures}"
                       ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}" RESOURCE_LOCK live_page_work
                       TIMEOUT 300 SKIP_RETURN_CODE 77)
endforeach()
set_tests_properties(relight.live.server PROPERTIES LABELS serve)
set_tests_properties(relight.live.browser PROPERTIES LABELS browser)

find_program(PRIZMA_NODE NAMES node nodejs)
if(PRIZMA_NODE)
  add_test(NAME relight.live.page_state COMMAND ${PRIZMA_NODE} --test ${PRIZMA_E2E_DIR}/browser/state_test.js)
else()
  prizma_missing_tool_test(relight.live.page_state "node (apt-get install nodejs)")
endif()
set_tests_properties(relight.live.page_state PROPERTIES LABELS browser)
