# CLI-level tests of bad scene input (included by tests/CMakeLists.txt): `canopy render <file>`
# must exit with code 2 and print the one-line SceneError message on stderr. Every
# tests/data/bad/*.json carries its expected message in its first line ("// expect: ...").
file(GLOB CANOPY_BAD_SCENES CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/data/bad/*.json)
foreach(scene ${CANOPY_BAD_SCENES})
  get_filename_component(stem ${scene} NAME_WE)
  add_test(NAME cli_bad_${stem}
    COMMAND ${CMAKE_COMMAND} -DEXE=$<TARGET_FILE:canopy> -DSCENE=${scene}
            -P ${CMAKE_CURRENT_SOURCE_DIR}/check_exit2.cmake)
  set_tests_properties(cli_bad_${stem} PROPERTIES LABELS cli TIMEOUT 120)
endforeach()

# A scene file that does not exist.
set(missing ${CMAKE_CURRENT_SOURCE_DIR}/data/bad/no_such_scene.json)
add_test(NAME cli_missing_scene_file
  COMMAND ${CMAKE_COMMAND} -DEXE=$<TARGET_FILE:canopy> -DSCENE=${missing}
          "-DEXPECT=${missing}: cannot open file"
          -P ${CMAKE_CURRENT_SOURCE_DIR}/check_exit2.cmake)
set_tests_properties(cli_missing_scene_file PROPERTIES LABELS cli TIMEOUT 120)

# The orientation ablation applies to the tree samplers only.
add_test(NAME cli_no_orientation_needs_a_tree
  COMMAND ${CMAKE_COMMAND} -DEXE=$<TARGET_FILE:canopy>
          -DSCENE=${CMAKE_CURRENT_SOURCE_DIR}/../scenes/default.json
          "-DARGS=--light-sampler;power;--no-orientation"
          "-DEXPECT=--no-orientation: applies to the tree samplers only (tree, tree-split), not power"
          -P ${CMAKE_CURRENT_SOURCE_DIR}/check_exit2.cmake)
set_tests_properties(cli_no_orientation_needs_a_tree PROPERTIES LABELS cli TIMEOUT 120)

# A film whose pixels exceed FLT_MAX: exit 0, one warning line, counted in the stats, finite image.
add_test(NAME cli_film_overflow_is_counted_and_finite
  COMMAND ${CMAKE_COMMAND} -DEXE=$<TARGET_FILE:canopy>
          -DSCENE=${CMAKE_CURRENT_SOURCE_DIR}/data/film_overflow.json
          -DWORK=${CMAKE_CURRENT_BINARY_DIR}/film_overflow
          -P ${CMAKE_CURRENT_SOURCE_DIR}/check_film_overflow.cmake)
set_tests_properties(cli_film_overflow_is_counted_and_finite PROPERTIES LABELS cli TIMEOUT 180)
