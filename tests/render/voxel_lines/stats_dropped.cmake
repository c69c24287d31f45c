# stats_dropped.cmake — sightline-render --stats reports the lines voxel_lines
# could not store: with max_lines_per_voxel = CAP on SCENE, `dropped` must be
# > 0 when EXPECT is "some" and exactly 0 when EXPECT is "none".
# Usage: cmake -DRENDER=exe -DSCENE=json -DOUT=dir -DCAP=n -DEXPECT=some|none -P stats_dropped.cmake
execute_process(COMMAND ${RENDER} --scene ${SCENE} --out ${OUT}/dropped_${CAP}.png --samples 1
                        --set params.max_lines_per_voxel=${CAP} --stats ${OUT}/dropped_${CAP}.json
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "sightline-render exited with ${rc}: ${err}")
endif()
file(READ ${OUT}/dropped_${CAP}.json stats)
string(JSON dropped GET "${stats}" dropped)
message("max_lines_per_voxel ${CAP}: dropped ${dropped}")
if(EXPECT STREQUAL "some" AND NOT dropped GREATER 0)
  message(FATAL_ERROR "expected dropped lines in --stats with a cap of ${CAP}, got ${dropped}")
elseif(EXPECT STREQUAL "none" AND NOT dropped EQUAL 0)
  message(FATAL_ERROR "expected no dropped lines with a cap of ${CAP}, got ${dropped}")
endif()
