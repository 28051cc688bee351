# End-to-end tests of fluorescence (docs/fluorescence.md): data/scenes/fluorescent_dye.json rendered
# small in two shards, merged (the bispectral channels too), relit under a violet LED; a fluorescent
# scene with --wavelength-sampling single renders and relights too.
if(NOT TARGET prizma-render OR NOT TARGET prizma-relight)
  return()
endif()

set(_fl_work ${PRIZMA_E2E_WORK}/fluorescence)
set(_fl_scene ${PRIZMA_SOURCE_DATA_DIR}/scenes/fluorescent_dye.json)

function(prizma_fluorescence_e2e name exe args)
  prizma_e2e_run(NAME_PREFIX fluorescence WORKDIR ${_fl_work} LOCK fluorescence_e2e_work NAME ${name}
                 EXE ${exe} ARGS "${args}" ${ARGN})
endfunction()

set(_small "--width|16|--height|16|--threads|2|-q")
prizma_fluorescence_e2e(shard0 $<TARGET_FILE:prizma-render> "${_fl_scene}|--samples|0:2|-o|dye0.exr|${_small}"
  MUST_EXIST dye0.exr FIXTURES_SETUP fluorescence_shards)
prizma_fluorescence_e2e(shard1 $<TARGET_FILE:prizma-render> "${_fl_scene}|--samples|2:4|-o|dye1.exr|${_small}"
  MUST_EXIST dye1.exr FIXTURES_SETUP fluorescence_shards)
prizma_fluorescence_e2e(merge $<TARGET_FILE:prizma-render> "merge|dye0.exr|dye1.exr|-o|dye.exr"
  MUST_EXIST dye.exr ERR_REGEX "samples 0:4" FIXTURES_REQUIRED fluorescence_shards FIXTURES_SETUP fluorescence_merged)
prizma_fluorescence_e2e(relight $<TARGET_FILE:prizma-relight> "dye.exr|--light|key=LED-V1|--light|sky=off|-o|dye_violet.png"
  MUST_EXIST dye_violet.png FIXTURES_REQUIRED fluorescence_merged)
prizma_fluorescence_e2e(single $<TARGET_FILE:prizma-render>
  "${_fl_scene}|--wavelength-sampling|single|--spp|4|-o|single.exr|${_small}" MUST_EXIST single.exr
  FIXTURES_SETUP fluorescence_single)
# Spectral MIS does not take fluorescent materials: asked for, it is refused (exit 2, one line naming
# the material, no output); auto leaves the scene on spectral tracking (the shards above).
prizma_fluorescence_e2e(mis_refused $<TARGET_FILE:prizma-render>
  "${_fl_scene}|--wavelength-sampling|spectral-mis|--spp|2|-o|mis.exr|${_small}" EXPECT_RC 2 MUST_NOT_EXIST mis.exr
  ERR_REGEX "prizma-render: error: wavelength_sampling: spectral-mis does not support fluorescent materials \\(material \"[^\"]+\" fluoresces\\)" ERR_LINES 1)
prizma_fluorescence_e2e(single_relight $<TARGET_FILE:prizma-relight> "single.exr|--light|key=LED-V1|--light|sky=off|-o|single_violet.png"
  MUST_EXIST single_violet.png FIXTURES_REQUIRED fluorescence_single)

# prizma-render --preview of a fluorescent scene shows the re-radiated light: the same PNG as
# prizma-relight -o of the render under its own lights (oiiotool --diff, no pixel may differ).
find_program(PRIZMA_OIIOTOOL oiiotool)
if(PRIZMA_OIIOTOOL)
  add_test(NAME fluorescence.e2e.preview_includes_reradiation
           COMMAND sh -c "\"$1\" \"$2\" -o pv.exr --preview pv.png --width 16 --height 16 --spp 4 --threads 2 -q && \"$3\" pv.exr -o pv_relight.png -q && \"$4\" pv.png pv_relight.png --fail 0.000001 --diff"
                   sh $<TARGET_FILE:prizma-render> ${_fl_scene} $<TARGET_FILE:prizma-relight> ${PRIZMA_OIIOTOOL}
           WORKING_DIRECTORY ${_fl_work})
  set_tests_properties(fluorescence.e2e.preview_includes_reradiation PROPERTIES
                       ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}" RESOURCE_LOCK fluorescence_e2e_work
                       FIXTURES_REQUIRED fluorescence_shards)
endif()
