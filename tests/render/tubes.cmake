# GPU tests of the `tubes` technique (renderer/tubes/): depth against the CPU
# double-precision reference (tests/render/tubes/tubes_reference.c) on random
# and degenerate Hermite segment sets, through the pipeline (tubes-check) and
# through `sightline-render --depth` + `sightline-diff`; golden images.
# Scenes and goldens live in tests/render/tubes/.
#
# Bound (every accuracy test): on pixels both hit, |depth error| <= 1e-3 x the
# local sweep radius; exceptions (beyond it, or hit by one side only) only at
# reference silhouettes and <= 0.5 % of the pixels hit; no NaN/Inf.
set(TUBES_DIR ${CMAKE_CURRENT_SOURCE_DIR}/tubes)
set(TUBES_OUT ${SL_RENDER_OUT}/tubes)
file(MAKE_DIRECTORY ${TUBES_OUT})
add_executable(tubes-check ${TUBES_DIR}/tubes_check.c ${TUBES_DIR}/tubes_reference.c)
target_include_directories(tubes-check PRIVATE ${TUBES_DIR} ${CMAKE_SOURCE_DIR}/proto)
target_link_libraries(tubes-check PRIVATE sightline_proto sightline_renderer)
set_target_properties(tubes-check PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
# The brute-force reference is slow unoptimized: always optimize it.
set_source_files_properties(${TUBES_DIR}/tubes_reference.c PROPERTIES COMPILE_OPTIONS "-O2")

add_executable(test_tubes_reference ${TUBES_DIR}/test_tubes_reference.c ${TUBES_DIR}/tubes_reference.c)
target_include_directories(test_tubes_reference PRIVATE ${TUBES_DIR} ${CMAKE_SOURCE_DIR}/tests/unit)
target_link_libraries(test_tubes_reference PRIVATE sightline_proto sightline_renderer)
set_target_properties(test_tubes_reference PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
add_test(NAME unit.test_tubes_reference COMMAND test_tubes_reference WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(unit.test_tubes_reference PROPERTIES ENVIRONMENT "${SL_TEST_ENV}" TIMEOUT 300)

function(tubes_render_test name)
  sl_add_render_test(NAME tubes.${name} COMMAND ${ARGN})
endfunction()

# Random segment sets (chains, bifurcations, varying radius and tangents).
foreach(seed 1 2 3)
  tubes_render_test(accuracy.random_${seed}
    tubes-check --scene ${TUBES_DIR}/random.json --random-segments 40 --seed ${seed})
endforeach()
tubes_render_test(accuracy.random_bisection
  tubes-check --scene ${TUBES_DIR}/random.json --random-segments 40 --seed 4 --set params.root_method=bisection)
tubes_render_test(accuracy.random_bisection_stress
  tubes-check --scene ${TUBES_DIR}/stress_big_radius.json --set params.root_method=bisection)
tubes_render_test(accuracy.random_no_culling
  tubes-check --scene ${TUBES_DIR}/random.json --random-segments 40 --seed 5 --set params.frustum_culling=false)
tubes_render_test(accuracy.random_close
  tubes-check --scene ${TUBES_DIR}/random.json --random-segments 40 --seed 6 --set camera.orbit.distance=0.6)
# Both proxies of a box: always one screen rectangle (every box "small") and
# always the box faces of the paper; coverage is the fragment shader's either way.
tubes_render_test(accuracy.random_all_rectangles
  tubes-check --scene ${TUBES_DIR}/random.json --random-segments 40 --seed 7 --set params.small_box_pixels=65536)
tubes_render_test(accuracy.random_all_faces
  tubes-check --scene ${TUBES_DIR}/random.json --random-segments 40 --seed 7 --set params.small_box_pixels=0)
tubes_render_test(accuracy.stress_inside_rectangles
  tubes-check --scene ${TUBES_DIR}/stress_inside.json --set params.small_box_pixels=65536)
tubes_render_test(accuracy.stress_grazing_rectangles
  tubes-check --scene ${TUBES_DIR}/stress_grazing.json --set params.small_box_pixels=65536)
# Thin tubes (segment length / radius up to ~300) seen from inside the set:
# the case where an expanded quartic g would lose the bound to cancellation.
tubes_render_test(accuracy.random_thin_close
  tubes-check --scene ${TUBES_DIR}/random.json --random-segments 40 --seed 9 --set params.radius_scale=0.15
  --set camera.orbit.distance=0.5)

# Numerical stress scenes and the golden-image scenes, each against the reference.
foreach(name stress_zero_length stress_zero_tangents stress_collinear stress_radius_zero_end stress_big_radius
             stress_offset stress_grazing stress_inside bifurcation sharp_corner varying_radius)
  tubes_render_test(accuracy.${name} tubes-check --scene ${TUBES_DIR}/${name}.json)
endforeach()

# The command-line path of the issue: sightline-render --depth, then the
# reference (tubes-check --gpu-depth) and sightline-diff on the two PFMs
# (absolute bound 1e-3 x the radius 0.01; 0.5 % bad / coverage allowance).
tubes_render_test(accuracy.tornado_cli
  ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:sightline-render>|--scene|${TUBES_DIR}/tornado.json|--out|${TUBES_OUT}/tornado.png|--depth|${TUBES_OUT}/tornado_gpu.pfm|--samples|1"
  "-DSTEP2=$<TARGET_FILE:tubes-check>|--scene|${TUBES_DIR}/tornado.json|--gpu-depth|${TUBES_OUT}/tornado_gpu.pfm|--out-ref|${TUBES_OUT}/tornado_ref.pfm"
  "-DSTEP3=$<TARGET_FILE:sightline-diff>|${TUBES_OUT}/tornado_gpu.pfm|${TUBES_OUT}/tornado_ref.pfm|--bad-threshold|1e-5|--max-bad-pct|0.5|--max-coverage-pct|0.5"
  -P ${TUBES_DIR}/run_steps.cmake)

# The same with data radii (1.2-2.5 x the segment length, smallest ~0.024):
# absolute bound 1e-3 x 0.024 for sightline-diff; tubes-check uses the local radius.
tubes_render_test(accuracy.hotroom_cli
  ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:sightline-render>|--scene|${TUBES_DIR}/hotroom.json|--out|${TUBES_OUT}/hotroom.png|--depth|${TUBES_OUT}/hotroom_gpu.pfm|--samples|1"
  "-DSTEP2=$<TARGET_FILE:tubes-check>|--scene|${TUBES_DIR}/hotroom.json|--gpu-depth|${TUBES_OUT}/hotroom_gpu.pfm|--out-ref|${TUBES_OUT}/hotroom_ref.pfm"
  "-DSTEP3=$<TARGET_FILE:sightline-diff>|${TUBES_OUT}/hotroom_gpu.pfm|${TUBES_OUT}/hotroom_ref.pfm|--bad-threshold|2.4e-5|--max-bad-pct|0.5|--max-coverage-pct|0.5"
  -P ${TUBES_DIR}/run_steps.cmake)

# Golden images (128x128, llvmpipe): mean colour difference <= 1 and at most
# 0.5 % of pixels off by more than 8 (of 255). Regenerate with
#   tubes-check --scene S.json --out-png tests/render/tubes/golden/S.png
foreach(name bifurcation sharp_corner varying_radius)
  tubes_render_test(golden.${name}
    ${CMAKE_COMMAND}
    "-DSTEP1=$<TARGET_FILE:tubes-check>|--scene|${TUBES_DIR}/${name}.json|--out-png|${TUBES_OUT}/${name}.png"
    "-DSTEP2=$<TARGET_FILE:sightline-diff>|${TUBES_OUT}/${name}.png|${TUBES_DIR}/golden/${name}.png|--max-mean|1|--max-bad-pct|0.5|--diff|${TUBES_OUT}/${name}_heat.png"
    -P ${TUBES_DIR}/run_steps.cmake)
endforeach()
