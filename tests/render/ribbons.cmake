# Tests of `ribbons` (renderer/ribbons/, issue 13) that exist so far: the halo
# and twist-line shader functions on the GPU (ribbons_probe.comp.glsl) against
# the CPU references of tests/support/ribbons_reference.h.
set(RIBBONS_DIR ${CMAKE_CURRENT_SOURCE_DIR}/ribbons)
add_executable(test_ribbons_halo ${RIBBONS_DIR}/test_ribbons_halo.c)
target_include_directories(test_ribbons_halo PRIVATE ${CMAKE_SOURCE_DIR}/tests/unit)
target_link_libraries(test_ribbons_halo PRIVATE sightline_test_support sightline_proto sightline_renderer)
set_target_properties(test_ribbons_halo PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
add_test(NAME unit.test_ribbons_halo COMMAND ${SL_TEST_RUN} $<TARGET_FILE:test_ribbons_halo>
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(unit.test_ribbons_halo PROPERTIES ENVIRONMENT "${SL_TEST_ENV}" TIMEOUT 300)
