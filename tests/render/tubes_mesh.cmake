# GPU tests of the `tubes_mesh` technique (renderer/tubes_mesh/) and of the
# sightline-render / sightline-diff command lines. Scenes, goldens and the
# check program (tubes_mesh_check.c) live in tests/render/tubes_mesh/; the
# step runner (SL_STEPS: each step's exact exit code and stderr/stdout
# regexes) is tests/steps.cmake. Every test that expects a failure
# names the exit code (1 = over a limit, 2 = bad input) and the failure line,
# so that a crash, a sanitizer report or a usage error cannot pass for it. Keep '[' and ']' balanced inside every argument: CMake does not
# split a list at ';' inside an open bracket, so an unbalanced one would
# swallow the following "-P steps.cmake" and turn the test into an in-source
# configure of the working directory.
set(TM_DIR ${CMAKE_CURRENT_SOURCE_DIR}/tubes_mesh)
set(TM_OUT ${SL_RENDER_OUT}/tubes_mesh)
file(MAKE_DIRECTORY ${TM_OUT})
add_executable(tubes-mesh-check ${TM_DIR}/tubes_mesh_check.c)
target_include_directories(tubes-mesh-check PRIVATE ${CMAKE_SOURCE_DIR}/proto)
target_link_libraries(tubes-mesh-check PRIVATE sightline_proto sightline_renderer)
set_target_properties(tubes-mesh-check PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)

set(TM_RENDER $<TARGET_FILE:sightline-render>)
set(TM_DIFF $<TARGET_FILE:sightline-diff>)
set(TM_CHECK $<TARGET_FILE:tubes-mesh-check>)
set(TM_STEPS ${SL_STEPS})

# Golden-image tolerance (colour, 0..255), over the covered pixels (either
# image differs from the background; SL_GOLDEN_BACKGROUND). llvmpipe is
# deterministic, so the same build reproduces a golden exactly (measured:
# mean 0, 0 bad pixels); the slack is for other Mesa/LLVM versions and CPUs:
# shading may move by an LSB or two on the tubes (mean <= 0.5) and MSAA edge
# coverage may flip on a few silhouette pixels (<= 0.5 % of the covered
# pixels off by more than 16). A real change — a 30-degree camera turn
# (cli.set_changes_image), a different tessellation, colormap or radius, or
# +5 on every drawn pixel (golden.detects_uniform_error) — is far beyond it.
set(TM_GOLDEN_LIMITS --max-mean 0.5 --max-bad-pct 0.5 --bad-threshold 16 ${SL_GOLDEN_BACKGROUND})
string(REPLACE ";" "|" TM_GOLDEN_ARGS "${TM_GOLDEN_LIMITS}")

function(tm_test name)
  sl_add_render_test(NAME tubes_mesh.${name} COMMAND ${ARGN})
endfunction()

# ---- 1. smoke: a generated tornado through sightline-render writes a PNG that is
# not all background and a depth map with hits, no NaN/Inf, within the bounds.
tm_test(smoke.tornado ${CMAKE_COMMAND}
  "-DSTEP1=${TM_RENDER}|--scene|${TM_DIR}/tornado.json|--out|${TM_OUT}/smoke.png|--depth|${TM_OUT}/smoke.pfm"
  "-DSTEP2=${TM_CHECK}|image|--scene|${TM_DIR}/tornado.json|--png|${TM_OUT}/smoke.png|--depth|${TM_OUT}/smoke.pfm|--min-color-pct|10|--min-hit-pct|10"
  ${TM_STEPS})

# ---- 2. golden images: the suite tests/render/tubes_mesh/goldens through
# sightline-regress (sightline-render defaults: 4x MSAA; each case is an
# expect file naming a scene of this folder and its --set overrides):
#   tornado:        colormap (viridis) on the speed attribute, constant radius, 12 sides, caps
#   hotroom:        per-vertex data radii x radius_scale 0.7, coolwarm on temperature, 16 sides
#   caps_sides6:    one tube, 6 sides, flat caps in view (plasma along the tube)
#   open_sides6:    the same without caps: the inner wall through the open end
#   degenerate_obj: degenerate.obj (repeated points, reversals) in a constant colour
# After a deliberate change: sightline-regress tests/render/tubes_mesh/goldens
# --update, look at the new goldens, and say so in the commit.
tm_test(goldens ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:sightline-regress>|${TM_DIR}/goldens|--out|${TM_OUT}/goldens|--jobs|2|--junit|${TM_OUT}/goldens.xml"
  "-DOUT1=5 cases, 5 passed, 0 failed, 0 errors"
  ${TM_STEPS})
# The limits catch a uniform error: +5 on every drawn pixel of the
# degenerate_obj golden (7 % of the frame drawn) is a covered mean of 5, over
# 0.5; over the whole frame it was 0.35 and passed (step 2 shows it).
tm_test(golden.detects_uniform_error ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:golden-offset>|${TM_DIR}/goldens/golden/degenerate_obj.png|${TM_OUT}/golden_plus5.png|26,26,31|5"
  "-DSTEP2=${TM_DIFF}|${TM_OUT}/golden_plus5.png|${TM_DIR}/goldens/golden/degenerate_obj.png|--max-mean|0.5|--max-bad-pct|0.5|--bad-threshold|16"
  "-DOUT2=\"pass\":[ \t]*true"
  "-DSTEP3=${TM_DIFF}|${TM_OUT}/golden_plus5.png|${TM_DIR}/goldens/golden/degenerate_obj.png|${TM_GOLDEN_ARGS}"
  -DEXIT3=1 "-DOUT3=\"failed\":[ \t]*\\[\"max_mean\"\\]"
  ${TM_STEPS})

# ---- 3. accuracy against the exact ray-cylinder distance (tubes-mesh-check cylinder,
# in double, rays from proto/scene.md). The mesh is a prism inscribed in the
# tube, so on every pixel entering the mantle
#   0 <= depth error <= t(cylinder of radius r cos(pi/n)) - t(cylinder of radius r)
#                    <= B(c) = r sin^2(pi/n) / (c + sqrt(c^2 - sin^2(pi/n))),
# c = cosine of the incidence angle; head-on B(1) = r (1 - cos(pi/n)), the
# polygonal bound. Plus eps = 1e-5 x the distance for float depth. Caps lie in
# the end planes exactly (error <= eps); open ends show the inner wall
# between the two cylinders' exits. Coverage: a ray entering the incircle
# cylinder must hit, a ray missing the circumcircle cylinder must miss (with a
# 1/64-pixel margin); only the band between may do either.
# Measured (llvmpipe): error / B(c) reaches 1.000 (the bound is tight: face
# midlines touch the incircle), error <= 1.13 x r(1 - cos(pi/n)) where c >= 0.9,
# min error -1.1e-7, cap error <= 5e-7 at distance ~2.4; the same at 1e6 offset.
foreach(n 6 12 30)
  tm_test(accuracy.side_sides${n}
    tubes-mesh-check cylinder --scene ${TM_DIR}/cylinder_side.json --set params.sides=${n} --min-mantle-pct 15)
endforeach()
foreach(n 6 12)
  tm_test(accuracy.oblique_caps_sides${n}
    tubes-mesh-check cylinder --scene ${TM_DIR}/cylinder_oblique.json --set params.sides=${n}
    --min-mantle-pct 5 --min-cap-pct 2)
  tm_test(accuracy.oblique_open_sides${n}
    tubes-mesh-check cylinder --scene ${TM_DIR}/cylinder_oblique.json --set params.sides=${n} --set params.caps=false
    --min-mantle-pct 5 --min-inside-pct 2)
endforeach()
# radius_scale multiplies the data radius (0.3 -> 0.15).
tm_test(accuracy.radius_scale
  tubes-mesh-check cylinder --scene ${TM_DIR}/cylinder_side.json --set params.radius_scale=0.5 --min-mantle-pct 5)
# The same tube 1e6 units from the origin (camera too): same bound.
tm_test(accuracy.offset_1e6
  tubes-mesh-check cylinder --scene ${TM_DIR}/cylinder_offset.json --min-mantle-pct 15)
# Through the command line: sightline-render --depth, then the reference on that PFM.
tm_test(accuracy.cli_depth ${CMAKE_COMMAND}
  "-DSTEP1=${TM_RENDER}|--scene|${TM_DIR}/cylinder_oblique.json|--out|${TM_OUT}/cyl_cli.png|--depth|${TM_OUT}/cyl_cli.pfm"
  "-DSTEP2=${TM_CHECK}|cylinder|--scene|${TM_DIR}/cylinder_oblique.json|--gpu-depth|${TM_OUT}/cyl_cli.pfm|--min-mantle-pct|5|--min-cap-pct|2"
  ${TM_STEPS})
# The check itself fails on a tube 1 % too thick (the surface in front of the
# exact cylinder) and on a 12-sided mesh judged as a 30-sided one.
tm_test(accuracy.detects_wrong_radius ${CMAKE_COMMAND}
  "-DSTEP1=${TM_RENDER}|--scene|${TM_DIR}/cylinder_side.json|--out|${TM_OUT}/cyl_thick.png|--depth|${TM_OUT}/cyl_thick.pfm|--set|params.radius_scale=1.01"
  "-DSTEP2=${TM_CHECK}|cylinder|--scene|${TM_DIR}/cylinder_side.json|--gpu-depth|${TM_OUT}/cyl_thick.pfm"
  -DEXIT2=1 "-DERR2=FAIL: pixel \\([0-9]+, [0-9]+\\) \\(mantle\\): GPU [0-9.]+ outside \\[[0-9.]+, [0-9.]+\\]"
  ${TM_STEPS})
tm_test(accuracy.detects_coarse_mesh ${CMAKE_COMMAND}
  "-DSTEP1=${TM_RENDER}|--scene|${TM_DIR}/cylinder_side.json|--out|${TM_OUT}/cyl_12.png|--depth|${TM_OUT}/cyl_12.pfm"
  "-DSTEP2=${TM_CHECK}|cylinder|--scene|${TM_DIR}/cylinder_side.json|--gpu-depth|${TM_OUT}/cyl_12.pfm|--set|params.sides=30"
  -DEXIT2=1 "-DERR2=FAIL: pixel [^\n]*: depth error [^\n]* > B\\(c = "
  ${TM_STEPS})

# ---- 4. degenerate geometry: no crash, no NaN/Inf in depth, what is valid is drawn.
tm_test(degenerate.obj_polylines ${CMAKE_COMMAND}
  "-DSTEP1=${TM_RENDER}|--scene|${TM_DIR}/degenerate_obj.json|--out|${TM_OUT}/deg_obj.png|--depth|${TM_OUT}/deg_obj.pfm"
  "-DSTEP2=${TM_CHECK}|image|--scene|${TM_DIR}/degenerate_obj.json|--png|${TM_OUT}/deg_obj.png|--depth|${TM_OUT}/deg_obj.pfm|--min-color-pct|3|--min-hit-pct|3"
  ${TM_STEPS})
tm_test(degenerate.hermite_segments ${CMAKE_COMMAND}
  "-DSTEP1=${TM_RENDER}|--scene|${TM_DIR}/degenerate_hermite.json|--out|${TM_OUT}/deg_herm.png|--depth|${TM_OUT}/deg_herm.pfm"
  "-DSTEP2=${TM_CHECK}|image|--scene|${TM_DIR}/degenerate_hermite.json|--png|${TM_OUT}/deg_herm.png|--depth|${TM_OUT}/deg_herm.pfm|--min-color-pct|5|--min-hit-pct|5"
  ${TM_STEPS})
# Nothing valid at all (zero length, radius 0): an empty frame and depth map.
tm_test(degenerate.all_degenerate ${CMAKE_COMMAND}
  "-DSTEP1=${TM_RENDER}|--scene|${TM_DIR}/degenerate_empty.json|--out|${TM_OUT}/deg_empty.png|--depth|${TM_OUT}/deg_empty.pfm"
  "-DSTEP2=${TM_CHECK}|image|--scene|${TM_DIR}/degenerate_empty.json|--png|${TM_OUT}/deg_empty.png|--depth|${TM_OUT}/deg_empty.pfm|--expect-empty"
  ${TM_STEPS})
# radius_scale 0 turns every data radius to 0: nothing drawn.
tm_test(degenerate.radius_scale_zero ${CMAKE_COMMAND}
  "-DSTEP1=${TM_RENDER}|--scene|${TM_DIR}/degenerate_hermite.json|--out|${TM_OUT}/deg_r0.png|--depth|${TM_OUT}/deg_r0.pfm|--set|params.radius_scale=0"
  "-DSTEP2=${TM_CHECK}|image|--scene|${TM_DIR}/degenerate_hermite.json|--set|params.radius_scale=0|--png|${TM_OUT}/deg_r0.png|--depth|${TM_OUT}/deg_r0.pfm|--expect-empty"
  ${TM_STEPS})
# Coordinates near 1e6 (inline Hermite data and an OBJ file): frame and depth
# map equal those of the same geometry at the origin (orbit cameras, so the
# views are the same). Measured: identical (0 difference). Depth limit: 1e-4
# absolute at distances ~2.5 on at most 0.5 % of pixels, coverage 0.5 %.
foreach(kind hermite obj)
  if(kind STREQUAL "hermite")
    set(base offset_base.json)
    set(far offset_1e6.json)
  else()
    set(base offset_base_obj.json)
    set(far offset_1e6_obj.json)
  endif()
  tm_test(degenerate.offset_1e6_${kind} ${CMAKE_COMMAND}
    "-DSTEP1=${TM_RENDER}|--scene|${TM_DIR}/${base}|--out|${TM_OUT}/off_${kind}_0.png|--depth|${TM_OUT}/off_${kind}_0.pfm"
    "-DSTEP2=${TM_RENDER}|--scene|${TM_DIR}/${far}|--out|${TM_OUT}/off_${kind}_1.png|--depth|${TM_OUT}/off_${kind}_1.pfm"
    "-DSTEP3=${TM_CHECK}|image|--scene|${TM_DIR}/${far}|--png|${TM_OUT}/off_${kind}_1.png|--depth|${TM_OUT}/off_${kind}_1.pfm|--min-color-pct|3|--min-hit-pct|3"
    "-DSTEP4=${TM_DIFF}|${TM_OUT}/off_${kind}_0.png|${TM_OUT}/off_${kind}_1.png|${TM_GOLDEN_ARGS}"
    "-DSTEP5=${TM_DIFF}|${TM_OUT}/off_${kind}_0.pfm|${TM_OUT}/off_${kind}_1.pfm|--bad-threshold|1e-4|--max-bad-pct|0.5|--max-coverage-pct|0.5"
    ${TM_STEPS})
endforeach()

# ---- 5. command line.
# --frames 3 --stats: renderer, technique, frames, gpu_ms / wall_ms {min, median,
# max}, dataset_load_ms (generation), prepare_ms, its parts preprocess_ms (mesh
# build) and upload_ms,
# gpu_bytes, primitives = 100 lines x 199 segments x 12 sides x 2 + 100 x 2 caps x 12.
tm_test(cli.stats ${CMAKE_COMMAND}
  "-DSTEP1=${TM_RENDER}|--scene|${TM_DIR}/tornado.json|--out|${TM_OUT}/stats.png|--frames|3|--stats|${TM_OUT}/stats.json"
  "-DSTEP2=${TM_CHECK}|stats|--stats|${TM_OUT}/stats.json|--frames|3|--technique|tubes_mesh|--expect-primitives|480000"
  ${TM_STEPS})
# --set camera.orbit.azimuth=30 turns the camera: the golden comparison must
# fail with exit 1 (a limit exceeded), not 2 (bad input).
tm_test(cli.set_changes_image ${CMAKE_COMMAND}
  "-DSTEP1=${TM_RENDER}|--scene|${TM_DIR}/tornado.json|--out|${TM_OUT}/azimuth30.png|--set|camera.orbit.azimuth=30"
  "-DSTEP2=${TM_DIFF}|${TM_OUT}/azimuth30.png|${TM_DIR}/goldens/golden/tornado.png|${TM_GOLDEN_ARGS}"
  -DEXIT2=1 "-DOUT2=\"pass\":[ \t]*false"
  ${TM_STEPS})
# The same for a parameter: another colormap.
tm_test(cli.set_param_changes_image ${CMAKE_COMMAND}
  "-DSTEP1=${TM_RENDER}|--scene|${TM_DIR}/tornado.json|--out|${TM_OUT}/magma.png|--set|params.colormap=magma"
  "-DSTEP2=${TM_DIFF}|${TM_OUT}/magma.png|${TM_DIR}/goldens/golden/tornado.png|${TM_GOLDEN_ARGS}"
  -DEXIT2=1 "-DOUT2=\"pass\":[ \t]*false"
  ${TM_STEPS})
# A .jpg output is a JPEG that decodes to the PNG's picture.
tm_test(cli.jpeg_output ${CMAKE_COMMAND}
  "-DSTEP1=${TM_RENDER}|--scene|${TM_DIR}/tornado.json|--out|${TM_OUT}/frame.jpg"
  "-DSTEP2=${TM_RENDER}|--scene|${TM_DIR}/tornado.json|--out|${TM_OUT}/frame_for_jpg.png"
  "-DSTEP3=${TM_CHECK}|image|--scene|${TM_DIR}/tornado.json|--jpeg|${TM_OUT}/frame.jpg|--png|${TM_OUT}/frame_for_jpg.png|--min-color-pct|10"
  ${TM_STEPS})
# Bad input: exit 2 and a message naming the problem (exit 1 for bad usage).
function(tm_cli_error name code regex)
  string(REPLACE ";" "|" args "${ARGN}")
  tm_test(cli.${name} ${CMAKE_COMMAND}
    "-DSTEP1=${TM_RENDER}|${args}" -DEXIT1=${code} "-DERR1=${regex}" ${TM_STEPS})
endfunction()
set(TM_SCENE --scene ${TM_DIR}/tornado.json --out ${TM_OUT}/never.png)
tm_cli_error(bad_set_syntax 2 "sightline-render: --set expects key\\.path=value, got 'camera'" ${TM_SCENE} --set camera)
tm_cli_error(bad_set_value 2 "camera\\.orbit\\.distance must be > 0, got -1" ${TM_SCENE} --set camera.orbit.distance=-1)
tm_cli_error(bad_set_path 2 "'width' is not an object" ${TM_SCENE} --set width.x=3)
tm_cli_error(unknown_param 2 "params: unknown parameter 'bogus' \\(known: radius, " ${TM_SCENE} --set params.bogus=1)
tm_cli_error(param_out_of_range 2 "parameter 'sides' = 31 is out of range \\[6, 30\\]" ${TM_SCENE} --set params.sides=31)
tm_cli_error(unknown_technique 2 "technique 'nope' is unknown \\(known: [^)]*tubes_mesh" ${TM_SCENE} --set technique=nope)
tm_cli_error(unknown_colormap 2 "parameter 'colormap' has no choice 'rainbow'" ${TM_SCENE} --set params.colormap=rainbow)
tm_cli_error(bad_scene_json 2 "bad_syntax\\.json is not valid JSON" --scene ${TM_DIR}/bad_syntax.json --out ${TM_OUT}/never.png)
tm_cli_error(bad_scene_field 2 "heigth: unknown field \\(allowed: " --scene ${TM_DIR}/bad_field.json --out ${TM_OUT}/never.png)
tm_cli_error(missing_scene 2 "no_such_scene\\.json" --scene ${TM_DIR}/no_such_scene.json --out ${TM_OUT}/never.png)
tm_cli_error(missing_dataset 2 "dataset: [^\n]*no_such_data\\.obj" ${TM_SCENE} --set dataset=no_such_data.obj)
tm_cli_error(usage 1 "usage: sightline-render --scene S\\.json --out frame\\.png" --scene ${TM_DIR}/tornado.json)
# sightline-diff: a PNG against a PFM is bad input (exit 2), not a difference.
tm_test(cli.diff_mixed_kinds ${CMAKE_COMMAND}
  "-DSTEP1=${TM_RENDER}|--scene|${TM_DIR}/degenerate_empty.json|--out|${TM_OUT}/mixed.png|--depth|${TM_OUT}/mixed.pfm"
  "-DSTEP2=${TM_DIFF}|${TM_OUT}/mixed.png|${TM_OUT}/mixed.pfm"
  -DEXIT2=2 "-DERR2=mixed\\.png \\(PNG\\) with [^\n]*mixed\\.pfm \\(PFM\\): both must be PNG or both PFM"
  ${TM_STEPS})

# ---- self-tests: the checks above fail on bad input (exit 1, naming the problem).
# A depth map with NaN, Inf, a negative value and a hit beyond the data.
tm_test(selftest.image_detects_bad_depth ${CMAKE_COMMAND}
  "-DSTEP1=${TM_RENDER}|--scene|${TM_DIR}/tiny.json|--out|${TM_OUT}/tiny.png"
  "-DSTEP2=${TM_CHECK}|image|--scene|${TM_DIR}/tiny.json|--png|${TM_OUT}/tiny.png|--depth|${TM_DIR}/bad_depth.pfm"
  -DEXIT2=1 "-DERR2== nan is not a finite distance[^\n]*\n[^\n]*= inf is not a finite distance[^\n]*\n[^\n]*1 hits lie outside the eye distance range"
  ${TM_STEPS})
# An empty frame where tubes are expected, and tubes where none are.
tm_test(selftest.image_detects_empty ${CMAKE_COMMAND}
  "-DSTEP1=${TM_RENDER}|--scene|${TM_DIR}/degenerate_empty.json|--out|${TM_OUT}/st_empty.png|--depth|${TM_OUT}/st_empty.pfm"
  "-DSTEP2=${TM_CHECK}|image|--scene|${TM_DIR}/degenerate_empty.json|--png|${TM_OUT}/st_empty.png|--depth|${TM_OUT}/st_empty.pfm"
  -DEXIT2=1 "-DERR2=0\\.00 % of the pixels differ from the background \\(expected >= 1 %\\)"
  ${TM_STEPS})
tm_test(selftest.image_detects_not_empty ${CMAKE_COMMAND}
  "-DSTEP1=${TM_RENDER}|--scene|${TM_DIR}/tiny.json|--out|${TM_OUT}/st_tiny.png|--depth|${TM_OUT}/st_tiny.pfm"
  "-DSTEP2=${TM_CHECK}|image|--scene|${TM_DIR}/tiny.json|--png|${TM_OUT}/st_tiny.png|--depth|${TM_OUT}/st_tiny.pfm|--expect-empty"
  -DEXIT2=1 "-DERR2=of the depth pixels are hits \\(expected exactly 0 %\\)"
  ${TM_STEPS})
# A stats file with every kind of defect.
tm_test(selftest.stats_detects_bad_file ${CMAKE_COMMAND}
  "-DSTEP1=${TM_CHECK}|stats|--stats|${TM_DIR}/bad_stats.json|--frames|3|--technique|tubes_mesh"
  -DEXIT1=1 "-DERR1=renderer is missing or empty.*frames = 2, expected 3.*gpu_ms is not ordered.*wall_ms\\.max = -1.*prepare_ms is missing.*gpu_bytes is 0"
  ${TM_STEPS})
# A JPEG that does not show the PNG's picture.
tm_test(selftest.jpeg_detects_other_picture ${CMAKE_COMMAND}
  "-DSTEP1=${TM_RENDER}|--scene|${TM_DIR}/tornado.json|--out|${TM_OUT}/st_frame.jpg"
  "-DSTEP2=${TM_CHECK}|image|--scene|${TM_DIR}/tornado.json|--jpeg|${TM_OUT}/st_frame.jpg|--png|${TM_DIR}/goldens/golden/hotroom.png"
  -DEXIT2=1 "-DERR2=the JPEG differs from [^\n]*hotroom\\.png by [0-9.]+ on average"
  ${TM_STEPS})

# ---- 6. radii from an attribute (radius_attribute, shared with tubes): the
# varying-radius Hermite scene with its radii moved into the colour scalar,
# meshed with radius_attribute 0, gives the same surface as the scene with
# the radii as data radii (the same radii; the two datasets' origins differ,
# as their bounds include the radii, so positions round differently: 1e-4 of
# a depth of ~2.7 is ~20 float ulps), and a frame without it (the constant
# 0.01) differs beyond that.
tm_test(radius_attribute ${CMAKE_COMMAND}
  "-DSTEP1=${TM_RENDER}|--scene|${CMAKE_CURRENT_SOURCE_DIR}/tubes/radius_attribute_ref.json|--set|technique=tubes_mesh|--out|${TM_OUT}/ra_ref.png|--depth|${TM_OUT}/ra_ref.pfm"
  "-DSTEP2=${TM_RENDER}|--scene|${CMAKE_CURRENT_SOURCE_DIR}/tubes/radius_attribute.json|--set|technique=tubes_mesh|--out|${TM_OUT}/ra_attr.png|--depth|${TM_OUT}/ra_attr.pfm"
  "-DSTEP3=${TM_DIFF}|${TM_OUT}/ra_attr.pfm|${TM_OUT}/ra_ref.pfm|--max-abs|1e-4|--max-coverage-pct|0"
  ${TM_STEPS})
tm_test(radius_attribute_changes_depth ${CMAKE_COMMAND}
  "-DSTEP1=${TM_RENDER}|--scene|${CMAKE_CURRENT_SOURCE_DIR}/tubes/radius_attribute_ref.json|--set|technique=tubes_mesh|--out|${TM_OUT}/rb_ref.png|--depth|${TM_OUT}/rb_ref.pfm"
  "-DSTEP2=${TM_RENDER}|--scene|${CMAKE_CURRENT_SOURCE_DIR}/tubes/radius_attribute.json|--set|technique=tubes_mesh|--set|params.radius_attribute=-1|--out|${TM_OUT}/rb_attr.png|--depth|${TM_OUT}/rb_attr.pfm"
  "-DSTEP3=${TM_DIFF}|${TM_OUT}/rb_attr.pfm|${TM_OUT}/rb_ref.pfm|--max-abs|1e-4|--max-coverage-pct|0"
  -DEXIT3=1 "-DOUT3=\"failed\":[ \t]*\\[[^]]*\"max_abs\"" ${TM_STEPS})
