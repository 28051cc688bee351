# prizma-relight compress and relighting from spectral-basis coefficients (docs/relight.md,
# "Compressed transport"): a file with coefficients beside the bins, a compact one, relit from them,
# and what is refused (one line, exit 2, nothing written). Needs relight.cmake's prizma_relight_e2e.
if(NOT COMMAND prizma_relight_e2e)
  return()
endif()

prizma_relight_e2e(compress "compress|colorchecker.exr|-o|cc_coef.exr" MUST_EXIST cc_coef.exr
  OUT_REGEX "key: k = [0-9]+ of 32 bins.*D65 [0-9.]+ / [0-9.]+.*gaussian:450:20|back: k = |wrote cc_coef\\.exr")
prizma_relight_e2e(compress_compact "compress|colorchecker.exr|-o|cc_compact.exr|--compact|--max-error|0.8" MUST_EXIST cc_compact.exr
  OUT_REGEX "wrote cc_compact\\.exr \\(compact: coefficients only")
set_tests_properties(relight.e2e.compress relight.e2e.compress_compact PROPERTIES FIXTURES_SETUP relight_compressed_files)

function(prizma_compressed_e2e name args)
  prizma_relight_e2e(${name} "${args}" ${ARGN})
  set_tests_properties(relight.e2e.${name} PROPERTIES FIXTURES_REQUIRED "relight_files;relight_compressed_files")
endfunction()
prizma_compressed_e2e(coef_png "cc_coef.exr|--light|key=A|-v|-o|cc_coef.png" MUST_EXIST cc_coef.png
  STDERR_MATCH "relighting from spectral-basis coefficients \\(key k = [0-9]+, back k = [0-9]+; --exact uses the bins\\)")
prizma_compressed_e2e(coef_exact "cc_coef.exr|--exact|-v|-o|cc_exact.png" MUST_EXIST cc_exact.png)
prizma_compressed_e2e(compact_png "cc_compact.exr|--light|key=F11|-v|-o|cc_compact.png" MUST_EXIST cc_compact.png
  STDERR_MATCH "compact file, no bins")
prizma_compressed_e2e(compact_interactive "cc_compact.exr|-i" STDIN ${PRIZMA_E2E_DIR}/relight/session.txt
  OUT_REGEX "probe 2 3|bins key: [0-9.-]+ ")
# Refused, one line, exit 2, nothing written.
prizma_compressed_e2e(compact_exact "cc_compact.exr|--exact|-o|err_compact_exact.png" EXPECT_RC 2
  ERR_REGEX "cc_compact\\.exr: compact file: .*cannot be relit exactly" MUST_NOT_EXIST err_compact_exact.png)
# The live page relights a compact file from its coefficients (relight.live.browser); --exact cannot.
prizma_compressed_e2e(compact_serve_exact "cc_compact.exr|--serve|--exact" EXPECT_RC 2
  ERR_REGEX "cc_compact\\.exr: compact file: .*cannot be relit exactly")
prizma_compressed_e2e(compress_compact_input "compress|cc_compact.exr|-o|err_again.exr" EXPECT_RC 2
  ERR_REGEX "cc_compact\\.exr: is a compact file .*compress the file it was made from" MUST_NOT_EXIST err_again.exr)
prizma_compressed_e2e(compress_bad_bound "compress|scene.exr|-o|err_bound.exr|--max-error|0" EXPECT_RC 2
  ERR_REGEX "--max-error: must be a positive" MUST_NOT_EXIST err_bound.exr)
prizma_compressed_e2e(compress_missing "compress|nowhere.exr|-o|err_missing.exr" EXPECT_RC 2
  ERR_REGEX "nowhere\\.exr" MUST_NOT_EXIST err_missing.exr)
prizma_compressed_e2e(compress_no_folder "compress|scene.exr|-o|no_such_folder/x.exr" EXPECT_RC 2 ERR_REGEX "no_such_folder")
prizma_compressed_e2e(compress_not_exr "compress|scene.exr|-o|err_png.png" EXPECT_RC 2 ERR_REGEX "\\.exr" MUST_NOT_EXIST err_png.png)
prizma_compressed_e2e(compress_onto_input "compress|scene.exr|-o|./scene.exr" EXPECT_RC 2 ERR_REGEX "would replace \"scene.exr\", the OpenEXR file this run reads")
prizma_compressed_e2e(compress_help "compress|--help" OUT_REGEX "--compact|--max-error")
