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
