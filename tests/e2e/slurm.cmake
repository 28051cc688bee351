# A real one-node Slurm cluster (tests/e2e/slurm/slurm-cluster): the job array of docs/distributed.md,
# one task preempted with SIGTERM and requeued (--resume), merged, equal to a one-machine render.
# Label "slurm"; skipped (exit 77) when not root or slurm-wlm/munge are missing, failed then with
# CI=true (tests/missing-tool). Bounded: 15 min.
# Also: the job script shown in docs/distributed.md is byte for byte scripts/slurm/render-shards.sbatch.
if(NOT TARGET prizma-render OR NOT TARGET prizma-test-exr-compare)
  return()
endif()
add_test(NAME slurm.e2e.job_array_preempt_resume
         COMMAND ${PRIZMA_E2E_DIR}/slurm/slurm-cluster $<TARGET_FILE:prizma-render>
                 $<TARGET_FILE:prizma-test-exr-compare> ${PRIZMA_E2E_DIR}/render/tiny.json
                 ${PROJECT_SOURCE_DIR}/scripts/slurm/render-shards.sbatch)
set_tests_properties(slurm.e2e.job_array_preempt_resume PROPERTIES LABELS slurm SKIP_RETURN_CODE 77
                     TIMEOUT 900 PROCESSORS 2 ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}")
add_test(NAME slurm.e2e.doc_job_script_is_the_tested_one
         COMMAND ${PRIZMA_SYSTEM_PYTHON3} ${PRIZMA_E2E_DIR}/slurm/check-doc-script
                 ${PROJECT_SOURCE_DIR}/docs/distributed.md ${PROJECT_SOURCE_DIR}/scripts/slurm/render-shards.sbatch)
set_tests_properties(slurm.e2e.doc_job_script_is_the_tested_one PROPERTIES LABELS docs)
