# GPU tests of `voxel_lines` and `lines_oit` (renderer/voxel_lines/, renderer/lines_oit/):
# opaque depth against tubes_mesh, transparent colour against lines_oit, and
# golden images. The check program and scenes live in tests/render/voxel_lines/.
set(VOXEL_DIR ${CMAKE_CURRENT_SOURCE_DIR}/voxel_lines)
add_executable(voxel-check ${VOXEL_DIR}/voxel_check.c)
target_link_libraries(voxel-check PRIVATE sightline_proto sightline_renderer)
set_target_properties(voxel-check PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)

function(voxel_render_test name)
  sl_add_render_test(NAME ${name} COMMAND ${ARGN})
endfunction()

# Opaque depth vs tubes_mesh (24 sides, no caps), tornado 150 lines, radius 0.4 %
# of the bounding radius, grid 64, N = 256 (quantization far below the radius).
voxel_render_test(voxel_lines.depth_vs_tubes_mesh
  voxel-check depth --size 128 --grid 64 --quant 256 --tol-median 0.05 --tol-p95 0.3 --max-mismatch-pct 8)

# Transparent colour vs lines_oit at 25 % opacity (same lines, radius, shading,
# constant colour), also with alpha termination at 0.5 in both and with the
# opacity ramp, plus the lines_oit overflow marking (Fig. 17). Statistics over
# the ~2850 covered pixels (of 16384): max-channel |diff| mean <= 3.5 and p99
# <= 35 (measured 2.76 / 29, ramp 1.66 / 16). The former limits averaged over
# all pixels (mean 1.5 ~ 8.6 per covered pixel; p99 of all pixels ~ p94 of the
# covered ones).
voxel_render_test(voxel_lines.transparent_vs_lines_oit
  voxel-check oit --size 128 --grid 64 --quant 256 --opacity 0.25 --tol-mean 3.5 --tol-p99 35)

# tubes_mesh `opacity`: 1 is the opaque frame bit for bit; 25 % (unsorted
# blending of the front halves) is fainter and close to the sorted lines_oit
# frame over covered pixels (same limits as above; measured 2.92 / 27).
voxel_render_test(voxel_lines.tubes_mesh_opacity
  voxel-check tubes --size 128 --grid 64 --quant 256 --opacity 0.25 --tol-mean 3.5 --tol-p99 35)

# The compute-shader voxelization equals the CPU one (headers, packed lines
# including the attribute byte, caps, density), without and with a colour
# attribute (tornado speed, bundle curvature / radial, hostile values), with
# dispatches chunked to 7 and 1 work groups (test-only limit), and at grid 184
# (4.3 M voxels: above one dispatch of 65535 groups x 64 on llvmpipe).
add_executable(voxel-gpu-build ${VOXEL_DIR}/voxel_gpu_build.c)
target_include_directories(voxel-gpu-build PRIVATE ${CMAKE_SOURCE_DIR}/tests/unit)
target_link_libraries(voxel-gpu-build PRIVATE sightline_proto sightline_renderer)
set_target_properties(voxel-gpu-build PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
voxel_render_test(voxel_lines.gpu_build_equals_cpu voxel-gpu-build)

# End to end: the transparent scene coloured by tornado speed (attribute 0),
# voxelized on the GPU (no CPU fallback) and on the CPU: identical frames.
voxel_render_test(voxel_lines.gpu_build_colour_image
  sh -c "$<TARGET_FILE:sightline-render> --scene ${VOXEL_DIR}/transparent.json --out ${SL_RENDER_OUT}/voxel_colour_cpu.png --samples 1 --set params.attribute=0 --set params.voxelize=cpu && $<TARGET_FILE:sightline-render> --scene ${VOXEL_DIR}/transparent.json --out ${SL_RENDER_OUT}/voxel_colour_gpu.png --samples 1 --set params.attribute=0 --set params.voxelize=gpu && $<TARGET_FILE:sightline-diff> ${SL_RENDER_OUT}/voxel_colour_cpu.png ${SL_RENDER_OUT}/voxel_colour_gpu.png --max-abs 0")

# Empty-space skipping changes nothing (also at grid 4, with fewer occupancy
# levels); full-strength shadows (soft, lines, shadow_lod 2) and AO darken;
# opacity_by_distance, alpha_threshold (bounded change), the ramp's alpha
# termination at opacity 1, neighbors = auto per frame quality, and shadows/AO
# weighted by the opacity transfer function (voxel_check.c, check_effects_more).
voxel_render_test(voxel_lines.effects
  voxel-check effects --size 128 --grid 64 --quant 32 --radius 0.008)

# Work per change (voxel_lines.h counters): a camera move prepares, voxelizes
# and recomputes nothing; opacity/radius recompute AO only; the transfer
# function recomputes the density (no re-voxelization).
voxel_render_test(voxel_lines.work_skipped
  voxel-check work --size 128 --grid 64 --quant 32 --radius 0.008)

# Tubes of 1.5 voxels along the data's bounding-box edges: with 2 voxels of
# padding no tubes_mesh pixel is lost (measured 0.00 %; 2.77 % with the former
# 1-voxel padding); one-side pixels (mostly the capsules' round ends, which the
# open tubes_mesh ends lack) measured 8.38 %.
voxel_render_test(voxel_lines.edge_padding
  voxel-check edge --size 128 --quant 256 --tol-median 0.05 --tol-p95 0.3 --max-mismatch-pct 9 --max-mesh-only-pct 0.5)

# Golden images (llvmpipe, 128x128, samples 1): opaque, transparent, shadowed and
# AO voxel_lines frames, transparent with soft shadows + AO, hard shadows from
# representative lines (shadow_mode = lines, level 1), and a lines_oit frame.
# The ao golden was regenerated when ao_rays went from 64 to 100 (mean change 0.09). The suite
# tests/render/voxel_lines/goldens runs through sightline-regress: each case an expect file
# naming a scene of this folder; limits (suite.json, the ones the per-scene tests had), over
# the covered pixels (either image differs from the background, SL_GOLDEN_BACKGROUND): mean
# |diff| <= 1 and at most 0.5 % of them off by more than 8 (0..255), samples 1. After a
# deliberate change: sightline-regress tests/render/voxel_lines/goldens --update, look at the
# new goldens, and say so in the commit.
set(VOXEL_GOLDEN_LIMITS --max-mean 1 --max-bad-pct 0.5 ${SL_GOLDEN_BACKGROUND})
string(REPLACE ";" "|" VOXEL_GOLDEN_ARGS "${VOXEL_GOLDEN_LIMITS}")
file(MAKE_DIRECTORY ${SL_RENDER_OUT}/voxel_lines)
voxel_render_test(voxel_lines.goldens
  ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:sightline-regress>|${VOXEL_DIR}/goldens|--out|${SL_RENDER_OUT}/voxel_lines/goldens|--jobs|2|--junit|${SL_RENDER_OUT}/voxel_lines/goldens.xml"
  "-DOUT1=7 cases, 7 passed, 0 failed, 0 errors"
  ${SL_STEPS})
# The cpu backend (voxel_cast_cpu.c) against the same GL goldens (goldens_cpu/golden is a
# link to goldens/golden; the goldens suite pins backend=gl): one model, two executions.
# Limits mean |diff| <= 2 over the covered pixels, at most 3 % off by more than 8. Measured
# (llvmpipe, gcc -O2): mean 0.42-0.84, bad 0.63-1.55 %: shading differs by a level or two
# (float order of the same formulas), single pixels by more where a grazing ray or two
# tubes at nearly one depth decide differently.
voxel_render_test(voxel_lines.goldens_cpu
  ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:sightline-regress>|${VOXEL_DIR}/goldens_cpu|--out|${SL_RENDER_OUT}/voxel_lines/goldens_cpu|--jobs|2|--junit|${SL_RENDER_OUT}/voxel_lines/goldens_cpu.xml"
  "-DOUT1=6 cases, 6 passed, 0 failed, 0 errors"
  ${SL_STEPS})
# The backend rule (core/sl_backend.h): auto is cpu on llvmpipe, gl when asked; the frame's
# stats name the execution that drew it.
foreach(case "auto|cpu" "gl|gl" "cpu|cpu")
  string(REPLACE "|" ";" pair "${case}")
  list(GET pair 0 choice)
  list(GET pair 1 expect)
  voxel_render_test(voxel_lines.backend_${choice}
    ${CMAKE_COMMAND}
    "-DSTEP1=$<TARGET_FILE:sightline-render>|--scene|${VOXEL_DIR}/opaque.json|--set|params.backend=${choice}|--out|${SL_RENDER_OUT}/voxel_lines/backend_${choice}.png|--stats|${SL_RENDER_OUT}/voxel_lines/backend_${choice}.json"
    "-DSTEP2=${CMAKE_COMMAND}|-E|cat|${SL_RENDER_OUT}/voxel_lines/backend_${choice}.json"
    "-DOUT2=\"backend\":[ \t]*\"${expect}\""
    ${SL_STEPS})
endforeach()
# The cpu backend traces on the workers asked for (SIGHTLINE_THREADS=2) and says so.
voxel_render_test(voxel_lines.threads_cpu
  ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:sightline-render>|--scene|${VOXEL_DIR}/opaque.json|--set|params.backend=cpu|--out|${SL_RENDER_OUT}/voxel_lines/threads_cpu.png|--stats|${SL_RENDER_OUT}/voxel_lines/threads_cpu.json"
  "-DSTEP2=${CMAKE_COMMAND}|-E|cat|${SL_RENDER_OUT}/voxel_lines/threads_cpu.json"
  "-DOUT2=\"threads\":[ \t]*2,"
  ${SL_STEPS})
set_tests_properties(render.voxel_lines.threads_cpu PROPERTIES ENVIRONMENT "${SL_TEST_ENV};SIGHTLINE_THREADS=2")
# The limits catch a uniform error: +3 on every drawn pixel of the lines_oit
# golden (28 % of the frame drawn) is a covered mean of 3, over 1; over the
# whole frame it was 0.83 with no pixel over 8, and passed (step 2).
voxel_render_test(voxel_lines.golden_detects_uniform_error
  ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:golden-offset>|${VOXEL_DIR}/goldens/golden/lines_oit.png|${SL_RENDER_OUT}/voxel_lines_oit_plus3.png|26,26,31|3"
  "-DSTEP2=$<TARGET_FILE:sightline-diff>|${SL_RENDER_OUT}/voxel_lines_oit_plus3.png|${VOXEL_DIR}/goldens/golden/lines_oit.png|--max-mean|1|--max-bad-pct|0.5"
  "-DOUT2=\"pass\":[ \t]*true"
  "-DSTEP3=$<TARGET_FILE:sightline-diff>|${SL_RENDER_OUT}/voxel_lines_oit_plus3.png|${VOXEL_DIR}/goldens/golden/lines_oit.png|${VOXEL_GOLDEN_ARGS}"
  -DEXIT3=1 "-DOUT3=\"failed\":[ \t]*\\[\"max_mean\"\\]"
  ${SL_STEPS})

# Lines exactly on voxel faces, edges and corners (grid 16, N = 256) against
# tubes_mesh depth, the same data 1e6 units from the origin: same image, and the
# lattice from 400 bounding radii through a 0.25 degree lens: depth again (the
# eye-based capsule quadratics put its median 8.4 (gl) / 10.9 (cpu) radii deep there,
# now 0.020). Both backends.
foreach(backend gl cpu)
  voxel_render_test(voxel_lines.stress_faces_and_offset_${backend}
    voxel-check stress --size 128 --quant 256 --tol-median 0.03 --tol-p95 0.15 --max-mismatch-pct 5
    --backend ${backend})
endforeach()

# The far eye of far_eye.json (tornado from 40 bounding radii, 2.5 degree lens) against
# tubes_mesh, both backends: max-channel |diff| mean over the covered pixels <= 8
# (measured 4.20 cpu, 4.19 gl; 52.4 / 53.8 with the quadratics solved from the eye).
foreach(backend cpu gl)
  voxel_render_test(voxel_lines.far_eye_${backend}_vs_tubes_mesh
    ${CMAKE_COMMAND}
    "-DSTEP1=$<TARGET_FILE:sightline-render>|--scene|${VOXEL_DIR}/far_eye.json|--samples|1|--set|technique=tubes_mesh|--out|${SL_RENDER_OUT}/voxel_lines/far_eye_mesh_${backend}.png"
    "-DSTEP2=$<TARGET_FILE:sightline-render>|--scene|${VOXEL_DIR}/far_eye.json|--samples|1|--set|params.backend=\"${backend}\"|--out|${SL_RENDER_OUT}/voxel_lines/far_eye_${backend}.png"
    "-DSTEP3=$<TARGET_FILE:sightline-diff>|${SL_RENDER_OUT}/voxel_lines/far_eye_${backend}.png|${SL_RENDER_OUT}/voxel_lines/far_eye_mesh_${backend}.png|--background|26,26,31|--max-mean|8"
    ${SL_STEPS})
endforeach()

# Lines beyond the per-voxel cap are counted in sightline-render --stats
# (`dropped`), not only on stderr: a cap of 1 line per voxel on the opaque
# scene drops some, the default cap none.
foreach(case "1;some" "255;none")
  list(GET case 0 cap)
  list(GET case 1 expect)
  voxel_render_test(voxel_lines.stats_dropped_cap${cap}
    ${CMAKE_COMMAND} -DRENDER=$<TARGET_FILE:sightline-render> -DSCENE=${VOXEL_DIR}/opaque.json
    -DOUT=${SL_RENDER_OUT} -DCAP=${cap} -DEXPECT=${expect} -P ${VOXEL_DIR}/stats_dropped.cmake)
endforeach()

# The cpu backend's work counter in --stats: the voxels its rays stepped through
# (ray_samples), fewer with empty-space skipping than without (tests/stats_skipping.cmake).
voxel_render_test(voxel_lines.stats_samples_cpu
  ${CMAKE_COMMAND} -DRENDER=$<TARGET_FILE:sightline-render> -DSCENE=${VOXEL_DIR}/opaque.json
  -DOUT=${SL_RENDER_OUT} -DNAME=voxel_samples_cpu -DSET=params.backend=cpu
  -P ${CMAKE_SOURCE_DIR}/tests/stats_skipping.cmake)

# Transparent compositing against the exact CPU reference
# (tests/support/lines_reference.h: every maximal interval of a ray inside a
# polyline's capsule-union tube blended once at its entry, all crossings
# sorted), each polyline its own colour, opacity 0.6 (transparency_check.c).
add_executable(transparency-check ${VOXEL_DIR}/transparency_check.c)
target_link_libraries(transparency-check PRIVATE sightline_test_support sightline_renderer)
set_target_properties(transparency-check PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
# Two families per dataset, on real tracts (dipy's minimal bundles, sub_1,
# from scripts/fetch-sample-data; exit 77 = skipped when absent) and on
# generated ones (bundle, tornado), 320x240 (real) / 256x192 (generated),
# orbit 40/25/1.6, grid 64, N = 32:
# * order: opacity 0.6, each polyline its own colour, lit. voxel_lines and
#   lines_oit: max-channel |diff| mean <= 8, p99 <= 90 (measured voxel 2.9-6.9
#   / 40-78, mostly where curves end: the voxel model drops a curve's pieces
#   before its first and after its last face crossing; lines_oit 0.9-5.5).
#   Unsorted blending (tubes_mesh opacity 0.6) must fail them (measured mean
#   17-38): the old single-colour 25 % comparison passed it.
# * crossings: opacity 0.05, white, ambient only, so a pixel tells how many
#   tube crossings it blended: mean |dN| <= 0.5 (measured voxel 0.12-0.21,
#   lines_oit 0.24-0.39). Before the fix voxel_lines lost 1.6 crossings per
#   pixel on AF_L (local ids repeated every 32 curves merged overlapping tubes
#   of two curves; the 16-hit pending list overflowed) or, with those fixed
#   alone, blended 1-5 too many (the 8-slot joint memory forgot open tubes).
set(VOXEL_TRACTS ${CMAKE_SOURCE_DIR}/data/samples/minimal_bundles/sub_1)
set(VOXEL_ORDER --opacity 0.6 --technique voxel_lines --technique lines_oit --expect-fail tubes_mesh
  --grid 64 --quant 32 --tol-mean 8 --tol-p99 90)
set(VOXEL_CROSSINGS --opacity 0.05 --flat on --colors off --technique voxel_lines --technique lines_oit
  --grid 64 --quant 32 --tol-crossings 0.5 --tol-mean 4 --tol-p99 40)
foreach(tract AF_L CC_ForcepsMajor CST_R)
  voxel_render_test(voxel_lines.transparency_order.${tract}
    transparency-check --data ${VOXEL_TRACTS}/${tract}.trk --radius 2 ${VOXEL_ORDER})
  voxel_render_test(voxel_lines.transparency_crossings.${tract}
    transparency-check --data ${VOXEL_TRACTS}/${tract}.trk --radius 2 ${VOXEL_CROSSINGS})
  set_tests_properties(render.voxel_lines.transparency_order.${tract} render.voxel_lines.transparency_crossings.${tract}
    PROPERTIES SKIP_RETURN_CODE 77)
endforeach()
# Issue 30: voxel_lines against lines_oit on a dense real tract (CC_ForcepsMajor, 25 %,
# radius 2, 320x240, orbit 40/25/1.6, sightline-render's default 4 MSAA samples), white
# and black background, both backends: max-channel |diff| mean over the covered pixels
# <= 6. lines_oit at 30 sides (its 8-sided polygon alone is 6.8 from the exact open tube,
# 30 sides 4.3). Measured 5.34 white / 4.77 black (cpu = gl); before lines_oit collected
# its lists with GL_MULTISAMPLE off (one node per pixel centre), MSAA stored two nodes per
# crossing on every inner mesh edge: 11.88 / 10.82 with 8 sides, 18.25 / 20.53 with 30.
# lines_oit's MSAA frame must equal its single-sample frame.
set(VOXEL_CC_SCENE ${VOXEL_DIR}/cc_forceps_transparent.json)
if(EXISTS ${VOXEL_TRACTS}/CC_ForcepsMajor.trk)
  set(cc_out ${SL_RENDER_OUT}/voxel_lines/cc)
  file(MAKE_DIRECTORY ${cc_out})
  set(cc_render $<TARGET_FILE:sightline-render>|--scene|${VOXEL_CC_SCENE}|--data-dir|${VOXEL_TRACTS})
  foreach(bg "white|1,1,1|255,255,255" "black|0,0,0|0,0,0")
    string(REPLACE "|" ";" bgl "${bg}")
    list(GET bgl 0 bgname)
    list(GET bgl 1 bgrgb)
    list(GET bgl 2 bg255)
    foreach(backend cpu gl)
      voxel_render_test(voxel_lines.vs_lines_oit_cc_${bgname}_${backend}
        ${CMAKE_COMMAND}
        "-DSTEP1=${cc_render}|--set|background=[${bgrgb},1]|--set|technique=lines_oit|--set|params.sides=30|--out|${cc_out}/oit_${bgname}_${backend}.png"
        "-DSTEP2=${cc_render}|--set|background=[${bgrgb},1]|--set|params.backend=\"${backend}\"|--out|${cc_out}/voxel_${bgname}_${backend}.png"
        "-DSTEP3=$<TARGET_FILE:sightline-diff>|${cc_out}/voxel_${bgname}_${backend}.png|${cc_out}/oit_${bgname}_${backend}.png|--background|${bg255}|--max-mean|6"
        ${SL_STEPS})
    endforeach()
  endforeach()
  voxel_render_test(voxel_lines.lines_oit_msaa_equals_single
    ${CMAKE_COMMAND}
    "-DSTEP1=${cc_render}|--set|technique=lines_oit|--samples|4|--out|${cc_out}/oit_msaa4.png"
    "-DSTEP2=${cc_render}|--set|technique=lines_oit|--samples|1|--out|${cc_out}/oit_msaa1.png"
    "-DSTEP3=$<TARGET_FILE:sightline-diff>|${cc_out}/oit_msaa4.png|${cc_out}/oit_msaa1.png|--max-abs|0"
    ${SL_STEPS})
endif()
set(VOXEL_GEN_bundle "{\"generator\":\"bundle\",\"lines\":120,\"seed\":1}")
set(VOXEL_GEN_tornado "{\"generator\":\"tornado\",\"lines\":150,\"seed\":3}")
foreach(gen bundle tornado)
  voxel_render_test(voxel_lines.transparency_order.${gen}
    transparency-check --data ${VOXEL_GEN_${gen}} --radius-frac 0.012 --size 256x192 ${VOXEL_ORDER})
  voxel_render_test(voxel_lines.transparency_crossings.${gen}
    transparency-check --data ${VOXEL_GEN_${gen}} --radius-frac 0.012 --size 256x192 ${VOXEL_CROSSINGS})
endforeach()
