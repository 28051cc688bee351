# The docs' shell blocks run as written against an installed tree (ctest label docs): docs.install
# installs this build tree (cmake --install) and moves it to a scratch HOME's ~/.local; each page's
# ```sh blocks then run in an empty folder, and tests/e2e/docs/check_docs.py checks what the text
# says about the results (the images' colours, the ΔE00 of the designs). tests/e2e/docs/run-doc.
prizma_e2e_require(docs.cmake TARGETS prizma-render prizma-relight prizma-metamer PYTHON WARNING)
get_filename_component(_docs_dir ${PRIZMA_E2E_DIR}/../../docs ABSOLUTE)
set(_docs_work ${PRIZMA_E2E_WORK}/docs)
set(_docs_run ${PRIZMA_SYSTEM_PYTHON3} ${PRIZMA_E2E_DIR}/docs/run-doc)

add_test(NAME docs.install COMMAND ${_docs_run} install --build ${CMAKE_BINARY_DIR} --work ${_docs_work})
set_tests_properties(docs.install PROPERTIES FIXTURES_SETUP docs_installed LABELS docs TIMEOUT 120
                     RESOURCE_LOCK docs_work)
add_test(NAME docs.user-guide COMMAND ${_docs_run} run --doc ${_docs_dir}/user-guide.md --work ${_docs_work} --other-home)
add_test(NAME docs.metamerism COMMAND ${_docs_run} run --doc ${_docs_dir}/metamerism.md --work ${_docs_work} --data-link)
add_test(NAME docs.relight COMMAND ${_docs_run} run --doc ${_docs_dir}/relight.md --work ${_docs_work} --data-link)
set_tests_properties(docs.user-guide docs.metamerism docs.relight PROPERTIES FIXTURES_REQUIRED docs_installed
                     LABELS docs TIMEOUT 300)
# python.md's ```python blocks, as one session with the installed module (run-doc --python), where
# this tree builds the module: python/ is configured after tests/, so the test is added at the end of
# the configure (a deferred call in the top directory), when the module's target is known.
function(prizma_add_docs_python_test)
  if(TARGET prizma_python)
    add_test(NAME docs.python COMMAND ${ARGN})
    set_tests_properties(docs.python PROPERTIES FIXTURES_REQUIRED docs_installed LABELS "docs;python" TIMEOUT 300)
  endif()
endfunction()
cmake_language(EVAL CODE "cmake_language(DEFER DIRECTORY [[${PROJECT_SOURCE_DIR}]] CALL prizma_add_docs_python_test
  ${_docs_run} run --doc [[${_docs_dir}/python.md]] --work [[${_docs_work}]] --python)")
# Every sentence of the docs about how an image looks carries a colour claim (<!-- colour: … -->),
# checked against the image the page shows (docs/images); the run pages check theirs against what
# their blocks wrote (check_docs.py). tests/e2e/docs/colour_claims.py.
add_test(NAME docs.colour-claims
         COMMAND sh -c "\"$0\" \"$1\" lint \"$2\"/*.md \"$2\"/../README.md && \"$0\" \"$1\" check \"$2\""
                 ${PRIZMA_SYSTEM_PYTHON3} ${PRIZMA_E2E_DIR}/docs/colour_claims.py ${_docs_dir})
set_tests_properties(docs.colour-claims PROPERTIES LABELS docs TIMEOUT 120)
# scripts/install and scripts/demo themselves, bounded (tests/e2e/docs/run-scripts): this build tree
# is reused as it is configured (PRIZMA_REUSE_BUILD=1, no apt: PRIZMA_SKIP_SETUP=1), the demo renders
# 16×16 at 2 samples per pixel. They build in this tree (a no-op when it is built): one at a time.
get_filename_component(_docs_src ${PRIZMA_E2E_DIR}/../.. ABSOLUTE)
foreach(script install demo)
  add_test(NAME docs.scripts-${script}
           COMMAND ${PRIZMA_E2E_DIR}/docs/run-scripts ${script} ${_docs_src} ${CMAKE_BINARY_DIR} ${_docs_work}/scripts-${script})
  set_tests_properties(docs.scripts-${script} PROPERTIES LABELS docs TIMEOUT 300 RESOURCE_LOCK build_tree)
endforeach()

# The tools' --help examples, man pages and bash completion on the installed tree, through man and a
# real bash in tmux (tests/e2e/docs/check_help.py).
# (help2man is also looked for here: cmake/PrizmaToolDocs.cmake may be read after this file, and on a
# fresh configure the test would otherwise be registered as missing its tool.)
find_program(PRIZMA_HELP2MAN help2man)
find_program(PRIZMA_TMUX tmux)
find_program(PRIZMA_MAN man)
if(PRIZMA_HELP2MAN AND PRIZMA_TMUX AND PRIZMA_MAN)
  add_test(NAME docs.help COMMAND ${PRIZMA_SYSTEM_PYTHON3} ${PRIZMA_E2E_DIR}/docs/check_help.py
           ${_docs_work}/home/.local ${_docs_work}/help)
  set_tests_properties(docs.help PROPERTIES FIXTURES_REQUIRED docs_installed LABELS "docs;terminal" TIMEOUT 120
                       RESOURCE_LOCK docs_work)
else()
  prizma_missing_tool_test(docs.help "help2man, tmux and man (scripts/setup installs them)")
endif()
