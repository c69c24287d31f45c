# Tests of `ribbons` (renderer/ribbons/, issue 13). First the halo and
# twist-line shader functions on the GPU (ribbons_probe.comp.glsl) against the
# CPU references of tests/support/ribbons_reference.h, then the render tests.
set(RIBBONS_DIR ${CMAKE_CURRENT_SOURCE_DIR}/ribbons)
add_executable(test_ribbons_halo ${RIBBONS_DIR}/test_ribbons_halo.c)
target_include_directories(test_ribbons_halo PRIVATE ${CMAKE_SOURCE_DIR}/tests/unit)
target_link_libraries(test_ribbons_halo PRIVATE sightline_test_support sightline_proto sightline_renderer)
set_target_properties(test_ribbons_halo PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
add_test(NAME unit.test_ribbons_halo COMMAND ${SL_TEST_RUN} $<TARGET_FILE:test_ribbons_halo>
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(unit.test_ribbons_halo PROPERTIES ENVIRONMENT "${SL_TEST_ENV}" TIMEOUT 300)

# Render tests of the technique (plan §4.3): smoke, min_pixels edge-on, culling,
# width_ratio 1 against tubes_mesh, stress scenes, goldens, halos (on the
# silhouette; none with the camera inside), twist-line width. Scenes and the
# small VTK files are in tests/render/ribbons/ (the VTK files were written once
# by a few lines of Python: straight and receding edge-on ribbons with data
# normals z, stress.vtk, a helix at the origin and at 1e5). The step runner is
# tests/steps.cmake (SL_STEPS); tests that expect a failure name the exit code
# and the failure line. ribbons-check (ribbons/ribbons_check.c) counts the
# thickness of an edge-on ribbon; tubes-mesh-check image is technique-agnostic.
set(RB_OUT ${SL_RENDER_OUT}/ribbons)
file(MAKE_DIRECTORY ${RB_OUT})
add_executable(ribbons-check ${RIBBONS_DIR}/ribbons_check.c)
target_link_libraries(ribbons-check PRIVATE sightline_renderer)
set_target_properties(ribbons-check PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
set(RB_RENDER $<TARGET_FILE:sightline-render>)
set(RB_DIFF $<TARGET_FILE:sightline-diff>)
set(RB_CHECK $<TARGET_FILE:ribbons-check>)
set(RB_IMAGE $<TARGET_FILE:tubes-mesh-check>|image)
set(RB_GOLDEN_LIMITS --max-mean 0.5 --max-bad-pct 0.5 --bad-threshold 16 ${SL_GOLDEN_BACKGROUND})
string(REPLACE ";" "|" RB_GOLDEN_ARGS "${RB_GOLDEN_LIMITS}")

function(rb_test name)
  sl_add_render_test(NAME ribbons.${name} COMMAND ${ARGN})
endfunction()

# ---- smoke: frame not all background, depth finite, in range, drawn.
foreach(scene tornado abc)
  if(scene STREQUAL "abc")
    set(pct 3)  # 30 thin lines in a big box: 6.2 % colour, 4.5 % hits measured
  else()
    set(pct 10)
  endif()
  rb_test(smoke.${scene} ${CMAKE_COMMAND}
    "-DSTEP1=${RB_RENDER}|--scene|${RIBBONS_DIR}/${scene}.json|--out|${RB_OUT}/smoke_${scene}.png|--depth|${RB_OUT}/smoke_${scene}.pfm"
    "-DSTEP2=${RB_IMAGE}|--scene|${RIBBONS_DIR}/${scene}.json|--png|${RB_OUT}/smoke_${scene}.png|--depth|${RB_OUT}/smoke_${scene}.pfm|--min-color-pct|${pct}|--min-hit-pct|${pct}"
    ${SL_STEPS})
endforeach()

# ---- min_pixels (plan §1.2): width_ratio = min_thickness = 0, so without
# min_pixels the ribbon is 2 r 1e-3 thick (0.005 px near, less far). Seen
# exactly edge-on, every column over 90 % of its length shows >= X pixels
# (--samples 1). Straight (distance 3) and receding (distance 1.5 .. 6).
# The receding ribbon's width axis b lies in the view plane, so past the axis'
# near end the ellipse's flank (thickness r w' cos(phi) -> 0) shows for ~8 of
# its ~103 columns; there the middle 80 % is checked (--span 0.8).
foreach(scene straight receding)
  if(scene STREQUAL "receding")
    set(span 0.8)
  else()
    set(span 0.9)
  endif()
  foreach(px 1 2 3)
    rb_test(min_pixels.${scene}_${px} ${CMAKE_COMMAND}
      "-DSTEP1=${RB_RENDER}|--scene|${RIBBONS_DIR}/edge_${scene}.json|--out|${RB_OUT}/edge_${scene}_${px}.png|--samples|1|--set|params.min_pixels=${px}"
      "-DSTEP2=${RB_CHECK}|edge_on|--png|${RB_OUT}/edge_${scene}_${px}.png|--min-pixels|${px}|--span|${span}"
      ${SL_STEPS})
  endforeach()
  # The check can fail: min_pixels 0 leaves the edge-on ribbon below a pixel.
  rb_test(min_pixels.${scene}_detects_off ${CMAKE_COMMAND}
    "-DSTEP1=${RB_RENDER}|--scene|${RIBBONS_DIR}/edge_${scene}.json|--out|${RB_OUT}/edge_${scene}_0.png|--samples|1|--set|params.min_pixels=0"
    "-DSTEP2=${RB_CHECK}|edge_on|--png|${RB_OUT}/edge_${scene}_0.png|--min-pixels|1|--span|${span}"
    -DEXIT2=1 "-DERR2=FAIL: (column [0-9]+ is [0-9]+ px thick, below 1|nothing drawn)"
    ${SL_STEPS})
endforeach()

# ---- frustum culling: a close-up of tornado culls chunks (stats culled > 0)
# and gives the same image as drawing every chunk (exactly: the draw order is
# the same front-to-back sort either way).
rb_test(culling.same_image ${CMAKE_COMMAND}
  "-DSTEP1=${RB_RENDER}|--scene|${RIBBONS_DIR}/tornado.json|--out|${RB_OUT}/cull_on.png|--depth|${RB_OUT}/cull_on.pfm|--set|camera.orbit.distance=0.45|--stats|${RB_OUT}/cull_on.json"
  "-DSTEP2=${RB_RENDER}|--scene|${RIBBONS_DIR}/tornado.json|--out|${RB_OUT}/cull_off.png|--depth|${RB_OUT}/cull_off.pfm|--set|camera.orbit.distance=0.45|--set|params.frustum_culling=false"
  "-DSTEP3=${RB_DIFF}|${RB_OUT}/cull_on.png|${RB_OUT}/cull_off.png|--max-abs|0"
  "-DSTEP4=${RB_DIFF}|${RB_OUT}/cull_on.pfm|${RB_OUT}/cull_off.pfm|--max-abs|0"
  "-DSTEP5=${CMAKE_COMMAND}|-E|cat|${RB_OUT}/cull_on.json"
  "-DOUT5=\"culled\":[ \t]*[1-9]"
  ${SL_STEPS})

# ---- width_ratio 1 is a circular tube: depth against tubes_mesh (same sides,
# same transport frame) within the tessellation bound 2 r (1 - cos(pi/N)) of
# bench-tubes-mesh (x2 for incidence), N = 8, r = 0.1: 0.0152. The twin with
# width_ratio 0.7 must fail (its thin axis is 0.03 off).
set(RB_W1 --set technique=ribbons --set params.width_ratio=1 --set params.min_thickness=0 --set params.min_pixels=0 --set params.halo=false --set params.frame=transport --set params.sides=8)
string(REPLACE ";" "|" RB_W1 "${RB_W1}")
rb_test(accuracy.w1_vs_tubes_mesh ${CMAKE_COMMAND}
  "-DSTEP1=${RB_RENDER}|--scene|${RIBBONS_DIR}/tube_oblique.json|--out|${RB_OUT}/w1.png|--depth|${RB_OUT}/w1.pfm|${RB_W1}"
  "-DSTEP2=${RB_RENDER}|--scene|${RIBBONS_DIR}/tube_oblique.json|--out|${RB_OUT}/w1_tm.png|--depth|${RB_OUT}/w1_tm.pfm|--set|technique=tubes_mesh|--set|params.sides=8"
  "-DSTEP3=${RB_DIFF}|${RB_OUT}/w1.pfm|${RB_OUT}/w1_tm.pfm|--bad-threshold|0.0152|--max-bad-pct|0.5|--max-coverage-pct|1"
  ${SL_STEPS})
# The helix (150 segments: 3 chunks of <= 64) checks the chunk seams and
# basevertex the same way: a wrong gl_VertexID base would tear the tube apart.
rb_test(accuracy.w1_vs_tubes_mesh_chunks ${CMAKE_COMMAND}
  "-DSTEP1=${RB_RENDER}|--scene|${RIBBONS_DIR}/goldens/helix.json|--out|${RB_OUT}/w1h.png|--depth|${RB_OUT}/w1h.pfm|${RB_W1}|--set|params.radius=0.06|--set|params.twist_lines=0"
  "-DSTEP2=${RB_RENDER}|--scene|${RIBBONS_DIR}/goldens/helix.json|--out|${RB_OUT}/w1h_tm.png|--depth|${RB_OUT}/w1h_tm.pfm|--set|technique=tubes_mesh|--set|params={\"radius\":0.06,\"sides\":8,\"attribute\":1}"
  "-DSTEP3=${RB_DIFF}|${RB_OUT}/w1h.pfm|${RB_OUT}/w1h_tm.pfm|--bad-threshold|0.0092|--max-bad-pct|0.5|--max-coverage-pct|1"
  ${SL_STEPS})
rb_test(accuracy.w1_detects_thin ${CMAKE_COMMAND}
  "-DSTEP1=${RB_RENDER}|--scene|${RIBBONS_DIR}/tube_oblique.json|--out|${RB_OUT}/w07.png|--depth|${RB_OUT}/w07.pfm|${RB_W1}|--set|params.width_ratio=0.7"
  "-DSTEP2=${RB_RENDER}|--scene|${RIBBONS_DIR}/tube_oblique.json|--out|${RB_OUT}/w07_tm.png|--depth|${RB_OUT}/w07_tm.pfm|--set|technique=tubes_mesh|--set|params.sides=8"
  "-DSTEP3=${RB_DIFF}|${RB_OUT}/w07.pfm|${RB_OUT}/w07_tm.pfm|--bad-threshold|0.0152|--max-bad-pct|0.5|--max-coverage-pct|1"
  -DEXIT3=1 "-DOUT3=\"pass\":[ \t]*false"
  ${SL_STEPS})

# ---- stress: degenerate lines (stress.vtk) draw without crash or NaN; a helix
# at 1e5 from the origin gives the frame and depth of the one at the origin
# (positions relative to the dataset origin; orbit cameras give the same view).
rb_test(stress.degenerate ${CMAKE_COMMAND}
  "-DSTEP1=${RB_RENDER}|--scene|${RIBBONS_DIR}/stress.json|--out|${RB_OUT}/stress.png|--depth|${RB_OUT}/stress.pfm"
  "-DSTEP2=${RB_IMAGE}|--scene|${RIBBONS_DIR}/stress.json|--png|${RB_OUT}/stress.png|--depth|${RB_OUT}/stress.pfm|--min-color-pct|3|--min-hit-pct|3"
  ${SL_STEPS})
rb_test(stress.transport_frame ${CMAKE_COMMAND}
  "-DSTEP1=${RB_RENDER}|--scene|${RIBBONS_DIR}/stress.json|--out|${RB_OUT}/stress_t.png|--depth|${RB_OUT}/stress_t.pfm|--set|params.frame=transport|--set|params.halo_space=screen"
  "-DSTEP2=${RB_IMAGE}|--scene|${RIBBONS_DIR}/stress.json|--png|${RB_OUT}/stress_t.png|--depth|${RB_OUT}/stress_t.pfm|--min-color-pct|3|--min-hit-pct|3"
  ${SL_STEPS})
rb_test(stress.offset_1e5 ${CMAKE_COMMAND}
  "-DSTEP1=${RB_RENDER}|--scene|${RIBBONS_DIR}/goldens/helix.json|--out|${RB_OUT}/off_0.png|--depth|${RB_OUT}/off_0.pfm"
  "-DSTEP2=${RB_RENDER}|--scene|${RIBBONS_DIR}/helix_1e5.json|--out|${RB_OUT}/off_1.png|--depth|${RB_OUT}/off_1.pfm"
  "-DSTEP3=${RB_IMAGE}|--scene|${RIBBONS_DIR}/helix_1e5.json|--png|${RB_OUT}/off_1.png|--depth|${RB_OUT}/off_1.pfm|--min-color-pct|3|--min-hit-pct|3"
  "-DSTEP4=${RB_DIFF}|${RB_OUT}/off_0.png|${RB_OUT}/off_1.png|${RB_GOLDEN_ARGS}"
  "-DSTEP5=${RB_DIFF}|${RB_OUT}/off_0.pfm|${RB_OUT}/off_1.pfm|--bad-threshold|1e-4|--max-bad-pct|0.5|--max-coverage-pct|0.5"
  ${SL_STEPS})

# ---- goldens: the suite tests/render/ribbons/goldens/ through sightline-regress
# (sightline-render defaults, 4x MSAA, 128x128; limits of the built-in
# defaults: mean 0.5 and 0.5 % of pixels over 16 on the covered pixels): the
# helix in the helicity frame with 3 twist lines and halos, an S-curve ribbon
# lying in z = 0 seen edge-on (it stays a band, min_thickness 0.15) and
# face-on, and a bifurcation (a trunk and two branches leaving its end point;
# s_curve.vtk and bifurcation.vtk were written by a few lines of Python).
# After a deliberate change: sightline-regress tests/render/ribbons/goldens
# --update, look at the new goldens, and say so in the commit.
set(RB_REGRESS $<TARGET_FILE:sightline-regress>)
rb_test(goldens ${CMAKE_COMMAND}
  "-DSTEP1=${RB_REGRESS}|${RIBBONS_DIR}/goldens|--out|${RB_OUT}/goldens|--jobs|2|--junit|${RB_OUT}/goldens.xml"
  "-DOUT1=4 cases, 4 passed, 0 failed, 0 errors"
  ${SL_STEPS})
# The limits catch +5 on every drawn pixel of a golden (covered mean 5 > 0.5).
rb_test(golden.detects_uniform_error ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:golden-offset>|${RIBBONS_DIR}/goldens/golden/helix.png|${RB_OUT}/golden_plus5.png|26,26,31|5"
  "-DSTEP2=${RB_DIFF}|${RB_OUT}/golden_plus5.png|${RIBBONS_DIR}/goldens/golden/helix.png|${RB_GOLDEN_ARGS}"
  -DEXIT2=1 "-DOUT2=\"failed\":[ \t]*\\[\"max_mean\"\\]"
  ${SL_STEPS})

# ---- halos (§3.2): red screen-space halos 2 px wide on a side-on ribbon
# (--samples 1). Every silhouette end of every column has a red pixel within
# 1 px and no red pixel is more than 4 px inside the outline. Twins: halo off
# (no outline: fails the first half) and halo_width 40 px (red fills the
# ribbon: fails the second half).
function(rb_halo name expect_exit err)
  string(REPLACE ";" "|" sets "${ARGN}")
  if(sets)
    set(sets "|${sets}")
  endif()
  set(extra)
  if(NOT expect_exit EQUAL 0)
    set(extra -DEXIT2=${expect_exit} "-DERR2=${err}")
  endif()
  rb_test(halo.${name} ${CMAKE_COMMAND}
    "-DSTEP1=${RB_RENDER}|--scene|${RIBBONS_DIR}/halo_side.json|--out|${RB_OUT}/halo_${name}.png|--samples|1${sets}"
    "-DSTEP2=${RB_CHECK}|halo|--png|${RB_OUT}/halo_${name}.png|--max-dist|4"
    ${extra} ${SL_STEPS})
endfunction()
rb_halo(on_silhouette 0 "")
rb_halo(detects_off 1 "FAIL: column [0-9]+ has a silhouette end without halo" --set params.halo=false)
rb_halo(detects_inside 1 "FAIL: [0-9]+ halo pixels inside the ribbon" --set params.halo_width=40)

# ---- camera inside a ribbon's elliptic cylinder (plan §1.4): no silhouette,
# so no halo at all. halo_inside.json puts the eye 0.145 from the axis of a
# circular ribbon (r 0.15, 8 sides) across a facet's middle: outside the
# octagon, so that facet is drawn (> 5 % of the frame), but inside the true
# circle. Depth stays finite and in range. The twin 0.16 from the axis
# (outside the circle) must show red halo pixels on the facet's edges.
rb_test(halo.inside_no_halo ${CMAKE_COMMAND}
  "-DSTEP1=${RB_RENDER}|--scene|${RIBBONS_DIR}/halo_inside.json|--out|${RB_OUT}/halo_inside.png|--depth|${RB_OUT}/halo_inside.pfm|--samples|1"
  "-DSTEP2=${RB_CHECK}|count|--png|${RB_OUT}/halo_inside.png|--min-covered-pct|5|--max-halo|0"
  "-DSTEP3=${RB_IMAGE}|--scene|${RIBBONS_DIR}/halo_inside.json|--png|${RB_OUT}/halo_inside.png|--depth|${RB_OUT}/halo_inside.pfm|--min-color-pct|5|--min-hit-pct|5"
  ${SL_STEPS})
rb_test(halo.inside_detects_outside ${CMAKE_COMMAND}
  "-DSTEP1=${RB_RENDER}|--scene|${RIBBONS_DIR}/halo_inside.json|--out|${RB_OUT}/halo_outside.png|--samples|1|--set|camera.eye=[-0.9,-0.061229,0.147821]"
  "-DSTEP2=${RB_CHECK}|count|--png|${RB_OUT}/halo_outside.png|--min-covered-pct|5|--max-halo|0"
  -DEXIT2=1 "-DERR2=FAIL: [0-9]+ halo pixels, outside \\[0, 0\\]"
  ${SL_STEPS})

# ---- twist-line width correction (paper Eq. 6-7, plan §1.5): a straight
# circular ribbon side-on (twist_width.json: r 0.4, eye 5 r from the axis,
# helicity 1, 3 stripes of w_r 0.4 rad) with twist_scale f = tan(alpha) / (r h)
# for stripe angles alpha = 0, 45 and 70 degrees to the axis. ribbons-check
# twist_width maps each column back to angles on the circle and requires the
# stripes' width across themselves, w_u cos(alpha), to be w_r within 5 %
# (measured 0.393, 0.397, 0.397 for 0.4). Without the correction the stripes
# would be w_r cos(alpha) across (0.137 at 70 degrees); the twin judges the
# 70-degree image as if alpha were 0 and must fail.
set(RB_TWIST_REF ${RB_RENDER}|--scene|${RIBBONS_DIR}/twist_width.json|--samples|1|--set|params.twist_lines=0|--out)
set(RB_TWIST_CHECK ${RB_CHECK}|twist_width|--axis-distance|5|--fov-deg|45|--width|0.4|--span|0.8)
foreach(case "0;0" "45;2.5" "70;6.8686935")
  list(GET case 0 alpha)
  list(GET case 1 scale)
  rb_test(twist.width_${alpha} ${CMAKE_COMMAND}
    "-DSTEP1=${RB_TWIST_REF}|${RB_OUT}/twist_ref_${alpha}.png"
    "-DSTEP2=${RB_RENDER}|--scene|${RIBBONS_DIR}/twist_width.json|--out|${RB_OUT}/twist_${alpha}.png|--samples|1|--set|params.twist_scale=${scale}"
    "-DSTEP3=${RB_TWIST_CHECK}|--png|${RB_OUT}/twist_${alpha}.png|--reference|${RB_OUT}/twist_ref_${alpha}.png|--alpha-deg|${alpha}"
    ${SL_STEPS})
endforeach()
rb_test(twist.detects_uncorrected ${CMAKE_COMMAND}
  "-DSTEP1=${RB_TWIST_REF}|${RB_OUT}/twist_ref_70_as_0.png"
  "-DSTEP2=${RB_RENDER}|--scene|${RIBBONS_DIR}/twist_width.json|--out|${RB_OUT}/twist_70_as_0.png|--samples|1|--set|params.twist_scale=6.8686935"
  "-DSTEP3=${RB_TWIST_CHECK}|--png|${RB_OUT}/twist_70_as_0.png|--reference|${RB_OUT}/twist_ref_70_as_0.png|--alpha-deg|0"
  -DEXIT3=1 "-DERR3=FAIL: stripe width [0-9.]+, want 0.4000"
  ${SL_STEPS})
# ===============================================================# ---- pipelines (plan §3.3): geometry, mesh and flat against pulling.
# Same image: geometry-shader extrusion and the static mesh place the same
# vertices (ribbons_vertex.glsl) and share the fragment shader, so against
# pulling on tornado (halo on, 3 twist lines) and the helix (helicity frame,
# halo, 3 twist lines) the colour over covered pixels is within a mean of
# 1/255 and the depth within 1e-4 with at most 0.05 % coverage mismatch.
# Measured (llvmpipe): geometry colour mean 0.0007 (max 1), depth max
# 2.1e-5 (helix; tornado 2.0e-6), coverage identical; mesh identical (0).
# Twins: width_ratio 0.3 instead of 0.25 on tornado fails all three
# (colour mean 3.0, depth max 0.75, coverage 0.17 %).
set(RB_SAME_COLOR --max-mean 1 ${SL_GOLDEN_BACKGROUND})
string(REPLACE ";" "|" RB_SAME_COLOR "${RB_SAME_COLOR}")
set(RB_SAME_DEPTH --max-abs|1e-4|--max-coverage-pct|0.05)
# rb_same_image(name scene pipeline expect_fail both second): `both` are
# --set pairs for the two renders, `second` for the non-pulling one only
# ('|'-separated, may be empty).
function(rb_same_image name scene pipeline expect_fail both second)
  set(extra)
  if(expect_fail)
    set(extra -DEXIT3=1 "-DOUT3=\"failed\":[ \t]*\\[\"max_mean\"\\]"
              -DEXIT4=1 "-DOUT4=\"failed\":[ \t]*\\[\"max_coverage_pct\", \"max_abs\"\\]")
  endif()
  set(o ${RB_OUT}/pipe_${name})
  set(common "--set|params.twist_lines=3${both}")
  if(scene STREQUAL "helix")
    set(scene goldens/helix) # the helix scene is a case of the goldens suite
  endif()
  rb_test(pipelines.${name} ${CMAKE_COMMAND}
    "-DSTEP1=${RB_RENDER}|--scene|${RIBBONS_DIR}/${scene}.json|--out|${o}_pulling.png|--depth|${o}_pulling.pfm|${common}"
    "-DSTEP2=${RB_RENDER}|--scene|${RIBBONS_DIR}/${scene}.json|--out|${o}_${pipeline}.png|--depth|${o}_${pipeline}.pfm|${common}|--set|params.pipeline=${pipeline}${second}"
    "-DSTEP3=${RB_DIFF}|${o}_pulling.png|${o}_${pipeline}.png|${RB_SAME_COLOR}"
    "-DSTEP4=${RB_DIFF}|${o}_pulling.pfm|${o}_${pipeline}.pfm|${RB_SAME_DEPTH}"
    ${extra} ${SL_STEPS})
endfunction()
foreach(scene tornado helix)
  foreach(pipeline geometry mesh)
    rb_same_image(same_image_${scene}_${pipeline} ${scene} ${pipeline} 0 "" "")
  endforeach()
endforeach()
foreach(pipeline geometry mesh)
  rb_same_image(same_image_detects_width_${pipeline} tornado ${pipeline} 1 "" "|--set|params.width_ratio=0.3")
endforeach()

# Geometry shader split: 2 (N + 1) x 21 output components exceed llvmpipe's
# 1024 from N = 24 on, so sides 24 and 32 run with 2 invocations (sides 16
# with one); both give pulling's image at the same sides.
foreach(sides 16 32)
  rb_same_image(same_image_tornado_geometry_sides${sides} tornado geometry 0 "|--set|params.sides=${sides}" "")
endforeach()

# ---- flat vanishes edge-on (the point of the baseline): the straight ribbon
# seen exactly along its width axis, min_pixels 1, is at least a pixel thick
# with pulling and draws nothing with the flat quads (they do not widen).
rb_test(pipelines.flat_vanishes_edge_on ${CMAKE_COMMAND}
  "-DSTEP1=${RB_RENDER}|--scene|${RIBBONS_DIR}/edge_straight.json|--out|${RB_OUT}/edge_flat.png|--samples|1|--set|params.pipeline=flat"
  "-DSTEP2=${RB_CHECK}|edge_on|--png|${RB_OUT}/edge_flat.png|--min-pixels|1|--span|0.9"
  -DEXIT2=1 "-DERR2=FAIL: (column [0-9]+ is [0-9]+ px thick, below 1|nothing drawn)"
  "-DSTEP3=${RB_RENDER}|--scene|${RIBBONS_DIR}/edge_straight.json|--out|${RB_OUT}/edge_pulling.png|--samples|1|--set|params.pipeline=pulling"
  "-DSTEP4=${RB_CHECK}|edge_on|--png|${RB_OUT}/edge_pulling.png|--min-pixels|1|--span|0.9"
  ${SL_STEPS})

# ---- GPU memory (sightline-render --stats gpu_bytes, every buffer each
# pipeline allocates): the static mesh needs at least 5x pulling's. Measured on
# tornado (100 lines x 200 points, N = 8): pulling 1,047,244, geometry
# 1,200,300, mesh 12,876,228 (12.3x), flat 1,041,796 bytes. The twin holds
# geometry (pulling's buffers + 8 B per segment, 1.15x) to the same 5x: fails.
function(rb_memory name pipeline)
  set(o ${RB_OUT}/mem_${name})
  set(extra)
  if(NOT pipeline STREQUAL "mesh")
    set(extra -DEXIT3=1 "-DERR3=FAIL: gpu_bytes ratio [0-4]\\.[0-9]+ is below 5")
  endif()
  rb_test(pipelines.${name} ${CMAKE_COMMAND}
    "-DSTEP1=${RB_RENDER}|--scene|${RIBBONS_DIR}/tornado.json|--out|${o}_pulling.png|--stats|${o}_pulling.json"
    "-DSTEP2=${RB_RENDER}|--scene|${RIBBONS_DIR}/tornado.json|--out|${o}_${pipeline}.png|--set|params.pipeline=${pipeline}|--stats|${o}_${pipeline}.json"
    "-DSTEP3=${CMAKE_COMMAND}|-DLARGE=${o}_${pipeline}.json|-DSMALL=${o}_pulling.json|-DMIN_RATIO=5|-P|${RIBBONS_DIR}/gpu_bytes_ratio.cmake"
    ${extra} ${SL_STEPS})
endfunction()
rb_memory(mesh_memory_5x_pulling mesh)
rb_memory(memory_detects_small_ratio geometry)

# ---- culling per pipeline: the tornado close-up culls chunks (stats culled
# > 0; the same 62,684 of 319,600 triangles for geometry and mesh as for
# pulling, 7,780 of 39,800 for flat) and gives exactly the image and depth of
# drawing every chunk.
foreach(pipeline geometry mesh flat)
  set(o ${RB_OUT}/cull_${pipeline})
  rb_test(pipelines.culling_same_image_${pipeline} ${CMAKE_COMMAND}
    "-DSTEP1=${RB_RENDER}|--scene|${RIBBONS_DIR}/tornado.json|--out|${o}_on.png|--depth|${o}_on.pfm|--set|camera.orbit.distance=0.45|--set|params.pipeline=${pipeline}|--stats|${o}_on.json"
    "-DSTEP2=${RB_RENDER}|--scene|${RIBBONS_DIR}/tornado.json|--out|${o}_off.png|--depth|${o}_off.pfm|--set|camera.orbit.distance=0.45|--set|params.pipeline=${pipeline}|--set|params.frustum_culling=false"
    "-DSTEP3=${RB_DIFF}|${o}_on.png|${o}_off.png|--max-abs|0"
    "-DSTEP4=${RB_DIFF}|${o}_on.pfm|${o}_off.pfm|--max-abs|0"
    "-DSTEP5=${CMAKE_COMMAND}|-E|cat|${o}_on.json"
    "-DOUT5=\"culled\":[ \t]*[1-9]"
    ${SL_STEPS})
endforeach()

# The comparison can fail: a chunk set that differed (here the unculled
# render with radius 0.021 instead of 0.02) is caught by the exact diff.
rb_test(pipelines.culling_detects_difference ${CMAKE_COMMAND}
  "-DSTEP1=${RB_RENDER}|--scene|${RIBBONS_DIR}/tornado.json|--out|${RB_OUT}/cull_twin_on.png|--set|camera.orbit.distance=0.45|--set|params.pipeline=geometry"
  "-DSTEP2=${RB_RENDER}|--scene|${RIBBONS_DIR}/tornado.json|--out|${RB_OUT}/cull_twin_off.png|--set|camera.orbit.distance=0.45|--set|params.pipeline=geometry|--set|params.frustum_culling=false|--set|params.radius=0.021"
  "-DSTEP3=${RB_DIFF}|${RB_OUT}/cull_twin_on.png|${RB_OUT}/cull_twin_off.png|--max-abs|0"
  -DEXIT3=1 "-DOUT3=\"failed\":[ \t]*\\[\"max_abs\"\\]"
  ${SL_STEPS})

# ---- stress per pipeline: the degenerate lines of stress.vtk draw without
# crash or NaN with every pipeline (the checks of stress.degenerate).
foreach(pipeline geometry mesh flat)
  rb_test(pipelines.stress_${pipeline} ${CMAKE_COMMAND}
    "-DSTEP1=${RB_RENDER}|--scene|${RIBBONS_DIR}/stress.json|--out|${RB_OUT}/stress_${pipeline}.png|--depth|${RB_OUT}/stress_${pipeline}.pfm|--set|params.pipeline=${pipeline}"
    "-DSTEP2=${RB_IMAGE}|--scene|${RIBBONS_DIR}/stress.json|--png|${RB_OUT}/stress_${pipeline}.png|--depth|${RB_OUT}/stress_${pipeline}.pfm|--min-color-pct|3|--min-hit-pct|3"
    ${SL_STEPS})
endforeach()
# ---- depth against the analytic elliptic profile (bench plan §5.1's error,
# as a test): the straight ribbon of straight_edge.vtk seen obliquely
# (ribbon_oblique.json, data frame, min_pixels 0, halo off, --samples 1),
# N = 8. ribbons-depth-check (ribbons/ribbons_depth_check.c on
# tests/support/ribbons_depth_error.h) holds every pixel entering the mantle
# to [t_ref - 1e-4, t_ref + ribbons_ref_polygon_bound + 1e-4], every pixel
# through the inscribed cap to 1e-4, and the coverage to the incircle and
# the profile (1/64 px margin); width_ratio 0.25 and 1. The twin renders
# width_ratio 0.5 and is judged against the profile of 0.25: it must fail.
add_executable(ribbons-depth-check ${RIBBONS_DIR}/ribbons_depth_check.c)
target_link_libraries(ribbons-depth-check PRIVATE sightline_test_support sightline_proto sightline_renderer)
set_target_properties(ribbons-depth-check PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
set(RB_DEPTH_CHECK $<TARGET_FILE:ribbons-depth-check>|--scene|${RIBBONS_DIR}/ribbon_oblique.json|--axis|-1,0,0,1,0,0|--normal|0,0,1|--radius|0.1|--sides|8)
function(rb_depth_test name rendered judged expect_exit)
  set(extra)
  if(NOT expect_exit EQUAL 0)
    set(extra -DEXIT2=${expect_exit} "-DERR2=FAIL: pixel")
  endif()
  rb_test(accuracy.analytic_${name} ${CMAKE_COMMAND}
    "-DSTEP1=${RB_RENDER}|--scene|${RIBBONS_DIR}/ribbon_oblique.json|--out|${RB_OUT}/analytic_${name}.png|--depth|${RB_OUT}/analytic_${name}.pfm|--samples|1|--set|params.width_ratio=${rendered}"
    "-DSTEP2=${RB_DEPTH_CHECK}|--depth|${RB_OUT}/analytic_${name}.pfm|--width-ratio|${judged}"
    ${extra} ${SL_STEPS})
endfunction()
rb_depth_test(w025_sides8 0.25 0.25 0)
rb_depth_test(w1_sides8 1 1 0)
rb_depth_test(detects_wrong_width 0.5 0.25 1)
