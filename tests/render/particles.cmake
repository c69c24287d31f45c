# Tests of `particles` (renderer/particles/, issue 14). sightline-render runs
# the technique on a scene and exports its particles (--export) and stats;
# particles-check (particles/particles_check.c) judges them against the
# double-precision references of tests/support/particles_reference.h.
set(PT_DIR ${CMAKE_CURRENT_SOURCE_DIR}/particles)
set(PT_OUT ${SL_RENDER_OUT}/particles)
file(MAKE_DIRECTORY ${PT_OUT})
add_executable(particles-check ${PT_DIR}/particles_check.c)
target_link_libraries(particles-check PRIVATE sightline_test_support sightline_renderer PkgConfig::CJSON)
set_target_properties(particles-check PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
set(PT_RENDER $<TARGET_FILE:sightline-render>)
set(PT_CHECK $<TARGET_FILE:particles-check>)
set(PT_BASE ${PT_DIR}/base.json)

function(pt_test name)
  sl_add_render_test(NAME particles.${name} COMMAND ${ARGN})
endfunction()

# Datasets (generators, analytic surfaces): a bright sphere of radius 0.45
# (ellipsoid a = b = c = 0.9 at iso 0.5: 14 voxels at 64^3), an ellipsoid
# with semi-axes (0.8, 0.5, 0.3) at iso 0.25 (the level set of axes 0.6,
# 0.375, 0.225), a pure torus (major 0.55, minor 0.25; a signed distance,
# dark inside, iso 0), Marschner-Lobb at iso 0.5 and the two samples.
set(PT_SPHERE64 "{\"generator\":\"ellipsoid\",\"size\":64,\"a\":0.9,\"b\":0.9,\"c\":0.9}")
set(PT_SPHERE128 "{\"generator\":\"ellipsoid\",\"size\":128,\"a\":0.9,\"b\":0.9,\"c\":0.9}")
set(PT_ELL64 "{\"generator\":\"ellipsoid\",\"size\":64,\"a\":0.8,\"b\":0.5,\"c\":0.3}")
set(PT_ELL128 "{\"generator\":\"ellipsoid\",\"size\":128,\"a\":0.8,\"b\":0.5,\"c\":0.3}")
set(PT_TORUS64 "{\"generator\":\"torus\",\"size\":64,\"minor\":0.25,\"sphere\":0.01}")
set(PT_TORUS128 "{\"generator\":\"torus\",\"size\":128,\"minor\":0.25,\"sphere\":0.01}")
set(PT_ML "{\"generator\":\"marschner_lobb\",\"size\":41}")
set(PT_CT ${CMAKE_SOURCE_DIR}/data/samples/cranium.nhdr)
set(PT_MRI ${CMAKE_SOURCE_DIR}/data/samples/ch2.nii.gz)

# pt_export(name dataset params): steps 1-2 of a test: render the base scene
# with that dataset and parameters, export the particles and the stats.
macro(pt_export name dataset params)
  set(PT_STEP1 "-DSTEP1=${PT_RENDER}|--scene|${PT_BASE}|--set|dataset=${dataset}|--set|params=${params}|--out|${PT_OUT}/${name}.png|--stats|${PT_OUT}/${name}.json|--export|${PT_OUT}/${name}.csv")
endmacro()

# ---- on the surface: after redistribution every particle lies on the
# trilinear isosurface, |f - iso| / |grad f| in voxels (f in double,
# independent). The issue's bound is 0.05 voxel for 99 %. Measured p99:
# sphere 6.3e-6, torus 5.9e-6, ellipsoid 5.6e-6 (the Newton step of every
# redistribution step converges in float).
foreach(case "sphere;${PT_SPHERE64};0.5" "torus;${PT_TORUS64};0" "ellipsoid;${PT_ELL64};0.25" "ml;${PT_ML};0.5"
             "mri;${PT_MRI};80" "ct;${PT_CT};400")
  list(GET case 0 name)
  list(GET case 1 src)
  list(GET case 2 iso)
  pt_export(surface_${name} "${src}" "{\"isovalues\":[${iso}]}")
  pt_test(surface.${name} ${CMAKE_COMMAND} "${PT_STEP1}"
    "-DSTEP2=${PT_CHECK}|surface|--dataset|${src}|--csv|${PT_OUT}/surface_${name}.csv|--iso|${iso}|--max-dist|0.05"
    "-DSTEP3=${PT_CHECK}|count|--csv|${PT_OUT}/surface_${name}.csv|--stats|${PT_OUT}/surface_${name}.json|--min|100"
    ${SL_STEPS})
endforeach()

# ---- evenness: the nearest-neighbour distance's coefficient of variation
# after redistribution (exact distances in double) and the packing ratio
# n pi (mean/2)^2 / area against the known area (0.907 for a perfect
# hexagonal packing). Measured: sphere cv 0.052, ratio 0.688; torus cv 0.053,
# ratio 0.692 (the count is fixed by the lattice: 1.5 area / step^2 seeds,
# so the mean distance settles 13 % below the hexagonal one). Bounds: cv <=
# 0.1 (the issue's 0.25), ratio in [0.6, 0.8]. The twin runs no redistribution
# (max_steps 0): the seeds on the lattice edges have cv 0.68 and fail.
set(PT_SPHERE_AREA 2.5446900494077322)   # 4 pi 0.45^2
set(PT_TORUS_AREA 5.428594962305142)     # 4 pi^2 0.55 0.25
foreach(case "sphere;${PT_SPHERE64};0.5;${PT_SPHERE_AREA}" "torus;${PT_TORUS64};0;${PT_TORUS_AREA}")
  list(GET case 0 name)
  list(GET case 1 src)
  list(GET case 2 iso)
  list(GET case 3 area)
  pt_export(evenness_${name} "${src}" "{\"isovalues\":[${iso}]}")
  pt_test(evenness.${name} ${CMAKE_COMMAND} "${PT_STEP1}"
    "-DSTEP2=${PT_CHECK}|evenness|--csv|${PT_OUT}/evenness_${name}.csv|--area|${area}|--max-cv|0.1|--ratio-lo|0.6|--ratio-hi|0.8"
    ${SL_STEPS})
endforeach()
pt_export(evenness_no_steps "${PT_SPHERE64}" "{\"isovalues\":[0.5],\"max_steps\":0}")
pt_test(evenness.detects_no_redistribution ${CMAKE_COMMAND} "${PT_STEP1}"
  "-DSTEP2=${PT_CHECK}|evenness|--csv|${PT_OUT}/evenness_no_steps.csv|--area|${PT_SPHERE_AREA}|--max-cv|0.1|--ratio-lo|0.6|--ratio-hi|0.8"
  -DEXIT2=1 "-DERR2=FAIL: nearest-neighbour cv"
  ${SL_STEPS})

# ---- placement: the GPU's seed count (Algorithm 1, max_steps 0) equals the
# CPU's count of lattice edges crossing the isosurface exactly, at integer
# and fractional lattice steps.
foreach(case "sphere_s1;${PT_SPHERE64};0.5;1" "sphere_s1_25;${PT_SPHERE64};0.5;1.25" "ml_s1_5;${PT_ML};0.5;1.5"
             "torus_s2;${PT_TORUS64};0;2")
  list(GET case 0 name)
  list(GET case 1 src)
  list(GET case 2 iso)
  list(GET case 3 step)
  pt_export(placement_${name} "${src}" "{\"isovalues\":[${iso}],\"spacing\":${step},\"max_steps\":0}")
  pt_test(placement.${name} ${CMAKE_COMMAND} "${PT_STEP1}"
    "-DSTEP2=${PT_CHECK}|placement|--dataset|${src}|--stats|${PT_OUT}/placement_${name}.json|--iso|${iso}|--spacing|${step}"
    ${SL_STEPS})
endforeach()

# ---- curvature: the principal curvatures of the 64-tap tricubic B-spline at
# each particle against the analytic ones at its nearest point of the shape
# (relative error max(|dk1|, |dk2|) / max(|k1|, |k2|), mean over particles).
# The torus generator is dark inside: its normals point inwards (--inward).
# Measured mean (p90) at 64^3 / 128^3: sphere 0.0010 (0.0013) / 0.0003
# (0.0004); ellipsoid 0.0050 (0.0079) / 0.0012 (0.0020); torus 0.0013
# (0.0026) / 0.0003 (0.0007): second order, 4x smaller per doubling. Bounds
# about twice that.
foreach(case "sphere_64;${PT_SPHERE64};0.5;--shape|sphere|--radius|0.45;0.002;0.003"
             "sphere_128;${PT_SPHERE128};0.5;--shape|sphere|--radius|0.45;0.0006;0.001"
             "ellipsoid_64;${PT_ELL64};0.25;--shape|ellipsoid|--axes|0.6,0.375,0.225;0.01;0.016"
             "ellipsoid_128;${PT_ELL128};0.25;--shape|ellipsoid|--axes|0.6,0.375,0.225;0.0025;0.004"
             "torus_64;${PT_TORUS64};0;--shape|torus|--major|0.55|--minor|0.25|--inward;0.003;0.005"
             "torus_128;${PT_TORUS128};0;--shape|torus|--major|0.55|--minor|0.25|--inward;0.0008;0.0015")
  list(GET case 0 name)
  list(GET case 1 src)
  list(GET case 2 iso)
  list(GET case 3 shape)
  list(GET case 4 mean)
  list(GET case 5 p90)
  pt_export(curvature_${name} "${src}" "{\"isovalues\":[${iso}]}")
  pt_test(curvature.${name} ${CMAKE_COMMAND} "${PT_STEP1}"
    "-DSTEP2=${PT_CHECK}|curvature|--csv|${PT_OUT}/curvature_${name}.csv|${shape}|--center|0,0,0|--max-mean-rel|${mean}|--max-p90-rel|${p90}"
    ${SL_STEPS})
endforeach()
# The check sees a sign error: the torus judged outward fails.
pt_test(curvature.detects_sign ${CMAKE_COMMAND}
  "-DSTEP1=${PT_CHECK}|curvature|--csv|${PT_OUT}/curvature_torus_64.csv|--shape|torus|--major|0.55|--minor|0.25|--center|0,0,0|--max-mean-rel|0.003"
  -DEXIT1=1 "-DERR1=FAIL: mean relative curvature error"
  ${SL_STEPS})
set_tests_properties(render.particles.curvature.detects_sign PROPERTIES DEPENDS render.particles.curvature.torus_64)

# ---- determinism: the particles are a function of the data and the
# parameters. Two runs give byte-equal exports; the two bin-table builds
# give the same table, so byte-equal exports too; and since the bitonic sort
# orders by (bin, previous index) exactly as the stable radix sort does, the
# two sorts give byte-equal exports as well. (The default look-up is
# binary_search, so the variant sets the other one, prefix_sum.)
foreach(variant a b bitonic prefix_sum)
  set(extra "")
  if(variant STREQUAL "bitonic")
    set(extra ",\"sort\":\"bitonic\"")
  elseif(variant STREQUAL "prefix_sum")
    set(extra ",\"lookup\":\"prefix_sum\"")
  endif()
  set(PT_DET_${variant} "${PT_RENDER}|--scene|${PT_BASE}|--set|dataset=${PT_TORUS64}|--set|params={\"isovalues\":[0]${extra}}|--out|${PT_OUT}/det_${variant}.png|--export|${PT_OUT}/det_${variant}.csv")
endforeach()
pt_test(deterministic.runs ${CMAKE_COMMAND} "-DSTEP1=${PT_DET_a}" "-DSTEP2=${PT_DET_b}"
  "-DSTEP3=${CMAKE_COMMAND}|-E|compare_files|${PT_OUT}/det_a.csv|${PT_OUT}/det_b.csv"
  "-DSTEP4=${CMAKE_COMMAND}|-E|compare_files|${PT_OUT}/det_a.png|${PT_OUT}/det_b.png"
  ${SL_STEPS})
pt_test(deterministic.sorts_and_lookups ${CMAKE_COMMAND} "-DSTEP1=${PT_DET_a}" "-DSTEP2=${PT_DET_bitonic}"
  "-DSTEP3=${PT_DET_prefix_sum}"
  "-DSTEP4=${CMAKE_COMMAND}|-E|compare_files|${PT_OUT}/det_a.csv|${PT_OUT}/det_bitonic.csv"
  "-DSTEP5=${CMAKE_COMMAND}|-E|compare_files|${PT_OUT}/det_a.csv|${PT_OUT}/det_prefix_sum.csv"
  ${SL_STEPS})
set_tests_properties(render.particles.deterministic.sorts_and_lookups PROPERTIES RESOURCE_LOCK particles_det)
set_tests_properties(render.particles.deterministic.runs PROPERTIES RESOURCE_LOCK particles_det)

# ---- stress (the issue's list). Flat regions: the plateau profile is
# exactly 0.5 outside q = 0.5, so at iso 0.50001 particles slide into cells
# whose gradient vanishes; they are dropped and counted (measured 738 of
# 1152), the others stay on the surface (p99 3.4e-4 voxel), no depth is
# NaN. An isovalue at or beyond the value range is refused by name. A one-
# voxel sheet (two sides one voxel apart), u16 and u8 volumes (the u8 sphere
# has 0.28 levels per voxel: terraces, so its curvature is not bounded),
# z spacing 2.5 x, a volume of one slice, and an isovalue inside the range
# that no lattice edge crosses (an empty set, not an error).
set(PT_FLAT "{\"generator\":\"ellipsoid\",\"size\":64,\"profile\":\"plateau\"}")
pt_export(stress_flat "${PT_FLAT}" "{\"isovalues\":[0.50001]}")
pt_test(stress.flat ${CMAKE_COMMAND} "${PT_STEP1}|--depth|${PT_OUT}/stress_flat.pfm"
  "-DSTEP2=${CMAKE_COMMAND}|-E|cat|${PT_OUT}/stress_flat.json"
  "-DOUT2=\"set0.dropped\":[ \t]*[1-9][0-9]*,"
  "-DSTEP3=${PT_CHECK}|surface|--dataset|${PT_FLAT}|--csv|${PT_OUT}/stress_flat.csv|--iso|0.50001"
  "-DSTEP4=${PT_CHECK}|count|--csv|${PT_OUT}/stress_flat.csv|--stats|${PT_OUT}/stress_flat.json|--min|100"
  "-DSTEP5=${PT_CHECK}|depth|--pfm|${PT_OUT}/stress_flat.pfm|--min|50"
  ${SL_STEPS})
foreach(case "at_min;0.5" "below_min;-3" "at_max;0.95417857170104980")
  list(GET case 0 name)
  list(GET case 1 iso)
  pt_test(stress.iso_${name} ${CMAKE_COMMAND}
    "-DSTEP1=${PT_RENDER}|--scene|${PT_BASE}|--set|dataset=${PT_FLAT}|--set|params={\"isovalues\":[0.6,${iso}]}|--out|${PT_OUT}/iso_${name}.png"
    -DEXIT1=2 "-DERR1=isovalue [-0-9.e]+ of set 1 is at or beyond the volume's value range"
    ${SL_STEPS})
endforeach()
set(PT_SHEET "{\"generator\":\"ellipsoid\",\"size\":64,\"profile\":\"sheet\"}")
set(PT_U16 "{\"generator\":\"ellipsoid\",\"size\":64,\"a\":0.9,\"b\":0.9,\"c\":0.9,\"voxel_type\":\"u16\"}")
set(PT_U8 "{\"generator\":\"ellipsoid\",\"size\":64,\"a\":0.9,\"b\":0.9,\"c\":0.9,\"voxel_type\":\"u8\"}")
set(PT_ANISO "{\"generator\":\"ellipsoid\",\"size\":64,\"a\":0.9,\"b\":0.9,\"c\":0.9,\"anisotropy\":2.5}")
set(PT_SLICE "{\"generator\":\"ellipsoid\",\"size\":64,\"slices\":1}")
# iso in data units: u16 (0.5 + 1.5) / 2.5 * 65535 = 52428, u8 204.
foreach(case "sheet;${PT_SHEET};0.5;1;2000;2800" "u16;${PT_U16};52428;1.25;2300;2550"
             "u8;${PT_U8};204;1.25;2200;2700" "anisotropic;${PT_ANISO};0.5;1.25;1300;1600"
             "one_slice;${PT_SLICE};0.5;1.25;40;80")
  list(GET case 0 name)
  list(GET case 1 src)
  list(GET case 2 iso)
  list(GET case 3 step)
  list(GET case 4 lo)
  list(GET case 5 hi)
  pt_export(stress_${name} "${src}" "{\"isovalues\":[${iso}],\"spacing\":${step}}")
  pt_test(stress.${name} ${CMAKE_COMMAND} "${PT_STEP1}|--depth|${PT_OUT}/stress_${name}.pfm"
    "-DSTEP2=${PT_CHECK}|surface|--dataset|${src}|--csv|${PT_OUT}/stress_${name}.csv|--iso|${iso}"
    "-DSTEP3=${PT_CHECK}|count|--csv|${PT_OUT}/stress_${name}.csv|--stats|${PT_OUT}/stress_${name}.json|--min|${lo}|--max|${hi}"
    "-DSTEP4=${PT_CHECK}|depth|--pfm|${PT_OUT}/stress_${name}.pfm|--min|10"
    ${SL_STEPS})
endforeach()
# u16 and z-anisotropic spheres keep their curvature (measured mean 0.0040
# and 0.0062 against 0.0010 for f32).
pt_test(stress.u16_curvature ${CMAKE_COMMAND}
  "-DSTEP1=${PT_CHECK}|curvature|--csv|${PT_OUT}/stress_u16.csv|--shape|sphere|--radius|0.45|--center|0,0,0|--max-mean-rel|0.008"
  ${SL_STEPS})
set_tests_properties(render.particles.stress.u16_curvature PROPERTIES DEPENDS render.particles.stress.u16)
pt_test(stress.anisotropic_curvature ${CMAKE_COMMAND}
  "-DSTEP1=${PT_CHECK}|curvature|--csv|${PT_OUT}/stress_anisotropic.csv|--shape|sphere|--radius|0.45|--center|0,0,0|--max-mean-rel|0.012"
  ${SL_STEPS})
set_tests_properties(render.particles.stress.anisotropic_curvature PROPERTIES DEPENDS render.particles.stress.anisotropic)
# A sphere of radius 2.8 voxels between the lines of a 16-voxel lattice.
pt_export(stress_empty "{\"generator\":\"ellipsoid\",\"size\":57,\"a\":0.1,\"b\":0.1,\"c\":0.1}" "{\"isovalues\":[0],\"spacing\":16}")
pt_test(stress.empty_set ${CMAKE_COMMAND} "${PT_STEP1}"
  "-DSTEP2=${PT_CHECK}|count|--csv|${PT_OUT}/stress_empty.csv|--stats|${PT_OUT}/stress_empty.json|--max|0"
  ${SL_STEPS})
# A lattice denser than max_particles allows is refused with the numbers.
pt_test(stress.max_particles ${CMAKE_COMMAND}
  "-DSTEP1=${PT_RENDER}|--scene|${PT_BASE}|--set|params={\"isovalues\":[0.5],\"max_particles\":1000}|--out|${PT_OUT}/max_particles.png"
  -DEXIT1=2 "-DERR1=isovalue 0.5 has 2424 particles at spacing 1.25, above max_particles 1000"
  ${SL_STEPS})

# ---- export: the CSV's header and rows (pref_csv_read checks every field),
# its count equal to the stats', and a technique without an export refused.
pt_export(export "${PT_TORUS64}" "{\"isovalues\":[0,0.1]}")
pt_test(export.two_sets ${CMAKE_COMMAND} "${PT_STEP1}"
  "-DSTEP2=${PT_CHECK}|count|--csv|${PT_OUT}/export.csv|--stats|${PT_OUT}/export.json|--set|0|--min|4000"
  "-DSTEP3=${PT_CHECK}|count|--csv|${PT_OUT}/export.csv|--stats|${PT_OUT}/export.json|--set|1|--min|4000"
  ${SL_STEPS})
pt_test(export.wrong_extension ${CMAKE_COMMAND}
  "-DSTEP1=${PT_RENDER}|--scene|${PT_BASE}|--out|${PT_OUT}/wrong_ext.png|--export|${PT_OUT}/wrong_ext.txt"
  -DEXIT1=1 "-DERR1=csv"
  ${SL_STEPS})

# ---- goldens: the suite tests/render/particles/goldens through
# sightline-regress (128x128, the built-in limits over the covered pixels):
# a stippled sphere with hidden-surface removal, a torus without it (the far
# side shows through), and the head phantom's skin and skull as two sets.
# After a deliberate change: sightline-regress tests/render/particles/goldens
# --update, look at the new goldens, and say so in the commit.
pt_test(goldens ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:sightline-regress>|${PT_DIR}/goldens|--out|${PT_OUT}/goldens|--jobs|2"
  "-DOUT1=3 cases, 3 passed, 0 failed, 0 errors"
  ${SL_STEPS})

# ---- the field functions on the GPU (particles_field.glsl through the probe
# particles_probe.comp.glsl) against the double-precision references:
# trilinear and B-spline values, gradients, Hessians and the curvature.
add_executable(test_particles_probe ${PT_DIR}/test_particles_probe.c)
target_link_libraries(test_particles_probe PRIVATE sightline_test_support sightline_renderer)
set_target_properties(test_particles_probe PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
add_test(NAME unit.test_particles_probe COMMAND ${SL_TEST_RUN} $<TARGET_FILE:test_particles_probe>
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(unit.test_particles_probe PROPERTIES ENVIRONMENT "${SL_TEST_ENV}" TIMEOUT 300)

# ---- what a prepare recomputes: camera moves and style changes never;
# a new isovalue list only the sets not in the cache (particles_cache.h).
add_executable(test_particles_cache ${PT_DIR}/test_particles_cache.c)
target_include_directories(test_particles_cache PRIVATE ${CMAKE_SOURCE_DIR}/tests/unit ${CMAKE_SOURCE_DIR}/proto)
target_link_libraries(test_particles_cache PRIVATE sightline_proto sightline_renderer PkgConfig::CJSON)
set_target_properties(test_particles_cache PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
add_test(NAME unit.test_particles_cache COMMAND ${SL_TEST_RUN} $<TARGET_FILE:test_particles_cache>
  WORKING_DIRECTORY ${CMAKE_BINARY_DIR})
set_tests_properties(unit.test_particles_cache PROPERTIES ENVIRONMENT "${SL_TEST_ENV}" TIMEOUT 300)

# ---- huge coordinates: the sphere's voxels written with voxel (0,0,0) at
# (1e5, -2e5, 3e5) give the same particles (positions are stored relative to
# the volume's origin; measured: position, normal and curvature differences
# 0) and the same image; the twin judges them against an origin 1e-3 off.
set(PT_FAR_ORIGIN 100000,-200000,300000)
pt_test(export.huge_offset ${CMAKE_COMMAND}
  "-DSTEP1=${PT_CHECK}|write-volume|--dataset|${PT_SPHERE64}|--origin|${PT_FAR_ORIGIN}|--out|${PT_OUT}/far_sphere"
  "-DSTEP2=${PT_RENDER}|--scene|${PT_BASE}|--out|${PT_OUT}/near.png|--export|${PT_OUT}/near.csv"
  "-DSTEP3=${PT_RENDER}|--scene|${PT_BASE}|--set|dataset=${PT_OUT}/far_sphere.nhdr|--out|${PT_OUT}/far.png|--export|${PT_OUT}/far.csv"
  "-DSTEP4=${PT_CHECK}|offset|--dataset|${PT_SPHERE64}|--csv|${PT_OUT}/near.csv|--csv-b|${PT_OUT}/far.csv|--origin|${PT_FAR_ORIGIN}"
  "-DSTEP5=${CMAKE_COMMAND}|-E|compare_files|${PT_OUT}/near.png|${PT_OUT}/far.png"
  "-DSTEP6=${PT_CHECK}|offset|--dataset|${PT_SPHERE64}|--csv|${PT_OUT}/near.csv|--csv-b|${PT_OUT}/far.csv|--origin|100000.001,-200000,300000"
  -DEXIT6=1 "-DERR6=FAIL: far from the origin the particles moved"
  ${SL_STEPS})

# ---- contours and splats (particles_contours.*, particles_splat.*): image
# checks on the sphere of radius 0.45 seen side-on by particles-contours-
# check (particles/particles_contours_check.c), which computes the
# silhouette circle from the camera, and goldens of their own.
add_executable(particles-contours-check ${PT_DIR}/particles_contours_check.c)
target_link_libraries(particles-contours-check PRIVATE sightline_test_support sightline_renderer)
set_target_properties(particles-contours-check PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
set(PT_CCHECK $<TARGET_FILE:particles-contours-check>)
# pt_side_on(name params distance): the sphere side-on (azimuth 0, elevation
# 0) at an orbit distance, 256x256, on a white background.
macro(pt_side_on name params distance)
  set(PT_SIDE_ON "${PT_RENDER}|--scene|${PT_BASE}|--set|params=${params}|--set|camera={\"orbit\":{\"azimuth\":0,\"elevation\":0,\"distance\":${distance}},\"fov_y\":45}|--set|background=[1,1,1,1]|--set|width=256|--set|height=256|--out|${PT_OUT}/${name}.png")
  set(PT_SIDE_ON_ARGS "--png|${PT_OUT}/${name}.png|--dataset|${PT_SPHERE64}|--radius|0.45|--distance|${distance}")
endmacro()
# Contour width: the ink integrated across the silhouette at 360 angles,
# median within max(25 %, 1 px) of contour_width at two zooms (the line
# keeps its screen width). Measured median (p10, p90), px: width 2 at
# distance 2.5: 2.63 (2.26, 2.88), at 5: 2.40 (2.10, 2.70); width 4 at 2.5:
# 4.59 (4.25, 4.85), at 5: 4.46 (4.11, 4.69). The 0.4-0.6 px over are the
# coverage ramps of overlapping segments adding up; the line's centre lies
# on the circle (mean radius 32.30 px against 32.29). The move onto the
# contour matters: the plan's first-order move alone gives 3.72 px at width
# 2 (the points land up to T outside), no move 3.84 px: both fail. The twin
# judges the far width-2 image as if the width were 4 (a width in world
# units would halve from 2.5 to 5) and must fail.
foreach(w 2 4)
  foreach(d 2.5 5)
    pt_side_on(contour_w${w}_d${d} "{\"isovalues\":[0.5],\"stipple\":0,\"contours\":1,\"contour_width\":${w},\"set0_color\":[0.05,0.05,0.05]}" ${d})
    pt_test(contours.width_${w}_d${d} ${CMAKE_COMMAND} "-DSTEP1=${PT_SIDE_ON}"
      "-DSTEP2=${PT_CCHECK}|width|${PT_SIDE_ON_ARGS}|--width|${w}" ${SL_STEPS})
  endforeach()
endforeach()
pt_side_on(contour_w2_d5 "" 5)
pt_test(contours.detects_world_width ${CMAKE_COMMAND}
  "-DSTEP1=${PT_CCHECK}|width|${PT_SIDE_ON_ARGS}|--width|4" -DEXIT1=1 "-DERR1=FAIL: contour width" ${SL_STEPS})
set_tests_properties(render.particles.contours.detects_world_width PROPERTIES DEPENDS render.particles.contours.width_2_d5)
# Contours only near the silhouette: ink pixels farther than 3 px from the
# circle (width 2, distance 2.5), measured share 0 of 567 (bound 0.02; 0.028
# with the first-order move only); the twin adds the stipples (ink all over
# the disk: 0.47) and must fail.
pt_side_on(contour_near "{\"isovalues\":[0.5],\"stipple\":0,\"contours\":1,\"set0_color\":[0.05,0.05,0.05]}" 2.5)
pt_test(contours.near_silhouette ${CMAKE_COMMAND} "-DSTEP1=${PT_SIDE_ON}"
  "-DSTEP2=${PT_CCHECK}|near|${PT_SIDE_ON_ARGS}|--far-px|3|--max-far-share|0.02" ${SL_STEPS})
pt_side_on(contour_near_stipple "{\"isovalues\":[0.5],\"stipple\":1,\"contours\":1,\"set0_color\":[0.05,0.05,0.05]}" 2.5)
pt_test(contours.detects_ink_off_silhouette ${CMAKE_COMMAND} "-DSTEP1=${PT_SIDE_ON}"
  "-DSTEP2=${PT_CCHECK}|near|${PT_SIDE_ON_ARGS}|--far-px|3|--max-far-share|0.02"
  -DEXIT2=1 "-DERR2=FAIL: ink away from the silhouette" ${SL_STEPS})
# Splats close the surface and are shaded: inside the projected disk (1.5 px
# inset) the covered share, measured 0.9993 (bound 0.97), and the
# correlation of the luminance with max(0, n.l) of the sphere, measured
# 0.9985 (bound 0.9; mean luminance 0.19 where n.l < 0.25, 0.81 above 0.75), the ink a light grey on black (the unlit side,
# ambient 0.1, stays apart from the background).
# Twins: disks of 0.3 mean spacings leave gaps (cover 0.960); judged with the
# light reversed, the shading correlates negatively (-0.26).
foreach(case "splat;1" "splat_small;0.3")
  list(GET case 0 name)
  list(GET case 1 radius)
  set(PT_SPLAT_${name} "${PT_RENDER}|--scene|${PT_BASE}|--set|params={\"isovalues\":[0.5],\"stipple\":0,\"splat\":1,\"cone_radius\":${radius},\"set0_color\":[0.9,0.9,0.9]}|--set|background=[0,0,0,1]|--set|camera={\"orbit\":{\"azimuth\":0,\"elevation\":0,\"distance\":2.5},\"fov_y\":45}|--set|width=256|--set|height=256|--out|${PT_OUT}/${name}.png")
endforeach()
set(PT_SPLAT_ARGS "--dataset|${PT_SPHERE64}|--radius|0.45|--distance|2.5|--ink|0.9,0.9,0.9")
pt_test(splat.cover_and_shading ${CMAKE_COMMAND} "-DSTEP1=${PT_SPLAT_splat}"
  "-DSTEP2=${PT_CCHECK}|splat|--png|${PT_OUT}/splat.png|${PT_SPLAT_ARGS}|--min-cover|0.97|--min-corr|0.9" ${SL_STEPS})
pt_test(splat.detects_gaps ${CMAKE_COMMAND} "-DSTEP1=${PT_SPLAT_splat_small}"
  "-DSTEP2=${PT_CCHECK}|splat|--png|${PT_OUT}/splat_small.png|${PT_SPLAT_ARGS}|--min-cover|0.97|--min-corr|0.9"
  -DEXIT2=1 "-DERR2=FAIL: splats cover" ${SL_STEPS})
pt_test(splat.detects_reversed_light ${CMAKE_COMMAND}
  "-DSTEP1=${PT_CCHECK}|splat|--png|${PT_OUT}/splat.png|${PT_SPLAT_ARGS}|--light|-0.3,-0.5,-1|--min-cover|0.97|--min-corr|0.9"
  -DEXIT1=1 "-DERR1=FAIL: shading correlation" ${SL_STEPS})
set_tests_properties(render.particles.splat.detects_reversed_light PROPERTIES DEPENDS render.particles.splat.cover_and_shading)
# Goldens (the suite tests/render/particles/goldens_contours, 128x128):
# contours on the torus, and the head phantom's skull splatted under its
# skin with contours. After a deliberate change: sightline-regress
# tests/render/particles/goldens_contours --update, look at them, say so.
pt_test(goldens_contours ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:sightline-regress>|${PT_DIR}/goldens_contours|--out|${PT_OUT}/goldens_contours|--jobs|2"
  "-DOUT1=2 cases, 2 passed, 0 failed, 0 errors"
  ${SL_STEPS})

# ---- focus + context (plan §1.11; renderer/particles/particles_focus.h):
# inside the focus sphere the volume by the shared marcher, outside the
# marks, one depth. particles-focus-check (particles/particles_focus_check.c)
# takes each pixel's centre ray of the scene's view against the analytic
# sphere. The mark tests render single-sample (--samples 1): the depth copy
# of an MSAA target resolves one sample per pixel (particles_focus.c).
add_executable(particles-focus-check ${PT_DIR}/particles_focus_check.c)
target_link_libraries(particles-focus-check PRIVATE sightline_proto sightline_renderer PkgConfig::CJSON)
set_target_properties(particles-focus-check PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
set(PT_FCHECK $<TARGET_FILE:particles-focus-check>)
set(PT_NEAR ${PT_DIR}/focus/near.json)
set(PT_BG 26,26,31)   # the default background (0.1, 0.1, 0.12)
set(PT_OPAQUE "{\"colormap\":\"viridis\",\"opacity\":[[0,1],[1,1]]}")
set(PT_CLEAR "{\"colormap\":\"viridis\",\"opacity\":[[0,0],[1,0]]}")

# (a) volume only (stipple 0): a focus sphere enclosing the volume gives
# volume_dvr's image (same default TF, step, jitter, camera) within the
# volume_dvr bounds, covered mean |dRGB| <= 1 and max <= 4 (measured 0.65
# and 1: the premultiplied blend rounds once more); a sphere of radius 0.35
# leaves every pixel whose ray passes it by more than 1.5 px at the
# background (measured 0 of 12872 differ) and draws inside (2876 of 2876).
pt_test(focus.volume_only ${CMAKE_COMMAND}
  "-DSTEP1=${PT_RENDER}|--scene|${PT_BASE}|--set|params={\"isovalues\":[0.5],\"stipple\":0,\"focus_radius\":100}|--out|${PT_OUT}/focus_enclosing.png"
  "-DSTEP2=${PT_RENDER}|--scene|${PT_BASE}|--set|technique=volume_dvr|--set|params={}|--out|${PT_OUT}/focus_volume_dvr.png"
  "-DSTEP3=$<TARGET_FILE:sightline-diff>|${PT_OUT}/focus_enclosing.png|${PT_OUT}/focus_volume_dvr.png|--background|${PT_BG}|--max-mean|1|--max-abs|4"
  "-DSTEP4=${PT_RENDER}|--scene|${PT_NEAR}|--set|params={\"isovalues\":[0.5],\"stipple\":0,\"focus_radius\":0.35}|--out|${PT_OUT}/focus_small.png"
  "-DSTEP5=${PT_FCHECK}|outside|--scene|${PT_NEAR}|--image|${PT_OUT}/focus_small.png|--background|${PT_BG}|--center|0,0,0|--radius|0.35|--min-inside|2000"
  ${SL_STEPS})

# (b) with marks (no hidden-surface removal, so marks lie both in front of
# the focus sphere, radius 0.35 inside the particles' 0.45, and behind it),
# single-sample, the volume opaque (alpha 1 everywhere): a mark in front of
# the sphere keeps the marks-only image's pixel byte for byte (measured 3974
# pixels, 1760 over the sphere, 0 differ), a mark behind the volume's depth
# shows the volume-only image (997 pixels, max |d| 0), and the depth map is
# the nearer of mark and volume (1436 pixels the volume's, 3974 a mark's,
# max relative error 0).
set(PT_FB "\"isovalues\":[0.5],\"hidden_surface_removal\":0,\"stipple_size\":0.6")
set(PT_FOCUS_B "\"focus_radius\":0.35,\"focus_transfer_function\":${PT_OPAQUE}")
pt_test(focus.with_marks ${CMAKE_COMMAND}
  "-DSTEP1=${PT_RENDER}|--scene|${PT_NEAR}|--samples|1|--set|params={${PT_FB}}|--out|${PT_OUT}/focus_marks.png|--depth|${PT_OUT}/focus_marks.pfm"
  "-DSTEP2=${PT_RENDER}|--scene|${PT_NEAR}|--samples|1|--set|params={${PT_FB},\"stipple\":0,${PT_FOCUS_B}}|--out|${PT_OUT}/focus_dvr.png|--depth|${PT_OUT}/focus_dvr.pfm"
  "-DSTEP3=${PT_RENDER}|--scene|${PT_NEAR}|--samples|1|--set|params={${PT_FB},${PT_FOCUS_B}}|--out|${PT_OUT}/focus_both.png|--depth|${PT_OUT}/focus_both.pfm"
  "-DSTEP4=${PT_FCHECK}|front|--scene|${PT_NEAR}|--image|${PT_OUT}/focus_both.png|--marks|${PT_OUT}/focus_marks.png|--marks-depth|${PT_OUT}/focus_marks.pfm|--center|0,0,0|--radius|0.35|--min|1000"
  "-DSTEP5=${PT_FCHECK}|behind|--image|${PT_OUT}/focus_both.png|--marks-depth|${PT_OUT}/focus_marks.pfm|--dvr|${PT_OUT}/focus_dvr.png|--dvr-depth|${PT_OUT}/focus_dvr.pfm|--min|500|--max-abs|1"
  "-DSTEP6=${PT_FCHECK}|depth|--image-depth|${PT_OUT}/focus_both.pfm|--marks-depth|${PT_OUT}/focus_marks.pfm|--dvr-depth|${PT_OUT}/focus_dvr.pfm|--rel|1e-4|--min|500"
  ${SL_STEPS})

# (c) particles inside the focus sphere are not drawn: a sphere of radius
# 0.2 on the particles' surface towards the eye, the volume fully
# transparent. Without the focus 678 depth pixels lie inside it (shrunk by
# 0.02, the dots' reach), with it 0; pixels whose ray passes the sphere by
# more than 4 px (cones and dots reach about 3) are the marks-only image's
# exactly (0 of 13816 differ), inside 1102 of 1288 differ (the far side shows
# through the hole).
set(PT_FOCUS_C "\"focus_center\":[0.2114,0.1539,0.3662],\"focus_radius\":0.2,\"focus_transfer_function\":${PT_CLEAR}")
pt_test(focus.culls_inside ${CMAKE_COMMAND}
  "-DSTEP1=${PT_RENDER}|--scene|${PT_NEAR}|--samples|1|--out|${PT_OUT}/focus_c_marks.png|--depth|${PT_OUT}/focus_c_marks.pfm"
  "-DSTEP2=${PT_RENDER}|--scene|${PT_NEAR}|--samples|1|--set|params={\"isovalues\":[0.5],${PT_FOCUS_C}}|--out|${PT_OUT}/focus_c.png|--depth|${PT_OUT}/focus_c.pfm"
  "-DSTEP3=${PT_FCHECK}|inside|--scene|${PT_NEAR}|--depth|${PT_OUT}/focus_c_marks.pfm|--center|0.2114,0.1539,0.3662|--radius|0.2|--tol|0.02|--min|300"
  "-DSTEP4=${PT_FCHECK}|inside|--scene|${PT_NEAR}|--depth|${PT_OUT}/focus_c.pfm|--center|0.2114,0.1539,0.3662|--radius|0.2|--tol|0.02|--min|0|--max|0"
  "-DSTEP5=${PT_FCHECK}|outside|--scene|${PT_NEAR}|--image|${PT_OUT}/focus_c.png|--reference|${PT_OUT}/focus_c_marks.png|--center|0.2114,0.1539,0.3662|--radius|0.2|--margin|4|--min-inside|500"
  ${SL_STEPS})

# Each check fails on the wrong image: the volume alone as "with marks"
# (front), the marks alone (behind), the marks' depth as the frame's
# (depth), the marks without a focus (inside), the enclosing sphere's image
# as the small sphere's (outside).
pt_test(focus.detects_errors ${CMAKE_COMMAND}
  "-DSTEP1=${PT_FCHECK}|front|--scene|${PT_NEAR}|--image|${PT_OUT}/focus_dvr.png|--marks|${PT_OUT}/focus_marks.png|--marks-depth|${PT_OUT}/focus_marks.pfm|--center|0,0,0|--radius|0.35"
  -DEXIT1=1 "-DOUT1=FAIL: [0-9]+ pixels with a mark in front"
  "-DSTEP2=${PT_FCHECK}|behind|--image|${PT_OUT}/focus_marks.png|--marks-depth|${PT_OUT}/focus_marks.pfm|--dvr|${PT_OUT}/focus_dvr.png|--dvr-depth|${PT_OUT}/focus_dvr.pfm"
  -DEXIT2=1 "-DOUT2=FAIL: [0-9]+ pixels with a mark behind"
  "-DSTEP3=${PT_FCHECK}|depth|--image-depth|${PT_OUT}/focus_marks.pfm|--marks-depth|${PT_OUT}/focus_marks.pfm|--dvr-depth|${PT_OUT}/focus_dvr.pfm"
  -DEXIT3=1 "-DOUT3=FAIL: [0-9]+ depth pixels are not the nearer"
  "-DSTEP4=${PT_FCHECK}|inside|--scene|${PT_NEAR}|--depth|${PT_OUT}/focus_c_marks.pfm|--center|0.2114,0.1539,0.3662|--radius|0.2|--tol|0.02|--min|0|--max|0"
  -DEXIT4=1 "-DOUT4=FAIL: [0-9]+ depth pixels inside the sphere"
  "-DSTEP5=${PT_RENDER}|--scene|${PT_NEAR}|--set|params={\"isovalues\":[0.5],\"stipple\":0,\"focus_radius\":100}|--out|${PT_OUT}/focus_near_enclosing.png"
  "-DSTEP6=${PT_FCHECK}|outside|--scene|${PT_NEAR}|--image|${PT_OUT}/focus_near_enclosing.png|--background|${PT_BG}|--center|0,0,0|--radius|0.35"
  -DEXIT6=1 "-DOUT6=FAIL: [0-9]+ pixels outside the focus sphere"
  ${SL_STEPS})
set_tests_properties(render.particles.focus.detects_errors PROPERTIES
  DEPENDS "render.particles.focus.with_marks;render.particles.focus.culls_inside")

# The golden (suite goldens_focus): the head phantom's skin as stipples
# with a focus sphere cut into it on the viewer's side, the skull and brain
# inside drawn by the marcher (the paper's Fig. 10 idea). After a deliberate
# change: sightline-regress tests/render/particles/goldens_focus --update,
# look at the golden, and say so in the commit.
pt_test(goldens_focus ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:sightline-regress>|${PT_DIR}/goldens_focus|--out|${PT_OUT}/goldens_focus|--jobs|1"
  "-DOUT1=1 cases, 1 passed, 0 failed, 0 errors"
  ${SL_STEPS})

# ---- hatching (particles_hatch.h; the paper's sec. 4.2.3). hatch-check
# (particles/hatch_check.c) drives sl_pipeline in process and reads the
# hatch cache through the checker-only hooks of particles_debug.h.
add_executable(hatch-check ${PT_DIR}/hatch_check.c)
target_link_libraries(hatch-check PRIVATE sightline_test_support sightline_renderer)
set_target_properties(hatch-check PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
set(PT_HATCH $<TARGET_FILE:hatch-check>)
# The stroke cache is rebuilt only when a parameter it depends on changes:
# not for a camera move, a width or a threshold (per frame), once for a new
# length or cross-hatching on. The twin expects a rebuild for a threshold
# change and fails.
pt_test(hatch.rebuild ${CMAKE_COMMAND}
  "-DSTEP1=${PT_HATCH}|rebuild|--dataset|${PT_TORUS64}|--param|isovalues=0|--param|hatch=1|--step|camera:0|--step|hatch_width=2:0|--step|hatch_threshold=0.5:0|--step|hatch_length=3:1|--step|cross_hatching=1:1|--step|camera:0"
  ${SL_STEPS})
pt_test(hatch.rebuild_detects_stale ${CMAKE_COMMAND}
  "-DSTEP1=${PT_HATCH}|rebuild|--dataset|${PT_TORUS64}|--param|isovalues=0|--param|hatch=1|--step|hatch_threshold=0.5:1"
  -DEXIT1=1 "-DOUT1=FAIL: hatch_threshold=0.5 rebuilt the hatch strokes 0 times"
  ${SL_STEPS})
# Curvature mode follows the main principal direction (the meridian, around
# the tube, where 1/r = 4 dominates): on the torus (5068 particles), the 528
# with reliability >= 0.9 have strokes (the chord of the vertices next to the
# particle, in its tangent plane) at a mean of 2.87 deg and a p90 of 5.07 deg
# (max 7.3) from pref_torus_curvature's main direction, with the fallback
# hatch_direction (1,0,0) across it. What is left is the paper's blend
# (1 - w) s' towards the fallback, w = the neighbours' mean reliability
# (about 0.9 there: up to atan(0.1/0.9) = 6 deg). Bounds: mean 4, p90 7.
# The twin in fixed mode (the same direction) is 45.1 deg off and fails.
foreach(case "follows_main_direction;curvature;0;direction: [0-9]+ of" "detects_fixed;fixed;1;FAIL: mean angle")
  list(GET case 0 name)
  list(GET case 1 mode)
  list(GET case 2 exit)
  list(GET case 3 out)
  pt_test(hatch.${name} ${CMAKE_COMMAND}
    "-DSTEP1=${PT_HATCH}|direction|--dataset|${PT_TORUS64}|--major|0.55|--minor|0.25|--param|isovalues=0|--param|hatch=1|--param|hatch_mode=${mode}|--param|hatch_direction=[1,0,0]|--min-reliability|0.9|--max-mean-deg|4|--max-p90-deg|7"
    -DEXIT1=${exit} "-DOUT1=${out}"
    ${SL_STEPS})
endforeach()
# Goldens (suite tests/render/particles/goldens_hatch, 128x128, the built-in
# limits): the head phantom's skin hatched along a fixed direction, the torus
# along its smoothed main principal directions (around the tube), and the
# skin lit from the side with cross-hatching (three tones). After a
# deliberate change: sightline-regress tests/render/particles/goldens_hatch
# --update, look at the new goldens, and say so in the commit.
pt_test(hatch.goldens ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:sightline-regress>|${PT_DIR}/goldens_hatch|--out|${PT_OUT}/goldens_hatch|--jobs|2"
  "-DOUT1=3 cases, 3 passed, 0 failed, 0 errors"
  ${SL_STEPS})

# ---- curvature transfer function (curvature_coloring, curvature_tf;
# renderer/particles/particles_tf2d.h). tf2d-check judges the colour of the
# torus seen along its axis (64^3, iso 0, dark inside: k1 = +0.107 per voxel
# at the inner equator, 0 on top, -0.040 at the outer equator; k2 = -0.127)
# with red at k1 = +0.08 and blue at -0.08 (equal weights at k1 = 0): red
# inside 23 px (the top ring, radius 0.55, at 128x128), blue outside.
# Measured: inside red share 1.000 (629 px), outside blue share 1.000
# (845 px); between 22 and 24 px the shares stay 1.000. With the colouring off (the set's bit 0)
# or the two colours swapped the check must fail. Goldens: the suite
# goldens_tf2d (the red/blue torus and the default function over a grey
# ink); after a deliberate change: sightline-regress
# tests/render/particles/goldens_tf2d --update, and look at them.
add_executable(tf2d-check ${PT_DIR}/tf2d_check.c)
target_link_libraries(tf2d-check PRIVATE sightline_renderer)
set_target_properties(tf2d-check PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
set(PT_TF2D_RB "{\"range\":0.25,\"widgets\":[[0.08,-0.13,0.12,1,0,0,1],[-0.08,-0.13,0.12,0,0,1,1]]}")
set(PT_TF2D_BR "{\"range\":0.25,\"widgets\":[[0.08,-0.13,0.12,0,0,1,1],[-0.08,-0.13,0.12,1,0,0,1]]}")
set(PT_TF2D_CAM "{\"orbit\":{\"azimuth\":0,\"elevation\":0,\"distance\":2.2},\"fov_y\":45}")
foreach(case "follows_curvature;1;${PT_TF2D_RB};0" "detects_off;0;${PT_TF2D_RB};1" "detects_swap;1;${PT_TF2D_BR};1")
  list(GET case 0 name)
  list(GET case 1 mask)
  list(GET case 2 tf)
  list(GET case 3 exit)
  set(PT_TF2D_LINE "-DOUT2=inside 23 px: red share 1.000.*blue share 1.000")
  if(exit)
    set(PT_TF2D_LINE "-DERR2=tf2d-check: needs at least")
  endif()
  pt_test(tf2d.${name} ${CMAKE_COMMAND}
    "-DSTEP1=${PT_RENDER}|--scene|${PT_BASE}|--set|dataset=${PT_TORUS64}|--set|camera=${PT_TF2D_CAM}|--set|params={\"isovalues\":[0],\"stipple_size\":1.0,\"curvature_coloring\":${mask},\"curvature_tf\":${tf}}|--out|${PT_OUT}/tf2d_${name}.png"
    "-DSTEP2=$<TARGET_FILE:tf2d-check>|--png|${PT_OUT}/tf2d_${name}.png|--split|23" -DEXIT2=${exit} "${PT_TF2D_LINE}"
    ${SL_STEPS})
endforeach()
pt_test(goldens_tf2d ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:sightline-regress>|${PT_DIR}/goldens_tf2d|--out|${PT_OUT}/goldens_tf2d|--jobs|2"
  "-DOUT1=2 cases, 2 passed, 0 failed, 0 errors"
  ${SL_STEPS})
