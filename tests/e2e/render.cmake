# End-to-end tests of prizma-render: a tiny scene (tests/e2e/render/tiny.json), shards and merge,
# and the failure cases (exit codes, one-line errors, no file left behind).
if(NOT TARGET prizma-render)
  return()
endif()

set(_render_work ${PRIZMA_E2E_WORK}/render)
set(_tiny ${PRIZMA_E2E_DIR}/render/tiny.json)

# prizma_render_e2e(NAME ARGS [key value]...): one run_and_check.cmake invocation (prizma_e2e_run).
function(prizma_render_e2e name args)
  prizma_e2e_run(NAME_PREFIX render WORKDIR ${_render_work} LOCK render_e2e_work NAME ${name}
                 EXE $<TARGET_FILE:prizma-render> ARGS "${args}" ${ARGN})
endfunction()

prizma_render_e2e(help "--help" OUT_REGEX "--spp.*--samples.*--preview")
prizma_render_e2e(version "--version" OUT_REGEX "prizma-render [0-9]")
prizma_render_e2e(merge_help "merge|--help" OUT_REGEX "shards")
prizma_render_e2e(render "${_tiny}|-o|tiny.exr|--preview|tiny.png|--variance|--threads|2"
  MUST_EXIST "tiny.exr|tiny.png" ERR_REGEX "4 spp \\(0:4\\)")
prizma_render_e2e(shard0 "${_tiny}|--samples|0:2|-o|shard0.exr|-q" MUST_EXIST shard0.exr FIXTURES_SETUP render_shards)
prizma_render_e2e(shard1 "${_tiny}|--samples|2:4|-o|shard1.exr|-q" MUST_EXIST shard1.exr FIXTURES_SETUP render_shards)
prizma_render_e2e(merge "merge|shard0.exr|shard1.exr|-o|merged.exr|--preview|merged.png"
  MUST_EXIST "merged.exr|merged.png" ERR_REGEX "samples 0:4" FIXTURES_REQUIRED render_shards)
prizma_render_e2e(merge_overlap "merge|shard0.exr|shard0.exr|-o|overlap.exr" EXPECT_RC 2
  MUST_NOT_EXIST overlap.exr ERR_REGEX "overlap" ERR_LINES 1 FIXTURES_REQUIRED render_shards)
prizma_render_e2e(resume "${_tiny}|--resume|shard0.exr|--spp|4|-o|resumed.exr|-q" MUST_EXIST resumed.exr
  FIXTURES_REQUIRED render_shards)

# --preview is the render's default relight, the same pixels and records as prizma-relight -o of the
# file it wrote, a --half file's too (render/preview_is_the_relight.sh).
find_program(PRIZMA_OIIOTOOL oiiotool)
if(PRIZMA_OIIOTOOL AND TARGET prizma-relight)
  foreach(_mode float half)
    set(_args)
    if(_mode STREQUAL half)
      set(_args --half)
    endif()
    add_test(NAME render.e2e.preview_is_the_relight_${_mode}
             COMMAND ${PRIZMA_E2E_DIR}/render/preview_is_the_relight.sh $<TARGET_FILE:prizma-render>
                     $<TARGET_FILE:prizma-relight> ${PRIZMA_OIIOTOOL} ${PRIZMA_SOURCE_DATA_DIR}/scenes/cube_sphere.json
                     ${_render_work}/preview_${_mode} ${_args})
    set_tests_properties(render.e2e.preview_is_the_relight_${_mode} PROPERTIES
                         ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}")
  endforeach()
else()
  prizma_missing_tool_test(render.e2e.preview_is_the_relight "oiiotool (Debian openimageio-tools)")
endif()

# prizma-render inspect (issue 25 item 9): the scene's volume, histogram and the voxels each material
# takes (tiny.json: cube_sphere at 16³, haze [50, 150], core [200, 255]); a volume file; a file it
# cannot inspect is one line, exit 2.
prizma_render_e2e(inspect_scene "inspect|${_tiny}|--bins|4"
  OUT_REGEX "volume +cube_sphere \\(procedural\\): 16 × 16 × 16 voxels.*histogram +4 bins over \\[100, 255\\].*haze +\\[50, 150\\] \\(normalised \\[0.196078, 0.588235\\]\\): [0-9 ]+ voxels.*core +\\[200, 255\\].*no material")
prizma_render_e2e(inspect_volume "inspect|${PRIZMA_SOURCE_DATA_DIR}/scenes/bench_peer_64x64x64.nii.gz"
  OUT_REGEX "NIfTI\\): 64 × 64 × 64 voxels.*voxel size +1 × 1 × 1 mm.*orientation +NIfTI orientation")
prizma_render_e2e(inspect_unknown "inspect|${_tiny}.txt" EXPECT_RC 2 ERR_LINES 1)

# A material's anisotropy is signed: a csv: table of g with negative values renders; the same table
# as an albedo is refused, naming the file and line (issue 27; docs/spectra.md, "Signed quantities").
prizma_render_e2e(signed_anisotropy_table "${_tiny}|-D|materials.haze.anisotropy=csv:backscatter_g.csv|-o|backscatter.exr|-q"
  MUST_EXIST backscatter.exr)
prizma_render_e2e(negative_albedo_table "${_tiny}|-D|materials.haze.albedo=csv:backscatter_g.csv|-o|bad.exr" EXPECT_RC 2
  MUST_NOT_EXIST bad.exr ERR_REGEX "backscatter_g\\.csv:3: value must not be negative, got -0\\.6" ERR_LINES 1)

# Failures: usage errors exit 2 with "prizma-render: error: ..." and write nothing.
prizma_render_e2e(bad_option "${_tiny}|--bogus|-o|bad.exr" EXPECT_RC 2 MUST_NOT_EXIST bad.exr
  ERR_REGEX "prizma-render: error:")
prizma_render_e2e(missing_scene "no_such_scene.json|-o|bad.exr" EXPECT_RC 2 MUST_NOT_EXIST bad.exr
  ERR_REGEX "prizma-render: error: .*no_such_scene.json" ERR_LINES 1)
prizma_render_e2e(unwritable "${_tiny}|-o|no_such_folder/out.exr" EXPECT_RC 2
  MUST_NOT_EXIST no_such_folder/out.exr ERR_REGEX "no_such_folder" ERR_LINES 1)
prizma_render_e2e(bad_samples "${_tiny}|--samples|5:2|-o|bad.exr" EXPECT_RC 2 MUST_NOT_EXIST bad.exr
  ERR_REGEX "--samples" ERR_LINES 1)
prizma_render_e2e(bad_bins "${_tiny}|--bins|linear:700:400:3|-o|bad.exr" EXPECT_RC 2 MUST_NOT_EXIST bad.exr
  ERR_REGEX "--bins" ERR_LINES 1)
prizma_render_e2e(bad_sampling "${_tiny}|--wavelength-sampling|hero|-o|bad.exr" EXPECT_RC 2
  MUST_NOT_EXIST bad.exr)
prizma_render_e2e(bad_sampler "${_tiny}|--sampler|halton|-o|bad.exr" EXPECT_RC 2
  MUST_NOT_EXIST bad.exr ERR_REGEX "--sampler")
# The Sobol' sampler: a shard resumes with it (recorded in prizma:renderOptions), and a resume that
# changes the sampler is refused.
prizma_render_e2e(sobol_shard "${_tiny}|--sampler|sobol|--samples|0:2|-o|sobol0.exr|-q" MUST_EXIST sobol0.exr
  FIXTURES_SETUP render_sobol)
prizma_render_e2e(sobol_resume "${_tiny}|--resume|sobol0.exr|--spp|4|-o|sobol_resumed.exr|-q"
  MUST_EXIST sobol_resumed.exr FIXTURES_REQUIRED render_sobol)
prizma_render_e2e(sobol_resume_other_sampler "${_tiny}|--resume|sobol0.exr|--sampler|independent|--spp|4|-o|bad.exr"
  EXPECT_RC 2 MUST_NOT_EXIST bad.exr ERR_REGEX "--sampler.*sampler sobol" ERR_LINES 1 FIXTURES_REQUIRED render_sobol)
