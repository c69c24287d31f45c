# stats_skipping.cmake — sightline-render --stats reports a ray caster's work:
# with empty-space skipping ray_samples > 0, and more samples taken without it.
# With -DSKIPPED=1 the technique also counts what it jumped over (volume_dvr):
# then ray_samples_skipped > 0 and skipped_fraction < 1 with skipping, exactly
# 0 skipped without. Shared by the techniques' tests (volume_dvr, voxel_lines).
# Usage: cmake -DRENDER=exe -DSCENE=json -DOUT=dir -DNAME=prefix [-DSET=key=value]
#              [-DSKIPPED=1] -P stats_skipping.cmake
set(extra)
if(SET)
  set(extra --set ${SET})
endif()
foreach(on true false)
  execute_process(COMMAND ${RENDER} --scene ${SCENE} --out ${OUT}/${NAME}_${on}.png --samples 1 ${extra}
                          --set params.empty_space_skipping=${on} --stats ${OUT}/${NAME}_${on}.json
                  RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "sightline-render exited with ${rc}: ${err}")
  endif()
  file(READ ${OUT}/${NAME}_${on}.json stats)
  string(JSON taken_${on} GET "${stats}" ray_samples)
  string(JSON skipped_${on} GET "${stats}" ray_samples_skipped)
  string(JSON fraction_${on} GET "${stats}" skipped_fraction)
  message("empty_space_skipping ${on}: ray_samples ${taken_${on}}, skipped ${skipped_${on}}, fraction ${fraction_${on}}")
endforeach()
if(NOT taken_true GREATER 0 OR NOT taken_false GREATER taken_true)
  message(FATAL_ERROR "expected 0 < ray_samples with skipping < without, got ${taken_true} and ${taken_false}")
endif()
if(SKIPPED AND (NOT skipped_true GREATER 0 OR NOT fraction_true LESS 1 OR NOT skipped_false EQUAL 0))
  message(FATAL_ERROR "expected skipped samples with skipping (${skipped_true}, fraction ${fraction_true}) "
                      "and none without (${skipped_false})")
endif()
