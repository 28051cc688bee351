# Interruptions and --resume (tests/e2e/resume/interrupt-and-resume): SIGINT, SIGTERM and SIGHUP keep
# the completed passes, a second signal writes nothing, --resume needs only the file and matches the
# uninterrupted render within the merge tolerance, a changed scene is refused. Label "resume".
prizma_e2e_require(resume.cmake TARGETS prizma-render PYTHON)

# Compares two renders of the same samples within the merge tolerance (also used by slurm.cmake).
add_executable(prizma-test-exr-compare ${PRIZMA_E2E_DIR}/resume/exr_compare.cpp)
target_link_libraries(prizma-test-exr-compare PRIVATE prizma::spectral)
prizma_set_warnings(prizma-test-exr-compare)

foreach(case signal-INT signal-TERM signal-HUP second-signal resume changed-scene)
  add_test(NAME resume.e2e.${case}
           COMMAND ${PRIZMA_SYSTEM_PYTHON3} ${PRIZMA_E2E_DIR}/resume/interrupt-and-resume ${case}
                   --render $<TARGET_FILE:prizma-render> --compare $<TARGET_FILE:prizma-test-exr-compare>
                   --scene ${PRIZMA_E2E_DIR}/render/tiny.json --workdir ${PRIZMA_E2E_WORK}/resume)
  set_tests_properties(resume.e2e.${case} PROPERTIES LABELS resume TIMEOUT 600
                       ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}")
endforeach()

# merge: a gap in the sample range warns (the merged file is written), --strict refuses it; shards
# are named by file; one shard is "1 shard". A huge --spp is refused with the reason. (Shards of the
# render_shards fixture in tests/e2e/render.cmake: shard0.exr holds 0:2, shard1.exr 2:4.)
prizma_render_e2e(shard_gap "${PRIZMA_E2E_DIR}/render/tiny.json|--samples|6:8|-o|shard_gap.exr|-q"
  MUST_EXIST shard_gap.exr FIXTURES_SETUP render_shards)
prizma_render_e2e(merge_gap_warns "merge|shard0.exr|shard_gap.exr|-o|gap.exr" MUST_EXIST gap.exr
  ERR_REGEX "warning: the shards leave a gap in the sample range: samples 2:6 are missing \\(the shards hold 0:2,6:8\\)"
  FIXTURES_REQUIRED render_shards)
prizma_render_e2e(merge_gap_strict "merge|shard0.exr|shard_gap.exr|shard1.exr|-o|gap_strict.exr|--strict"
  EXPECT_RC 2 MUST_NOT_EXIST gap_strict.exr ERR_LINES 1
  ERR_REGEX "^prizma-render: error: merge: the shards leave a gap in the sample range: samples 4:6 are missing"
  FIXTURES_REQUIRED render_shards)
prizma_render_e2e(merge_names_files "merge|shard0.exr|shard1.exr|shard0.exr|-o|named.exr" EXPECT_RC 2
  MUST_NOT_EXIST named.exr ERR_LINES 1
  ERR_REGEX "^prizma-render: error: shard0.exr: samples 0:2 overlap samples 0:2 of shard0.exr"
  FIXTURES_REQUIRED render_shards)
prizma_render_e2e(merge_one_shard "merge|shard1.exr|-o|one.exr" MUST_EXIST one.exr
  ERR_REGEX "merged 1 shard, samples 2:4" FIXTURES_REQUIRED render_shards)
prizma_render_e2e(resume_huge_spp "--resume|shard0.exr|--spp|18446744073709551613|-o|huge.exr" EXPECT_RC 2
  MUST_NOT_EXIST huge.exr ERR_LINES 1
  ERR_REGEX "^prizma-render: error: --spp: must be in \\[1, 1099511627776\\] \\(got 18446744073709551613\\)"
  FIXTURES_REQUIRED render_shards)

# --no-verify on merge and --resume: a shard re-encoded by another tool (oiiotool -d half keeps
# prizma:checksum but not the values) is refused as "probably re-encoded" without it, read with it;
# without --resume, --no-verify is refused.
find_program(PRIZMA_OIIOTOOL oiiotool)
if(PRIZMA_OIIOTOOL)
  add_test(NAME render.e2e.no_verify_reencoded_shard
           COMMAND sh -c "set -e; \"$1\" shard0.exr -d half -o reencoded.exr; rm -f nv_*.exr
if \"$0\" merge reencoded.exr shard1.exr -o nv_refused.exr 2>nv_err.txt; then exit 1; fi
grep -q '^prizma-render: error: reencoded.exr: .*probably re-encoded by another tool.*; --no-verify reads it$' nv_err.txt
if grep -q prizma-relight nv_err.txt; then exit 1; fi; test ! -e nv_refused.exr
if \"$0\" \"$2\" --resume reencoded.exr --spp 4 -o nv_refused.exr -q 2>nv_err.txt; then exit 1; fi
grep -q '^prizma-render: error: reencoded.exr: .*probably re-encoded by another tool.*; --no-verify reads it$' nv_err.txt
if grep -q prizma-relight nv_err.txt; then exit 1; fi; test ! -e nv_refused.exr
\"$0\" merge reencoded.exr shard1.exr -o nv_merged.exr --no-verify 2>nv_err.txt; grep -q 'samples 0:4' nv_err.txt
\"$0\" \"$2\" --resume reencoded.exr --spp 4 -o nv_resumed.exr --no-verify -q; test -s nv_resumed.exr"
                   $<TARGET_FILE:prizma-render> ${PRIZMA_OIIOTOOL} ${PRIZMA_E2E_DIR}/render/tiny.json)
  set_tests_properties(render.e2e.no_verify_reencoded_shard PROPERTIES WORKING_DIRECTORY ${PRIZMA_E2E_WORK}/render
                       FIXTURES_REQUIRED render_shards RESOURCE_LOCK render_e2e_work LABELS resume
                       ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}")
endif()
prizma_render_e2e(no_verify_without_resume "${PRIZMA_E2E_DIR}/render/tiny.json|--no-verify|-o|bad.exr" EXPECT_RC 2
  MUST_NOT_EXIST bad.exr ERR_LINES 1 ERR_REGEX "^prizma-render: error: --no-verify: only with --resume")
