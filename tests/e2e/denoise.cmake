# prizma-render denoise (docs/denoise.md) through the real executables: a render with --variance, a
# merged and a resumed file denoised; prizma:denoised shown by prizma-relight (--show, the shell's
# status) and relit like any other file; what is refused (one line, exit 2, nothing written): a file
# without variance layers, a denoised file denoised, merged or resumed again, -o naming the input.
if(NOT TARGET prizma-render OR NOT TARGET prizma-relight)
  return()
endif()

set(_denoise_work ${PRIZMA_E2E_WORK}/denoise)
set(_tiny ${PRIZMA_E2E_DIR}/render/tiny.json)

# prizma_denoise_e2e(NAME EXE ARGS [key value]...): one run_and_check.cmake run in the denoise folder.
function(prizma_denoise_e2e name exe args)
  prizma_e2e_run(NAME_PREFIX denoise WORKDIR ${_denoise_work} LOCK denoise_e2e_work NAME ${name}
                 EXE ${exe} ARGS "${args}" ${ARGN})
endfunction()
set(_render $<TARGET_FILE:prizma-render>)
set(_relight $<TARGET_FILE:prizma-relight>)

# The raw files: one render, two shards and a partial render, all with --variance.
prizma_denoise_e2e(raw ${_render} "${_tiny}|--variance|-o|raw.exr|-q" MUST_EXIST raw.exr FIXTURES_SETUP denoise_raw)
prizma_denoise_e2e(raw_shard0 ${_render} "${_tiny}|--variance|--samples|0:2|-o|vshard0.exr|-q" MUST_EXIST vshard0.exr
  FIXTURES_SETUP denoise_raw)
prizma_denoise_e2e(raw_shard1 ${_render} "${_tiny}|--variance|--samples|2:4|-o|vshard1.exr|-q" MUST_EXIST vshard1.exr
  FIXTURES_SETUP denoise_raw)
prizma_denoise_e2e(raw_plain ${_render} "${_tiny}|-o|novar.exr|-q" MUST_EXIST novar.exr FIXTURES_SETUP denoise_raw)
prizma_denoise_e2e(raw_features ${_render} "${_tiny}|--variance|--features|--samples|0:2|-o|feat0.exr|-q" MUST_EXIST feat0.exr
  FIXTURES_SETUP denoise_raw)
prizma_denoise_e2e(raw_features1 ${_render} "${_tiny}|--variance|--features|--samples|2:4|-o|feat1.exr|-q" MUST_EXIST feat1.exr
  FIXTURES_SETUP denoise_raw)

function(prizma_denoise_case name exe args)
  prizma_denoise_e2e(${name} ${exe} "${args}" ${ARGN})
  set_property(TEST denoise.e2e.${name} APPEND PROPERTY FIXTURES_REQUIRED denoise_raw)  # (beside the case's own)
endfunction()
prizma_denoise_case(help ${_render} "denoise|--help" OUT_REGEX "--variance.*propagate.*drop")
prizma_denoise_case(denoise ${_render} "denoise|raw.exr|-o|clean.exr|--threads|2" MUST_EXIST clean.exr
  ERR_REGEX "denoised by prizma [^:]+: non-local means on luminance. variance propagated \\(8×8, 2 lights, [0-9]+ bins\\) in [0-9.e-]+ s → clean\\.exr\nprizma-render: variance layers: Σ W²·Var"
  FIXTURES_SETUP denoise_clean)
# (No ';' in the values here: prizma_e2e_run's key/value list splits at one, so the pairs after it
# shifted and the fixtures were lost; '.' in the regexes matches the message's ';'.)
prizma_denoise_case(drop ${_render} "denoise|raw.exr|-o|clean_drop.exr|--variance|drop|--window|3|-q" MUST_EXIST clean_drop.exr
  FIXTURES_SETUP denoise_clean)
# Merged shards and a --resume'd file are files like any other.
prizma_denoise_case(merged_setup ${_render} "merge|vshard0.exr|vshard1.exr|-o|merged.exr|-q" MUST_EXIST merged.exr
  FIXTURES_SETUP denoise_merged)
prizma_denoise_case(resumed_setup ${_render} "--resume|vshard0.exr|--spp|4|-o|resumed.exr|-q" MUST_EXIST resumed.exr
  FIXTURES_SETUP denoise_merged)
prizma_denoise_case(merged ${_render} "denoise|merged.exr|-o|merged_clean.exr|-q" MUST_EXIST merged_clean.exr
  FIXTURES_REQUIRED denoise_merged)
prizma_denoise_case(resumed ${_render} "denoise|resumed.exr|-o|resumed_clean.exr|-q" MUST_EXIST resumed_clean.exr
  FIXTURES_REQUIRED denoise_merged)

# Guide layers (--features): merged, resumed and used as features; a file with them relights as before.
prizma_denoise_case(features_merged ${_render} "merge|feat0.exr|feat1.exr|-o|feat.exr|-q" MUST_EXIST feat.exr
  FIXTURES_SETUP denoise_features)
prizma_denoise_case(features_denoise ${_render} "denoise|feat.exr|-o|feat_clean.exr|--guides|features" MUST_EXIST feat_clean.exr
  ERR_REGEX "denoised by prizma [^:]+: non-local means and first-order regression on luminance, hit_albedo, .*hit_depth, .*hit_normal_z. variance propagated"
  FIXTURES_REQUIRED denoise_features)
prizma_denoise_case(features_resume ${_render} "--resume|feat0.exr|--spp|4|--denoise|--features|-o|feat_rs.exr"
  MUST_EXIST feat_rs.exr ERR_REGEX "non-local means and first-order regression on luminance, hit_albedo, .*hit_normal_z. variance propagated")
prizma_denoise_case(features_by_default_not_used ${_render} "denoise|feat.exr|-o|feat_lum.exr" MUST_EXIST feat_lum.exr
  ERR_REGEX "non-local means on luminance. variance propagated" FIXTURES_REQUIRED denoise_features)
prizma_denoise_case(features_relight ${_relight} "feat.exr|--light|side=A|-o|feat.png" MUST_EXIST feat.png
  FIXTURES_REQUIRED denoise_features)

# Every reader says so; a denoised file (variance propagated or dropped) relights like any other.
function(prizma_denoised_case name exe args)
  prizma_denoise_case(${name} ${exe} "${args}" ${ARGN})
  set_tests_properties(denoise.e2e.${name} PROPERTIES FIXTURES_REQUIRED "denoise_raw;denoise_clean")
endfunction()
prizma_denoised_case(relight_show ${_relight} "clean.exr|--show" OUT_REGEX "▀"
  ERR_REGEX "^prizma-relight: clean\\.exr: denoised by prizma [^:]+: non-local means on luminance. variance propagated\n$")
prizma_denoised_case(relight_png ${_relight} "clean.exr|--light|side=F11|-o|clean.png" MUST_EXIST clean.png)
prizma_denoised_case(relight_dropped ${_relight} "clean_drop.exr|-o|clean_drop.png" MUST_EXIST clean_drop.png)
prizma_denoised_case(relight_raw_show ${_relight} "raw.exr|--show" OUT_REGEX "▀" ERR_LINES 0)
add_test(NAME denoise.e2e.shell_status
         COMMAND ${CMAKE_COMMAND} -DEXE=${_relight} -DARGS=clean_drop.exr|-i -DWORKDIR=${_denoise_work}
                 -DSTDIN=${PRIZMA_E2E_DIR}/denoise/status.txt
                 "-DOUT_REGEX=filter +denoised by prizma [^:]+: non-local means on luminance. variance dropped"
                 -P ${PRIZMA_E2E_DIR}/relight/run_and_check.cmake)
set_tests_properties(denoise.e2e.shell_status PROPERTIES FIXTURES_REQUIRED "denoise_raw;denoise_clean"
                     ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}" RESOURCE_LOCK denoise_e2e_work)

# Refused: one line, exit 2, nothing written.
prizma_denoise_case(no_variance ${_render} "denoise|novar.exr|-o|err_novar.exr" EXPECT_RC 2 ERR_LINES 1
  MUST_NOT_EXIST err_novar.exr
  ERR_REGEX "^prizma-render: error: novar\\.exr: light \"[a-z]+\" has no variance layer: the denoiser weighs neighbours by their noise \\(render with --variance\\)")
prizma_denoise_case(onto_input ${_render} "denoise|raw.exr|-o|./raw.exr" EXPECT_RC 2 ERR_LINES 1
  ERR_REGEX "would replace \"raw\\.exr\", the OpenEXR file this run reads")
prizma_denoise_case(not_exr ${_render} "denoise|raw.exr|-o|err.png" EXPECT_RC 2 ERR_LINES 1 MUST_NOT_EXIST err.png
  ERR_REGEX "-o: err\\.png: the denoised file is a spectral EXR")
prizma_denoise_case(bad_window ${_render} "denoise|raw.exr|-o|err_window.exr|--window|16" EXPECT_RC 2 ERR_LINES 1
  MUST_NOT_EXIST err_window.exr ERR_REGEX "denoise options: window radius 16 is outside \\[1, 15\\]")
prizma_denoise_case(missing ${_render} "denoise|nowhere.exr|-o|err_missing.exr" EXPECT_RC 2 ERR_LINES 1
  MUST_NOT_EXIST err_missing.exr ERR_REGEX "nowhere\\.exr")
prizma_denoised_case(twice ${_render} "denoise|clean.exr|-o|err_twice.exr" EXPECT_RC 2 ERR_LINES 1
  MUST_NOT_EXIST err_twice.exr ERR_REGEX "^prizma-render: error: clean\\.exr: is already denoised \\(denoised by prizma .*\\): denoise the raw render")
prizma_denoised_case(merge_denoised ${_render} "merge|clean.exr|vshard1.exr|-o|err_merge.exr" EXPECT_RC 2 ERR_LINES 1
  MUST_NOT_EXIST err_merge.exr ERR_REGEX "^prizma-render: error: clean\\.exr: is denoised by prizma .*: samples cannot be added to filtered values")
prizma_denoised_case(resume_denoised ${_render} "--resume|clean.exr|--spp|8|-o|err_resume.exr" EXPECT_RC 2 ERR_LINES 1
  MUST_NOT_EXIST err_resume.exr ERR_REGEX "^prizma-render: error: clean\\.exr: is denoised by prizma .*: samples cannot be added")

# prizma-render SCENE --denoise: implies --variance, -o is the denoised file, --keep-raw the raw one
# (resumable); refused on a shard and, with --resume, without an -o of its own.
prizma_denoise_case(render_denoise ${_render} "${_tiny}|--denoise|--keep-raw|rd_raw.exr|--preview|rd.png|-o|rd.exr"
  MUST_EXIST "rd.exr|rd_raw.exr|rd.png"
  ERR_REGEX "prizma-render: denoised by prizma [^:]+: non-local means on luminance. variance propagated in [0-9.e-]+ s\nprizma-render: variance layers: Σ W²·Var"
  FIXTURES_SETUP denoise_rendered)
prizma_denoise_case(render_denoised_shows ${_relight} "rd.exr|-v|-o|rd_relit.png" MUST_EXIST rd_relit.png
  ERR_REGEX "prizma-relight: rd\\.exr: denoised by prizma" FIXTURES_REQUIRED denoise_rendered)
prizma_denoise_case(render_keep_raw_resumes ${_render} "--resume|rd_raw.exr|--spp|6|-o|rd_raw6.exr|-q" MUST_EXIST rd_raw6.exr
  FIXTURES_REQUIRED denoise_rendered)
prizma_denoise_case(resume_and_denoise ${_render} "--resume|vshard0.exr|--spp|4|--denoise|-o|rs_clean.exr|--keep-raw|rs_raw.exr|-q"
  MUST_EXIST "rs_clean.exr|rs_raw.exr" FIXTURES_REQUIRED denoise_merged)
# --keep-raw may name the resumed file itself: its raw samples are updated beside the denoised -o.
prizma_denoise_e2e(raw_inplace ${_render} "${_tiny}|--variance|--samples|0:2|-o|inplace.exr|-q" MUST_EXIST inplace.exr
  FIXTURES_SETUP denoise_inplace)
prizma_denoise_e2e(resume_keep_raw_in_place ${_render}
  "--resume|inplace.exr|--spp|4|--denoise|-o|inplace_clean.exr|--keep-raw|inplace.exr|-q"
  MUST_EXIST "inplace_clean.exr|inplace.exr")
set_tests_properties(denoise.e2e.resume_keep_raw_in_place PROPERTIES FIXTURES_REQUIRED denoise_inplace)
prizma_denoise_e2e(resume_keep_raw_in_place_done ${_render} "--resume|inplace.exr|--spp|4"
  ERR_REGEX "inplace\\.exr already holds samples 0:4, all that were asked for")
set_tests_properties(denoise.e2e.resume_keep_raw_in_place_done PROPERTIES FIXTURES_REQUIRED denoise_inplace
                     DEPENDS denoise.e2e.resume_keep_raw_in_place)
prizma_denoise_case(keep_raw_alone ${_render} "${_tiny}|--keep-raw|kr.exr|-o|kr_out.exr" EXPECT_RC 2 ERR_LINES 1
  MUST_NOT_EXIST "kr.exr|kr_out.exr" ERR_REGEX "^prizma-render: error: --keep-raw: only with --denoise")
prizma_denoise_case(denoise_shard ${_render} "${_tiny}|--samples|0:2|--denoise|-o|ds.exr" EXPECT_RC 2 ERR_LINES 1
  MUST_NOT_EXIST ds.exr ERR_REGEX "^prizma-render: error: --denoise: not with --samples: shards are merged, then denoised")
prizma_denoise_case(resume_denoise_in_place ${_render} "--resume|vshard1.exr|--spp|6|--denoise" EXPECT_RC 2 ERR_LINES 1
  ERR_REGEX "^prizma-render: error: --denoise: with --resume, give -o for the denoised file: it cannot replace vshard1\\.exr")
prizma_denoise_case(keep_raw_is_output ${_render} "${_tiny}|--denoise|--keep-raw|same.exr|-o|same.exr" EXPECT_RC 2 ERR_LINES 1
  MUST_NOT_EXIST same.exr ERR_REGEX "--keep-raw")
