# Bad input files through the executables (docs/errors.md): truncated and mis-sized volumes, corrupt
# NIfTI, broken scenes, bad spectra, bad spectral EXR files. Each test checks, with
# tests/e2e/errors/check-error, the exit code, a single stderr line "<prog>: error: <input>: <reason>"
# naming the bad file, no output file (and no temporary) left behind, or an existing output untouched.
# The bad files are written at test time by tests/e2e/errors/make-fixtures (fixture errors_files).
set(_errors_work ${PRIZMA_E2E_WORK}/errors)
set(_errors_dir ${PRIZMA_E2E_DIR}/errors)
prizma_e2e_require(errors.cmake PYTHON)

add_test(NAME errors.e2e.fixtures COMMAND ${PRIZMA_SYSTEM_PYTHON3} ${_errors_dir}/make-fixtures ${_errors_work})
set_tests_properties(errors.e2e.fixtures PROPERTIES FIXTURES_SETUP errors_files LABELS errors)

# prizma_error_e2e(NAME TOOL RC INPUT_REGEX REASON_REGEX OUTPUT [EXISTING] ARGS...)
function(prizma_error_e2e name tool rc input reason output)
  set(args ${ARGN})
  set(existing "")
  list(GET args 0 first)
  if(first STREQUAL "EXISTING")
    set(existing --existing)
    list(REMOVE_AT args 0)
  endif()
  add_test(NAME errors.e2e.${name}
           COMMAND ${PRIZMA_SYSTEM_PYTHON3} ${_errors_dir}/check-error --workdir ${_errors_work} --rc ${rc}
                   --input ${input} --reason ${reason} --output ${output} ${existing} -- $<TARGET_FILE:${tool}> ${args})
  set_tests_properties(errors.e2e.${name} PROPERTIES FIXTURES_REQUIRED errors_files LABELS errors
                       ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}")
endfunction()

if(TARGET prizma-render)
  # prizma_render_error(NAME SCENE INPUT_REGEX REASON_REGEX [EXISTING]): render SCENE -o <NAME>.exr, expect exit 2.
  function(prizma_render_error name scene input reason)
    prizma_error_e2e(render_${name} prizma-render 2 "${input}" "${reason}" render_${name}.exr ${ARGN}
                     ${scene} -o render_${name}.exr)
  endfunction()
  # Raw volumes.
  prizma_render_error(raw_truncated raw_truncated.json "trunc_4x4x4_uint8\\.raw" "size|truncated")
  prizma_render_error(raw_size_mismatch raw_size_mismatch.json "block_4x4x4_uint8\\.raw" "size")
  prizma_render_error(raw_unparsable_name raw_unparsable_name.json "noname\\.raw" "name")
  prizma_render_error(raw_too_large raw_too_large.json "block_4x4x4_uint8\\.raw" "too large")
  prizma_render_error(raw_missing raw_missing.json "no_such_volume_8x8x8_uint8\\.raw" "(?i)no such file")
  prizma_render_error(raw_existing_output raw_truncated.json "trunc_4x4x4_uint8\\.raw" "size|truncated" EXISTING)
  # NIfTI.
  prizma_render_error(nifti_truncated_gz nifti_truncated_nii_gz.json "truncated\\.nii\\.gz" ".")
  prizma_render_error(nifti_corrupt_gz nifti_corrupt_nii_gz.json "corrupt\\.nii\\.gz" ".")
  prizma_render_error(nifti_complex nifti_complex_nii.json "complex\\.nii" "unsupported|COMPLEX")
  prizma_render_error(nifti_rgb nifti_rgb_nii.json "rgb\\.nii" "unsupported|RGB")
  prizma_render_error(nifti_short nifti_short_nii.json "short\\.nii" "truncated|corrupt|read")
  prizma_render_error(nifti_existing_output nifti_corrupt_nii_gz.json "corrupt\\.nii\\.gz" "." EXISTING)
  # Scene files.
  prizma_render_error(scene_malformed scene_malformed.json "scene_malformed\\.json" "JSON|parse|syntax")
  prizma_render_error(scene_unknown_field scene_unknown_field.json "scene_unknown_field\\.json.*albdo" "unknown")
  prizma_render_error(scene_unknown_top_field scene_unknown_top_field.json "scene_unknown_top_field\\.json.*sampels" "unknown")
  prizma_render_error(scene_wrong_type scene_wrong_type.json "scene_wrong_type\\.json.*samples" "must be|integer|number")
  prizma_render_error(scene_wrong_type_camera scene_wrong_type_camera.json "scene_wrong_type_camera\\.json.*camera" "object")
  prizma_render_error(scene_albedo_above_one scene_albedo_above_one.json "scene_albedo_above_one\\.json.*albedo" "1")
  prizma_render_error(scene_anisotropy_one scene_anisotropy_one.json "scene_anisotropy_one\\.json.*anisotropy" "1")
  prizma_render_error(scene_negative_extinction scene_negative_extinction.json "scene_negative_extinction\\.json.*extinction" "0|negative")
  prizma_render_error(scene_zero_width scene_zero_width.json "scene_zero_width\\.json.*width" "0|positive")
  prizma_render_error(scene_unknown_spectrum scene_unknown_spectrum.json "scene_unknown_spectrum\\.json.*albedo" "D66")
  prizma_render_error(scene_no_lights scene_no_lights.json "scene_no_lights\\.json.*lights" "light|empty")
  prizma_render_error(scene_bins_outside_cmf scene_bins_outside_cmf.json "scene_bins_outside_cmf\\.json.*bins" "360|830")
  # Point, spot and environment-map lights.
  prizma_render_error(light_radius_negative light_radius_negative.json "light_radius_negative\\.json: lights\\[0\\]\\.radius" "must be in \\[0,")
  prizma_render_error(light_position_short light_position_short.json "light_position_short\\.json: lights\\[0\\]\\.position" "3 numbers")
  prizma_render_error(light_spot_falloff light_spot_falloff.json "light_spot_falloff\\.json: lights\\[0\\]\\.spot\\.falloff_deg" "cone_deg")
  prizma_render_error(light_spot_cone light_spot_cone.json "light_spot_cone\\.json: lights\\[0\\]\\.spot\\.cone_deg" "\\(0, 180\\]")
  prizma_render_error(light_spot_type light_spot_type.json "light_spot_type\\.json: lights\\[0\\]\\.spot" "must be an object")
  prizma_render_error(light_direction_and_position light_direction_and_position.json
                      "light_direction_and_position\\.json: lights\\[0\\]\\.direction" "one of direction, position and environment")
  prizma_render_error(light_rotation_range light_rotation_range.json "light_rotation_range\\.json: lights\\[0\\]\\.rotation_deg" "-360, 360")
  prizma_render_error(light_sky_negative light_sky_negative.json "light_sky_negative\\.json: lights\\[0\\]\\.environment" "sky_negative\\.exr.*pixel \\(5, 2\\) channel R = -1")
  prizma_render_error(light_sky_inf light_sky_inf.json "light_sky_inf\\.json: lights\\[0\\]\\.environment" "sky_inf\\.exr.*pixel \\(3, 1\\) channel B = inf")
  prizma_render_error(light_sky_black light_sky_black.json "light_sky_black\\.json: lights\\[0\\]\\.environment" "sky_black\\.exr.*every pixel is 0")
  prizma_render_error(light_sky_text light_sky_text.json "light_sky_text\\.json: lights\\[0\\]\\.environment" "cannot read image .*sky_text\\.exr")
  prizma_render_error(light_sky_missing light_sky_missing.json "light_sky_missing\\.json: lights\\[0\\]\\.environment" "sky_missing\\.exr")
  prizma_render_error(light_sky_existing_output light_sky_negative.json "light_sky_negative\\.json: lights\\[0\\]\\.environment" "negative|≥ 0" EXISTING)
  prizma_render_error(scene_existing_output scene_unknown_field.json "scene_unknown_field\\.json" "unknown" EXISTING)
  # Spectra (CSV files named by the scene).
  prizma_render_error(spectrum_unsorted spectrum_unsorted.json "unsorted\\.csv" "increasing|sorted|order")
  prizma_render_error(spectrum_nan spectrum_nan.json "nan\\.csv" "nan|NaN|finite|number")
  prizma_render_error(spectrum_negative spectrum_negative.json "spectrum_negative\\.json.*albedo|negative\\.csv" "-0\\.2|negative|\\[0, 1\\]")
  # Inputs that are not regular files (they blocked forever), deep JSON (crashed), and what a
  # scene path really is (issue 11).
  prizma_render_error(scene_fifo scene_fifo.json "scene_fifo\\.json" "FIFO")
  prizma_render_error(scene_dir scene_dir.json "scene_dir\\.json" "is a folder")
  prizma_render_error(scene_loop scene_loop_a.json "scene_loop_a\\.json" "symbolic link loop")
  prizma_render_error(scene_deep scene_deep.json "scene_deep\\.json" "nested deeper than 128 levels")
  prizma_render_error(spectrum_fifo spectrum_fifo.json "fifo\\.csv" "FIFO")
  prizma_render_error(raw_fifo raw_fifo.json "fifo_4x4x4_uint8\\.raw" "FIFO")
  prizma_render_error(tf_dev_zero tf_dev_zero.json "transfer_function\\.image" "/dev/zero: is a character device")
  # Extinction beyond what the tracker steps through (the render never ended), a PNG claiming more
  # pixels than it holds (1.2 GB before it was refused), a truncated PNG (four lines).
  prizma_render_error(scene_extinction_huge scene_extinction_huge.json "materials\\[0\\]\\.extinction" "extinction × density reaches 1e\\+39")
  prizma_render_error(scene_density_huge scene_density_huge.json "materials\\[0\\]\\.extinction" "reaches 5000000 per unit length")
  # Light that overflowed into no light: emission 3e38 (NaN, counted as 0), a default spectrum D65*1e39.
  prizma_render_error(scene_emission_huge scene_emission_huge.json "materials\\[0\\]\\.emission" "must be at most 1000000 at every wavelength \\(got 3e\\+38\\)")
  prizma_render_error(scene_light_scale_huge scene_light_scale_huge.json "lights\\[0\\]\\.spectrum" "light scale 1e\\+39 in \"D65\\*1e39\" is above 1e\\+12")
  prizma_render_error(tf_huge_png tf_huge_png.json "transfer_function\\.image" "8192×8192")
  prizma_render_error(tf_truncated_png tf_truncated_png.json "transfer_function\\.image" "cannot read image")
  # A TIFF, JPEG or EXR cut in half (the TIFF and the JPEG rendered, their missing rows read as 0).
  foreach(_ext tif jpg exr)
    prizma_render_error(tf_truncated_${_ext} tf_truncated_${_ext}.json "transfer_function\\.image"
                        "cannot read image tf_truncated\\.${_ext}: ")
    prizma_render_error(light_sky_truncated_${_ext} light_sky_truncated_${_ext}.json "lights\\[0\\]\\.environment"
                        "cannot read image sky_truncated\\.${_ext}: ")
  endforeach()
  # NIfTI headers the format refuses (they were read as pixdim 1, unchecked, shifted).
  prizma_render_error(nifti_pixdim_zero nifti_pixdim_zero_nii.json "pixdim_zero\\.nii" "pixdim\\[2\\]")
  prizma_render_error(nifti_vox_offset nifti_vox_offset_negative_nii.json "vox_offset_negative\\.nii" "vox_offset")
  prizma_render_error(nifti_no_trailer nifti_no_trailer_nii_gz.json "no_trailer\\.nii\\.gz" "gzip")
  # Command-line values obey exactly the scene's ranges.
  prizma_error_e2e(render_cli_width prizma-render 2 "^(--width)" "must be in \\[1, 16384\\] \\(got 20000\\)" render_cli_width.exr
                   good.json --width 20000 -o render_cli_width.exr)
  prizma_error_e2e(render_cli_width_float prizma-render 2 "^(--width)" "must be an integer" render_cli_width_float.exr
                   good.json --width 1e9 -o render_cli_width_float.exr)
  prizma_error_e2e(render_cli_seed prizma-render 2 "^(--seed)" "must be an integer ≥ 0" render_cli_seed.exr
                   good.json --seed -1 -o render_cli_seed.exr)
  prizma_error_e2e(render_cli_spp prizma-render 2 "^(--spp)" "must be in \\[1, " render_cli_spp.exr
                   good.json --spp 0 -o render_cli_spp.exr)
  # A spectrum outside the bins is zero there by definition (spectrum.h), so a material or a light's
  # default spectrum that misses the bins is valid for the renderer; prizma-relight refuses a light
  # with no energy inside the bins (below).
  # Damaged OpenVDB files (issue 21): a valid cloud from prizma-make-cloud-vdb cut short or with one
  # byte changed (a size that then asks for terabytes was "out of memory", exit 1), and a real level
  # set (taken as density before). Written by make-vdb-fixtures (fixture errors_vdb_files).
  if(TARGET prizma-make-cloud-vdb)
    add_executable(prizma_test_make_level_set_vdb ${_errors_dir}/make_level_set_vdb.cpp)
    target_link_libraries(prizma_test_make_level_set_vdb PRIVATE prizma_openvdb)
    prizma_set_warnings(prizma_test_make_level_set_vdb)
    prizma_sanitizer_ignorelist(${_errors_dir}/make_level_set_vdb.cpp)  # OpenVDB's trees: see vdb/CMakeLists.txt
    add_test(NAME errors.e2e.vdb_fixtures
             COMMAND ${PRIZMA_SYSTEM_PYTHON3} ${_errors_dir}/make-vdb-fixtures ${_errors_work}
                     $<TARGET_FILE:prizma-make-cloud-vdb> $<TARGET_FILE:prizma_test_make_level_set_vdb>)
    set_tests_properties(errors.e2e.vdb_fixtures PROPERTIES FIXTURES_SETUP errors_vdb_files LABELS errors)
    function(prizma_vdb_error name input reason)
      prizma_render_error(${name} ${name}.json "${input}" "${reason}")
      set_tests_properties(errors.e2e.render_${name} PROPERTIES FIXTURES_REQUIRED "errors_files;errors_vdb_files")
    endfunction()
    prizma_vdb_error(vdb_truncated "vdb_truncated\\.vdb"
                     "not a readable OpenVDB file \\(cut short: grid \"density\" ends at byte 42125, the file at byte 21062\\)")
    prizma_vdb_error(vdb_truncated_header "vdb_truncated_header\\.vdb"
                     "not a readable OpenVDB file \\(cut short: the file ends at byte 40, inside its header or a grid's descriptor\\)")
    if(NOT PRIZMA_SANITIZE AND NOT PRIZMA_FUZZ)  # AddressSanitizer aborts on the size before OpenVDB can throw
      prizma_vdb_error(vdb_flipped_size "vdb_flipped_size\\.vdb"
                       "not a readable OpenVDB file \\(corrupt: a size in it asks for more memory than any valid file of 42125 bytes needs\\)")
    endif()
    prizma_vdb_error(vdb_level_set "vdb_level_set\\.vdb: grid \"density\"" "is a level set .*convert it to a fog volume first")
  endif()
endif()

if(TARGET prizma-relight)
  # prizma_relight_error(NAME EXR REASON_REGEX [EXISTING]): relight EXR -o <NAME>.png, expect exit 2.
  function(prizma_relight_error name exr reason)
    string(REPLACE "." "\\." input "${exr}")
    prizma_error_e2e(relight_${name} prizma-relight 2 "${input}" "${reason}" relight_${name}.png ${ARGN}
                     ${exr} -o relight_${name}.png)
  endfunction()
  prizma_relight_error(truncated truncated.exr ".")
  prizma_relight_error(not_an_exr not_an_exr.exr "EXR|OpenEXR")
  prizma_relight_error(rgb_only rgb_only.exr "spectral")
  prizma_relight_error(emissive_only emissive_only.exr "emissive|S0")
  prizma_relight_error(missing_layer missing_layer.exr "announces light \"back\"")
  prizma_relight_error(inconsistent_edges inconsistent_edges.exr "edge|centre|center")
  prizma_relight_error(edge_count edge_count.exr "6 edges for 4 spectral channels")
  prizma_relight_error(unsorted_edges unsorted_edges.exr "edge|increasing")
  prizma_relight_error(nan_pixel nan_pixel.exr "NaN|nan|finite")
  prizma_relight_error(bad_checksum bad_checksum.exr "do not match prizma:checksum")
  prizma_relight_error(unusable_light unusable_light.exr "no_such_lamp\\.csv.*--light key=SPEC")
  # The same file relights once the unusable light is given a spectrum.
  add_test(NAME errors.e2e.relight_unusable_light_overridden
           COMMAND $<TARGET_FILE:prizma-relight> unusable_light.exr --light key=D65 -o relight_unusable_light_ok.png
           WORKING_DIRECTORY ${_errors_work})
  set_tests_properties(errors.e2e.relight_unusable_light_overridden PROPERTIES FIXTURES_REQUIRED errors_files
                       LABELS errors ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}")
  prizma_relight_error(moved_edges moved_edges.exr "is not the centre 435 nm of its bin")
  prizma_relight_error(fifo fifo.exr "FIFO")
  prizma_error_e2e(relight_batch_bitdepth prizma-relight 2 "batch_bitdepth\\.json: outputs\\[0\\]\\.bitDepth" "must be 8 or 16 \\(got 8\\.7\\)"
                   batch_bitdepth.png good.exr --batch batch_bitdepth.json)
  prizma_error_e2e(relight_batch_deep prizma-relight 2 "batch_deep\\.json" "nested deeper than" batch_deep.png
                   good.exr --batch batch_deep.json)
  prizma_relight_error(truncated_existing_output truncated.exr "." EXISTING)
  prizma_relight_error(not_an_exr_existing_exr not_an_exr.exr "EXR|OpenEXR" EXISTING)
  # Light spectra: outside the colour matching range, unsorted CSV.
  prizma_error_e2e(relight_light_outside_bins prizma-relight 2 "light" "no energy" relight_light_ir.png
                   good.exr --light csv:infrared.csv -o relight_light_ir.png)
  prizma_error_e2e(relight_light_scale_huge prizma-relight 2 "\\-\\-light:" "light scale 1e\\+39 in \"D65\\*1e39\" is above 1e\\+12"
                   relight_light_scale.png good.exr --light D65*1e39 -o relight_light_scale.png)
  prizma_error_e2e(relight_light_far_infrared prizma-relight 2 "light" "no energy" relight_light_ir2.png
                   good.exr --light gaussian:1200:10 -o relight_light_ir2.png)
  prizma_error_e2e(relight_light_unsorted_csv prizma-relight 2 "unsorted\\.csv" "increasing" relight_light_unsorted.png
                   good.exr --light csv:unsorted.csv -o relight_light_unsorted.png)
  prizma_error_e2e(relight_light_nan_csv prizma-relight 2 "nan\\.csv" "finite" relight_light_nan.png EXISTING
                   good.exr --light csv:nan.csv -o relight_light_nan.png)
endif()

# An unknown PRIZMA_SIMD level (simd_choice.h; docs/renderer.md, "SIMD levels"): both tools refuse it
# with one line and exit 2, before writing anything; an existing output is kept.
if(TARGET prizma-render AND TARGET prizma-relight)
  set(_simd_reason "unknown SIMD level \"avx1024\" \\(known: baseline, sse4, avx2, avx512\\)")
  prizma_error_e2e(render_simd_level prizma-render 2 "^PRIZMA_SIMD: " "${_simd_reason}" render_simd_level.exr EXISTING
                   good.json -q -o render_simd_level.exr)
  prizma_error_e2e(relight_simd_level prizma-relight 2 "^PRIZMA_SIMD: " "${_simd_reason}" relight_simd_level.png EXISTING
                   good.exr -o relight_simd_level.png)
  set_property(TEST errors.e2e.render_simd_level errors.e2e.relight_simd_level APPEND PROPERTY ENVIRONMENT
               "PRIZMA_SIMD=avx1024")
endif()

# Out of memory wherever it happens (issue 11): under a series of address-space limits each run is
# a success or exit 1 with one "out of memory" line (below ~20 MB for prizma-render, ~40 MB for
# prizma-relight, the dynamic loader itself cannot map the libraries: exit 127 with ld.so's own
# message before any code runs, so the limits start there; OpenVDB comes with the VDB module, loaded
# only for "vdb" volumes). prizma-render's floor was 16 MB until its --preview went through
# OpenColorIO (issue 22: the preview is prizma-relight's relight), which it now links. The PNG relight loads OpenImageIO's ~260 libraries with the image
# module when it writes (400–500 MB: log4cplus, loaded with it, gives up starting its thread).
# Not in sanitizer builds: ASan reserves terabytes of address space.
if(NOT PRIZMA_SANITIZE AND NOT PRIZMA_FUZZ AND TARGET prizma-render AND TARGET prizma-relight)
  # One list of limits (MB) for both tools; each runs those from its own floor up.
  set(_memory_limits_mb 16 20 24 28 32 40 50 60 64 70 80 100 150 200 300 400 420 440 450 460 480 500 550 600 800 1200 2000 4000)
  # prizma_memory_limits_e2e(NAME FLOOR_MB OUTPUT TOOL ARGS...): TOOL ARGS under every limit ≥ FLOOR_MB.
  function(prizma_memory_limits_e2e name floor output tool)
    set(limits "")
    foreach(mb IN LISTS _memory_limits_mb)
      if(mb GREATER_EQUAL floor)
        list(APPEND limits ${mb})
      endif()
    endforeach()
    string(REPLACE ";" "," limits "${limits}")
    add_test(NAME errors.e2e.${name}
             COMMAND ${PRIZMA_SYSTEM_PYTHON3} ${_errors_dir}/check-memory-limits --workdir ${_errors_work}
                     --output ${output} --limits-mb ${limits} -- $<TARGET_FILE:${tool}> ${ARGN})
    set_tests_properties(errors.e2e.${name} PROPERTIES FIXTURES_REQUIRED errors_files LABELS errors
                         ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}")
  endfunction()
  prizma_memory_limits_e2e(render_out_of_memory 20 mem_render.exr prizma-render good.json -q -o mem_render.exr)
  prizma_memory_limits_e2e(relight_out_of_memory 40 mem_relight.png prizma-relight good.exr -o mem_relight.png)
endif()
