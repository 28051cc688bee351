# One vocabulary across the tools (issue 15 part 4): -q, -v, --threads everywhere; -D KEY=VALUE on
# prizma-render; --ocio, --color-space, JPEG output and refused unused options on prizma-relight;
# both spellings in the files; prizma-metamer's global options after the subcommand. Uses the
# helpers and fixtures of render.cmake and relight.cmake (included before this file).
if(NOT TARGET prizma-render OR NOT TARGET prizma-relight OR NOT TARGET prizma-metamer)
  return()
endif()

# prizma-render -D: overrides typed by the field, checked like the file, errors naming the key.
set(_tiny ${PRIZMA_E2E_DIR}/render/tiny.json)
prizma_render_e2e(define "${_tiny}|-D|camera.width=5|-Dcamera.height=3|-D|lights.side.spectrum=A|-D|seed=7|-D|bins=linear:400:700:3|-v|--threads|1|-o|define.exr"
  MUST_EXIST define.exr ERR_REGEX "5×3, 3 bins linear:400:700:3, samples 0:4, seed 7.*light side: .*default spectrum A")
prizma_render_e2e(define_index "${_tiny}|-D|lights[1].spectrum=D50|-D|materials.core.albedo=0.5|-v|-o|define_index.exr"
  MUST_EXIST define_index.exr ERR_REGEX "light sky: .*default spectrum D50")
prizma_render_e2e(define_normalization "${_tiny}|-D|normalization={\"min\": 0, \"max\": 255}|-q|-o|define_norm.exr"
  MUST_EXIST define_norm.exr)
# A refused -D: exit 2, one error line matching REGEX, no bad.exr.
function(prizma_define_refused name args regex)
  prizma_render_e2e(${name} "${_tiny}|${args}|-o|bad.exr" EXPECT_RC 2 MUST_NOT_EXIST bad.exr ERR_LINES 1
                    ERR_REGEX "${regex}" ${ARGN})
endfunction()
prizma_define_refused(define_both_spellings "-D|normalization=\"auto\"|-D|normalisation=\"auto\""
  "error: -D normalization: give normalisation or normalization")
prizma_define_refused(define_range "-D|camera.ortho_height=-1"
  "prizma-render: error: -D camera.ortho_height: must be > 0 \\(got -1\\)")
prizma_define_refused(define_type "-D|camera.width=wide" "error: -D camera.width: must be an integer \\(got string \"wide\"\\)")
prizma_define_refused(define_unknown "-D|camera.fovdeg=30" "error: -D camera.fovdeg: unknown field \\(known: type, position")
prizma_define_refused(define_no_light "-D|lights.fill.spectrum=A"
  "error: -D lights.fill.spectrum: lights has no element named \"fill\" \\(2 elements: side, sky\\)")
prizma_define_refused(define_no_value "-D|camera.width" "error: -D camera.width: expected KEY=VALUE")
prizma_define_refused(define_twice "-D|seed=1|-D|seed=2" "error: -D seed: is given twice")
prizma_define_refused(define_resume "--resume|shard0.exr|-D|seed=1" "error: -D: not with --resume"
  FIXTURES_REQUIRED render_shards)
prizma_render_e2e(merge_vocabulary "merge|shard0.exr|shard1.exr|-o|merged_v.exr|-v|--threads|1"
  MUST_EXIST merged_v.exr ERR_REGEX "shard shard0.exr: samples 0:2" FIXTURES_REQUIRED render_shards)

# prizma-relight: JPEG, --ocio, both spellings, -q/-v/--threads, options that nothing would use.
prizma_relight_e2e(jpeg "scene.exr|--light|key=A|-q|--threads|1|-o|single.jpg" MUST_EXIST single.jpg)
prizma_relight_e2e(err_jpeg_16bit "scene.exr|--bit-depth|16|-o|err11.jpg" EXPECT_RC 2
  ERR_REGEX "--bit-depth: JPEG is 8-bit only" MUST_NOT_EXIST err11.jpg)
prizma_relight_e2e(color_space_spelling "scene.exr|--color-space|ACEScg|-o|acescg.exr" MUST_EXIST acescg.exr)
prizma_relight_e2e(ocio "scene.exr|--ocio|${PRIZMA_SOURCE_DATA_DIR}/ocio/config.ocio|-v|-o|ocio.png" MUST_EXIST ocio.png
  STDERR_MATCH "OCIO config ${PRIZMA_SOURCE_DATA_DIR}/ocio/config.ocio")
# --ocio with every kind of output that goes through OpenColorIO; refused where nothing would use it.
prizma_relight_e2e(ocio_tiff "scene.exr|--ocio|${PRIZMA_SOURCE_DATA_DIR}/ocio/config.ocio|--display|Display P3|-o|ocio.tif"
  MUST_EXIST ocio.tif)
prizma_relight_e2e(ocio_jpeg "scene.exr|--ocio|${PRIZMA_SOURCE_DATA_DIR}/ocio/config.ocio|-o|ocio.jpg" MUST_EXIST ocio.jpg)
prizma_relight_e2e(ocio_exr_colour_space "scene.exr|--ocio|${PRIZMA_SOURCE_DATA_DIR}/ocio/config.ocio|--colour-space|ACEScg|-o|ocio_cs.exr"
  MUST_EXIST ocio_cs.exr)
prizma_relight_e2e(err_ocio_xyz_exr "scene.exr|--ocio|${PRIZMA_SOURCE_DATA_DIR}/ocio/config.ocio|-o|err15.exr" EXPECT_RC 2
  ERR_REGEX "--ocio: an XYZ EXR output is written as it is" MUST_NOT_EXIST err15.exr)
prizma_render_e2e(err_ocio "${_tiny}|--ocio|${PRIZMA_SOURCE_DATA_DIR}/ocio/config.ocio|-o|bad.exr" EXPECT_RC 2
  MUST_NOT_EXIST bad.exr ERR_LINES 1 ERR_REGEX "^prizma-render: error: --ocio: prizma-render takes no OpenColorIO config")
prizma_relight_e2e(err_ocio_missing "scene.exr|--ocio|nowhere.ocio|-o|err12.png" EXPECT_RC 2
  ERR_REGEX "nowhere\\.ocio" MUST_NOT_EXIST err12.png)
prizma_relight_e2e(err_display_exr "scene.exr|--display|Display P3|-o|err13.exr" EXPECT_RC 2
  ERR_REGEX "--display: an EXR output is linear" MUST_NOT_EXIST err13.exr)
prizma_relight_e2e(err_colour_space_png "scene.exr|--colour-space|ACEScg|-o|err14.png" EXPECT_RC 2
  ERR_REGEX "--colour-space: applies to EXR outputs only" MUST_NOT_EXIST err14.png)
prizma_relight_e2e(verbose_short "scene.exr|-v|-o|verbose.png" MUST_EXIST verbose.png STDERR_MATCH "prizma-relight: input scene.exr")
add_test(NAME relight.e2e.batch_color_space
         COMMAND sh -c "printf '{\"outputs\": [{\"file\": \"batch_us.exr\", \"colorSpace\": \"ACEScg\"}]}' > batch_us.json && \"$0\" scene.exr --batch batch_us.json && test -s batch_us.exr"
                 $<TARGET_FILE:prizma-relight>)
set_tests_properties(relight.e2e.batch_color_space PROPERTIES WORKING_DIRECTORY ${PRIZMA_E2E_WORK}/relight
                     FIXTURES_REQUIRED relight_files RESOURCE_LOCK relight_e2e_work
                     ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}")

# prizma-metamer: global options after the subcommand, -q, -v, --threads.
set(_metamer_env "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}")
add_test(NAME metamer.cli.options_after_subcommand
         COMMAND sh -c "\"$0\" weights --light D65 --bins linear:380:780:16 --cmf 1964 -o \"$1\" && test $(wc -l < \"$1\") -eq 17"
                 $<TARGET_FILE:prizma-metamer> ${PRIZMA_METAMER_WORK}/weights_after.csv)
add_test(NAME metamer.cli.quiet
         COMMAND sh -c "out=$(\"$0\" metamer --albedo cc:4 --match-light D65 --split-light F11 -o \"$1\" -q --threads 1) && test -z \"$out\" && test -s \"$1\""
                 $<TARGET_FILE:prizma-metamer> ${PRIZMA_METAMER_WORK}/metamer_quiet.csv)
add_test(NAME metamer.cli.verbose
         COMMAND sh -c "\"$0\" weights --light A -o \"$1\" -v --cmf 2012-2 --bins linear:380:780:8 2>&1 >/dev/null | grep -q 'observer cie2012-2, bins linear:380:780:8'"
                 $<TARGET_FILE:prizma-metamer> ${PRIZMA_METAMER_WORK}/tab_verbose.csv)
set_tests_properties(metamer.cli.options_after_subcommand metamer.cli.quiet metamer.cli.verbose PROPERTIES
                     LABELS e2e ENVIRONMENT "${_metamer_env}")
