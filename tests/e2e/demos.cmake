# The prizma-metamer CLI (label "e2e") and the demonstration scripts at a tiny size (label "demo";
# each script checks its own claim and exits non-zero when it fails).
set(PRIZMA_METAMER_WORK ${PRIZMA_E2E_WORK}/metamer)
file(MAKE_DIRECTORY ${PRIZMA_METAMER_WORK})

if(TARGET prizma-metamer)
  add_test(NAME metamer.cli.help COMMAND prizma-metamer --help)
  set_tests_properties(metamer.cli.help PROPERTIES LABELS e2e PASS_REGULAR_EXPRESSION "metamer.*light.*delta-e")

  # A metamer of ColorChecker foliage under D65 split by F11: exit 0, a CSV, the table.
  add_test(NAME metamer.cli.metamer
           COMMAND sh -c "\"$0\" metamer --albedo cc:4 --match-light D65 --split-light F11 -o \"$1\" && test -s \"$1\""
                   $<TARGET_FILE:prizma-metamer> ${PRIZMA_METAMER_WORK}/metamer.csv)
  set_tests_properties(metamer.cli.metamer PROPERTIES LABELS e2e
                       ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}")

  add_test(NAME metamer.cli.light_reveal
           COMMAND sh -c "\"$0\" light --albedo-a cc:7 --albedo-b cc:16 --reveal --primaries LED-B3,gaussian:450:20,gaussian:620:20 -o \"$1\" && test -s \"$1\""
                   $<TARGET_FILE:prizma-metamer> ${PRIZMA_METAMER_WORK}/reveal.csv)
  set_tests_properties(metamer.cli.light_reveal PROPERTIES LABELS e2e
                       ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}")

  # The relighter's weights for D65 in 16 bins: 16 rows; sums are D65's white point with Y = 1
  # (X 0.9504, Z 1.0888 for the 1931 observer, CIE 015:2018 table 3).
  add_test(NAME metamer.cli.weights
           COMMAND sh -c "\"$0\" --bins linear:380:780:16 weights --light D65 -o \"$1\" && awk -F, 'NR > 1 { n++; x += $3; y += $4; z += $5 } END { printf \"%d %.6f %.6f %.6f\\n\", n, x, y, z; exit !(n == 16 && y > 0.999999 && y < 1.000001 && x > 0.9494 && x < 0.9514 && z > 1.0878 && z < 1.0898) }' \"$1\""
                   $<TARGET_FILE:prizma-metamer> ${PRIZMA_METAMER_WORK}/weights.csv)
  set_tests_properties(metamer.cli.weights PROPERTIES LABELS e2e
                       ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}")

  # --scene reads the materials with the renderer's scene reader: by name or by index, the same
  # albedos as the spec strings the scene gives them (the two designed lights are the same bytes).
  add_test(NAME metamer.cli.scene_materials
           COMMAND sh -c "\"$0\" -q light --scene \"$1\" --material-a haze --material-b 1 --reveal -o \"$2/scene.csv\" && \"$0\" -q light --albedo-a 0.9 --albedo-b cc:orange --reveal -o \"$2/specs.csv\" && cmp \"$2/scene.csv\" \"$2/specs.csv\""
                   $<TARGET_FILE:prizma-metamer> ${PRIZMA_E2E_DIR}/render/tiny.json ${PRIZMA_METAMER_WORK})
  set_tests_properties(metamer.cli.scene_materials PROPERTIES LABELS e2e
                       ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}")
  # A scene prizma-render refuses (a misspelt field) is refused here too, with the renderer's message.
  file(READ ${PRIZMA_E2E_DIR}/render/tiny.json _metamer_scene)
  string(REPLACE "\"anisotropy\": 0}" "\"anisotrpy\": 0}" _metamer_scene "${_metamer_scene}")
  file(WRITE ${PRIZMA_METAMER_WORK}/misspelt.json "${_metamer_scene}")
  set(PRIZMA_METAMER_TINY ${PRIZMA_E2E_DIR}/render/tiny.json)
  set(PRIZMA_METAMER_MISSPELT ${PRIZMA_METAMER_WORK}/misspelt.json)

  # Input errors: exit 2, one line naming the input, no output file.
  foreach(case
      "bad_albedo|metamer --albedo 1.5 --match-light D65 --split-light A -o OUT|error: albedo: value 1.5"
      "unknown_light|metamer --albedo 0.5 --match-light D66 --split-light A -o OUT|error: --match-light"
      "hide_and_reveal|light --albedo-a cc:7 --albedo-b cc:16 --hide --reveal -o OUT|error: --hide/--reveal"
      "same_albedos|light --albedo-a cc:7 --albedo-b cc:7 --reveal -o OUT|error: albedo-b"
      "weights_dark_light|--bins linear:700:780:4 weights --light box:400:500 -o OUT|error: light"
      "scene_no_material|light --scene ${PRIZMA_METAMER_TINY} --material-a nope --material-b core --hide -o OUT|no material .nope. (its materials: haze, core)"
      "scene_misspelt|light --scene ${PRIZMA_METAMER_MISSPELT} --material-a haze --material-b core --hide -o OUT|materials.1..anisotrpy.*unknown field")
    string(REPLACE "|" ";" parts "${case}")
    list(GET parts 0 name)
    list(GET parts 1 args)
    list(GET parts 2 pattern)
    set(out ${PRIZMA_METAMER_WORK}/${name}.csv)
    string(REPLACE "OUT" "${out}" args "${args}")
    add_test(NAME metamer.cli.${name}
             COMMAND sh -c "rm -f \"$1\"; msg=$(\"$0\" ${args} 2>&1 >/dev/null); rc=$?; echo \"$msg\"; test $rc -eq 2 && test ! -e \"$1\" && test $(echo \"$msg\" | wc -l) -eq 1 && echo \"$msg\" | grep -q -- \"$2\""
                     $<TARGET_FILE:prizma-metamer> ${out} "${pattern}")
    set_tests_properties(metamer.cli.${name} PROPERTIES LABELS e2e
                         ENVIRONMENT "PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR}")
  endforeach()
endif()

if(TARGET prizma-metamer AND TARGET prizma-render AND TARGET prizma-relight)
  get_filename_component(_prizma_scripts ${PRIZMA_E2E_DIR}/../../scripts ABSOLUTE)
  foreach(demo metamerism-demo scattering-demo reveal-demo fluorescence-demo)
    add_test(NAME demo.${demo} COMMAND ${_prizma_scripts}/${demo} ${PRIZMA_E2E_WORK}/${demo} --small)
    set_tests_properties(demo.${demo} PROPERTIES LABELS demo TIMEOUT 600 ENVIRONMENT
      "PRIZMA_RENDER=$<TARGET_FILE:prizma-render>;PRIZMA_RELIGHT=$<TARGET_FILE:prizma-relight>;PRIZMA_METAMER=$<TARGET_FILE:prizma-metamer>;PRIZMA_DATA_DIR=${PRIZMA_SOURCE_DATA_DIR};MPLCONFIGDIR=${PRIZMA_E2E_WORK}/${demo}/.mpl")
  endforeach()
endif()
