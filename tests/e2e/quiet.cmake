# Successful runs with -q print nothing (issue 21): no library chatter on either stream. An EXR
# --preview printed OpenImageIO's "OIIO DEBUG: Don't know what to do with … ICCProfile" on stderr;
# OpenVDB's log lines went to stdout in ANSI colours. PNG and TIFF outputs carry an ICC profile.
# OpenVDB's messages about a file it still reads are now prizma-render's own warnings on stderr
# (kept by -q, like every warning about an input: vdb_warning below).
prizma_e2e_require(quiet.cmake TARGETS prizma-render prizma-relight)
set(_quiet_work ${PRIZMA_E2E_WORK}/quiet)
set(_quiet_scene ${PRIZMA_SOURCE_DATA_DIR}/scenes/cube_sphere.json)

prizma_e2e_run(NAME_PREFIX quiet WORKDIR ${_quiet_work} LOCK quiet_e2e_work NAME render EXE $<TARGET_FILE:prizma-render>
               ARGS "${_quiet_scene}|--width|8|--height|8|--spp|1|-q|-o|q.exr"
               MUST_EXIST q.exr OUT_REGEX "^$" ERR_LINES 0 FIXTURES_SETUP quiet_render)
foreach(_ext exr png tif)
  prizma_e2e_run(NAME_PREFIX quiet WORKDIR ${_quiet_work} LOCK quiet_e2e_work NAME render_preview_${_ext}
                 EXE $<TARGET_FILE:prizma-render>
                 ARGS "${_quiet_scene}|--width|8|--height|8|--spp|1|-q|-o|q_${_ext}.exr|--preview|q_preview.${_ext}"
                 MUST_EXIST "q_${_ext}.exr|q_preview.${_ext}" OUT_REGEX "^$" ERR_LINES 0)
endforeach()
foreach(_ext png tif jpg)
  prizma_e2e_run(NAME_PREFIX quiet WORKDIR ${_quiet_work} LOCK quiet_e2e_work NAME relight_${_ext}
                 EXE $<TARGET_FILE:prizma-relight> ARGS "q.exr|-q|--display|Display P3|-o|relit.${_ext}"
                 MUST_EXIST relit.${_ext} OUT_REGEX "^$" ERR_LINES 0 FIXTURES_REQUIRED quiet_render)
endforeach()

# A VDB scene (the fixtures of errors.cmake: a cloud from prizma-make-cloud-vdb, and the same cloud
# whose header claims an unknown format version, which OpenVDB reads and logs).
if(TARGET prizma-make-cloud-vdb AND PRIZMA_SYSTEM_PYTHON3)
  set(_quiet_errors_work ${PRIZMA_E2E_WORK}/errors)
  prizma_e2e_run(NAME_PREFIX quiet WORKDIR ${_quiet_errors_work} LOCK quiet_e2e_work NAME render_vdb
                 EXE $<TARGET_FILE:prizma-render> ARGS "vdb_cloud.json|-q|-o|quiet_vdb.exr"
                 MUST_EXIST quiet_vdb.exr OUT_REGEX "^$" ERR_LINES 0 FIXTURES_REQUIRED errors_vdb_files)
  prizma_e2e_run(NAME_PREFIX quiet WORKDIR ${_quiet_errors_work} LOCK quiet_e2e_work NAME render_vdb_warning
                 EXE $<TARGET_FILE:prizma-render> ARGS "vdb_flipped_version.json|-q|-o|quiet_vdb_warning.exr"
                 MUST_EXIST quiet_vdb_warning.exr OUT_REGEX "^$" ERR_LINES 1
                 ERR_REGEX "^prizma-render: warning: vdb_flipped_version\\.vdb: OpenVDB: unsupported VDB file format \\(expected version 224 or earlier, got version [0-9]+\\)\n$"
                 FIXTURES_REQUIRED errors_vdb_files)
endif()
