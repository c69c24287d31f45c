# stats_skipped.cmake — sightline-render --stats reports volume_dvr's ray
# samples and the fraction empty-space skipping jumped over: with skipping
# on, skipped_fraction in (0, 1) and ray_samples > 0; off, ray_samples_skipped
# exactly 0 and more samples taken.
# Usage: cmake -DRENDER=exe -DSCENE=json -DOUT=dir -P stats_skipped.cmake
foreach(on true false)
  execute_process(COMMAND ${RENDER} --scene ${SCENE} --out ${OUT}/volume_stats_${on}.png --samples 1
                          --set params.empty_space_skipping=${on} --stats ${OUT}/volume_stats_${on}.json
                  RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "sightline-render exited with ${rc}: ${err}")
  endif()
  file(READ ${OUT}/volume_stats_${on}.json stats)
  string(JSON taken_${on} GET "${stats}" ray_samples)
  string(JSON skipped_${on} GET "${stats}" ray_samples_skipped)
  string(JSON fraction_${on} GET "${stats}" skipped_fraction)
  message("empty_space_skipping ${on}: ray_samples ${taken_${on}}, skipped ${skipped_${on}}, fraction ${fraction_${on}}")
endforeach()
if(NOT taken_true GREATER 0 OR NOT skipped_true GREATER 0 OR NOT fraction_true LESS 1)
  message(FATAL_ERROR "skipping on: expected samples taken and skipped, got ${taken_true} / ${skipped_true}")
endif()
if(NOT skipped_false EQUAL 0 OR NOT taken_false GREATER taken_true)
  message(FATAL_ERROR "skipping off: expected no skipped samples and more taken, got ${taken_false} / ${skipped_false}")
endif()
