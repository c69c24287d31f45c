# GPU tests of `volume_dvr` (renderer/volume_dvr/, renderer/volume/): frames
# against the CPU double-precision reference (tests/support/volume_reference.h,
# the model of renderer/volume_dvr/README.md), stress cases, work per change and
# golden images. The check program and scenes live in tests/render/volume_dvr/.
set(VOLUME_DIR ${CMAKE_CURRENT_SOURCE_DIR}/volume_dvr)
add_executable(volume-check ${VOLUME_DIR}/volume_check.c)
target_link_libraries(volume-check PRIVATE sightline_test_support sightline_proto sightline_renderer)
set_target_properties(volume-check PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)

function(volume_test name)
  sl_add_render_test(NAME volume_dvr.${name} COMMAND ${ARGN})
endfunction()

# Against the reference at step 0.25, 128x128, orbit 30/20/2.5, jitter off:
# composite mean |dRGB| <= 1 and max <= 4 (0..255, every channel of every
# pixel), mip max <= 1, iso distance within 1e-3 of the box diagonal over the
# pixels both hit, at most 0.5 % of the hit pixels hit in one image only.
# Measured (llvmpipe): composite mean <= 0.0001, max 1; mip max <= 1; iso
# distance error <= 3.6e-6 of the diagonal, no pixel hit by one only;
# composite depth <= 6.9e-7 (ML), one pixel of the CT one step (6.3e-4) off
# where alpha reaches 0.5 within rounding of a sample. The
# transfer functions put colour and opacity where each field has structure.
set(ML "{\"generator\":\"marschner_lobb\",\"size\":41}")
set(ML_TF "[[0.3,0,0,0,0],[0.5,1,0.6,0.2,0.3],[0.7,0.2,0.5,1,0.6]]")
set(TORUS "{\"generator\":\"torus\",\"size\":48}")
set(TORUS_TF "[[-0.3,0,0,0,0],[-0.05,1,0.8,0.3,0.4],[0.0,0.9,0.3,0.1,0.9],[0.05,0.2,0.3,1,0.1],[0.3,0,0,1,0]]")
set(TORUS_MIP_TF "[[0,0,0,0,0],[0.5,0.2,0.5,1,0.5],[1.2,1,1,0.5,1]]")
set(CT ${CMAKE_SOURCE_DIR}/data/samples/cranium.nhdr)
set(CT_TF "[[-1000,0,0,0,0],[200,0.8,0.5,0.3,0.0],[400,1,0.9,0.8,0.3],[1500,1,1,1,0.9]]")
set(MRI ${CMAKE_SOURCE_DIR}/data/samples/ch2.nii.gz)
set(MRI_TF "[[0,0,0,0,0],[40,0.3,0.3,0.5,0.0],[90,1,0.8,0.6,0.15],[255,1,1,1,0.6]]")
foreach(case "ml;${ML};${ML_TF};${ML_TF};0.5" "torus;${TORUS};${TORUS_TF};${TORUS_MIP_TF};0"
             "ct;${CT};${CT_TF};${CT_TF};400" "mri;${MRI};${MRI_TF};${MRI_TF};80")
  list(GET case 0 name)
  list(GET case 1 src)
  list(GET case 2 tf)
  list(GET case 3 mip_tf)
  list(GET case 4 iso)
  volume_test(reference.${name}.composite volume-check compare --dataset ${src} --size 128
    --params "{\"step\":0.25,\"transfer_function\":${tf}}" --tol-mean 1 --tol-max 4 --depth-tol 1e-3)
  volume_test(reference.${name}.mip volume-check compare --dataset ${src} --size 128
    --params "{\"step\":0.25,\"mode\":\"mip\",\"transfer_function\":${mip_tf}}" --tol-mean 1 --tol-max 1)
  volume_test(reference.${name}.iso volume-check compare --dataset ${src} --size 128
    --params "{\"step\":0.25,\"mode\":\"iso\",\"isovalue\":${iso},\"transfer_function\":${tf}}"
    --depth-tol 1e-3 --max-miss-pct 0.5)
endforeach()
# Nearest-voxel interpolation and a clip box follow the same model.
volume_test(reference.ml.nearest_clipped volume-check compare --dataset ${ML} --size 128
  --params "{\"step\":0.25,\"interpolation\":\"nearest\",\"clip_min\":[0.2,0,0.1],\"clip_max\":[1,0.7,1],\"transfer_function\":${ML_TF}}")

# Interactive frames (camera drags) sample at twice the step: an interactive
# frame at step 0.25 matches the reference at step 0.5. Measured: max |dRGB| 0
# (mean 0.0000); the still frame at step 0.25 against the same reference is
# max 3, mean 0.094, so the check fails without the doubling.
volume_test(reference.ml.interactive_step volume-check compare --dataset ${ML} --size 128 --interactive 1
  --ref-step 0.5 --params "{\"step\":0.25,\"transfer_function\":${ML_TF}}" --tol-max 1)
volume_test(reference.ml.interactive_step_detects_still
  ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:volume-check>|compare|--dataset|${ML}|--size|128|--ref-step|0.5|--params|{\"step\":0.25,\"transfer_function\":${ML_TF}}|--tol-max|1"
  -DEXIT1=1 "-DERR1=check failed: max"
  ${SL_STEPS})

# The check catches a renderer without opacity correction: against a
# reference that leaves it out, the same frame is far off (measured mean
# 11.1, max 135) and must fail.
volume_test(reference.detects_missing_opacity_correction
  ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:volume-check>|compare|--dataset|${ML}|--size|128|--params|{\"step\":0.25,\"transfer_function\":${ML_TF}}|--ref-uncorrected|1"
  -DEXIT1=1 "-DERR1=check failed: mean"
  ${SL_STEPS})

# Stress (96x96, step 0.25, same limits as composite): a constant volume
# with shading on (zero gradient: unlit, so equal to the unshaded reference,
# no NaN), 1x1x32 and 32x32x1 (one-voxel axes are a slab one spacing thick),
# spacing 1x1x4, f32 1e30 voxels (beyond the TF's last point: its colour),
# NaN voxels (transparent; seen through a clip box), the eye inside the
# volume (orbit distance 0.5 radii), and an all-transparent transfer
# function: background only, every sample skipped, none taken.
set(STRESS_TF "[[0,0,0,0,0],[0.4,0.2,0.4,1,0.05],[0.6,1,0.7,0.2,0.3],[1,1,1,1,0.6]]")
volume_test(stress.constant_shaded volume-check compare --dataset synthetic:constant --size 96
  --params "{\"step\":0.25,\"shading\":true,\"transfer_function\":${STRESS_TF}}")
foreach(v line slab aniso huge)
  volume_test(stress.${v} volume-check compare --dataset synthetic:${v} --size 96
    --params "{\"step\":0.25,\"transfer_function\":${STRESS_TF}}")
endforeach()
# NaN: a transfer function opaque at its low end, so a NaN read as any
# value would show (clamped into the table, NaN lands on texel 0).
set(NAN_TF "[[0,0.2,0.4,1,0.3],[0.6,1,0.7,0.2,0.3],[1,1,1,1,0.6]]")
volume_test(stress.nan_clipped volume-check compare --dataset synthetic:nan --size 96
  --params "{\"step\":0.25,\"clip_max\":[1,1,0.5],\"transfer_function\":${NAN_TF}}")
volume_test(stress.nan_mip volume-check compare --dataset synthetic:nan --size 96
  --params "{\"step\":0.25,\"mode\":\"mip\",\"transfer_function\":${NAN_TF}}" --tol-max 1)
volume_test(stress.nan_iso volume-check compare --dataset synthetic:nan --size 96
  --params "{\"step\":0.25,\"mode\":\"iso\",\"isovalue\":0.7,\"clip_max\":[1,1,0.5],\"transfer_function\":${NAN_TF}}"
  --depth-tol 1e-3)
volume_test(stress.eye_inside volume-check compare --dataset ${ML} --size 96 --orbit 30,20,0.5
  --params "{\"step\":0.25,\"transfer_function\":${STRESS_TF}}")
volume_test(stress.all_transparent volume-check compare --dataset ${ML} --size 96
  --params "{\"step\":0.25,\"transfer_function\":[[0,1,1,1,0],[1,1,1,1,0]]}" --tol-max 0 --max-samples 0 --min-skipped 1)

# Empty-space skipping changes no pixel (composite, mip, iso on the CT) and
# skips most samples where the transfer function leaves air transparent
# (measured 87 % composite at 128^2; 29 % mip; iso most).
volume_test(skipping.ct_composite volume-check compare --dataset ${CT} --size 96
  --params "{\"step\":0.25,\"transfer_function\":${CT_TF}}" --skipping-equal 1 --min-skipped 0.5)
volume_test(skipping.ct_mip volume-check compare --dataset ${CT} --size 96
  --params "{\"step\":0.25,\"mode\":\"mip\",\"transfer_function\":${CT_TF}}" --tol-max 1 --skipping-equal 1 --min-skipped 0.1)
volume_test(skipping.ct_iso volume-check compare --dataset ${CT} --size 96
  --params "{\"step\":0.25,\"mode\":\"iso\",\"isovalue\":400,\"transfer_function\":${CT_TF}}" --depth-tol 1e-3
  --skipping-equal 1 --min-skipped 0.5)
# Runs of visible bricks (sampled without a lookup per brick) and of
# invisible ones on the MRI with shading (the reference does not shade, so
# only skipping on = off is checked there: measured max |dRGB| 0, 61 %
# skipped), and with the eye inside the volume.
volume_test(skipping.mri_composite_shaded volume-check compare --dataset ${MRI} --size 96
  --params "{\"step\":0.25,\"shading\":true,\"transfer_function\":${MRI_TF}}" --tol-mean 255 --tol-max 255
  --skipping-equal 1 --min-skipped 0.3)
volume_test(skipping.mri_inside volume-check compare --dataset ${MRI} --size 96 --orbit 10,5,0.4
  --params "{\"step\":0.25,\"transfer_function\":${MRI_TF}}" --skipping-equal 1)

# Work per change (sl_volume_counters, sl_frame_stats.prepared): the first
# frame uploads the volume and builds the min-max grid once; a camera move
# uploads nothing; a transfer-function change re-bakes the TF and rebuilds
# the mask only; step/shading/interpolation/clip touch nothing; a mode or
# isovalue change rebuilds the mask only. Nothing re-prepares.
volume_test(work_skipped volume-check work --dataset ${ML})

# sightline-render: the transfer function through --set (a different image),
# a bad point refused naming it (exit 2), and --stats reporting the samples
# skipped (head phantom, air transparent).
volume_test(cli.set_transfer_function
  ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:sightline-render>|--scene|${VOLUME_DIR}/composite.json|--out|${SL_RENDER_OUT}/volume_cli_a.png|--samples|1"
  "-DSTEP2=$<TARGET_FILE:sightline-render>|--scene|${VOLUME_DIR}/composite.json|--out|${SL_RENDER_OUT}/volume_cli_b.png|--samples|1|--set|params.transfer_function=[[0.2,1,0,0,0],[0.6,1,1,0,0.5]]"
  "-DSTEP3=$<TARGET_FILE:sightline-diff>|${SL_RENDER_OUT}/volume_cli_a.png|${SL_RENDER_OUT}/volume_cli_b.png|--max-mean|1"
  -DEXIT3=1 "-DOUT3=\"failed\":[ \t]*\\[\"max_mean\"\\]"
  "-DSTEP4=$<TARGET_FILE:sightline-render>|--scene|${VOLUME_DIR}/composite.json|--out|${SL_RENDER_OUT}/volume_cli_c.png|--set|params.transfer_function=[[0,0,0,0,0],[1,1,1,1,1.5]]"
  -DEXIT4=2 "-DERR4=parameter 'transfer_function': point 1: alpha 1.5 is outside \\[0, 1\\]"
  "-DSTEP5=$<TARGET_FILE:sightline-render>|--scene|${VOLUME_DIR}/composite.json|--out|${SL_RENDER_OUT}/volume_cli_d.png|--set|params.transfer_function={\"colormap\":\"gray\",\"opacity\":[[0.6,0],[0.2,1]]}"
  -DEXIT5=2 "-DERR5=point 1: t 0.2 is below point 0's 0.6"
  ${SL_STEPS})
volume_test(cli.stats_skipped
  ${CMAKE_COMMAND} -DRENDER=$<TARGET_FILE:sightline-render> -DSCENE=${VOLUME_DIR}/head_composite.json
  -DOUT=${SL_RENDER_OUT} -DNAME=volume_stats -DSKIPPED=1 -P ${CMAKE_SOURCE_DIR}/tests/stats_skipping.cmake)

# Golden images (llvmpipe, 128x128, samples 1, jitter off), one per mode:
# composite with shading (Marschner-Lobb), mip (head phantom, magma), iso
# (torus, clipped): the suite tests/render/volume_dvr/goldens through
# sightline-regress, each case an expect file naming a scene of this folder,
# with the limits these tests had (suite.json: the voxel_lines goldens',
# over covered pixels: mean <= 1, <= 0.5 % off by more than 8, samples 1).
# After a deliberate change: sightline-regress tests/render/volume_dvr/goldens
# --update, look at the new goldens, and say so in the commit.
file(MAKE_DIRECTORY ${SL_RENDER_OUT}/volume_dvr)
volume_test(goldens
  ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:sightline-regress>|${VOLUME_DIR}/goldens|--out|${SL_RENDER_OUT}/volume_dvr/goldens|--jobs|2|--junit|${SL_RENDER_OUT}/volume_dvr/goldens.xml"
  "-DOUT1=6 cases, 6 passed, 0 failed, 0 errors"
  ${SL_STEPS})

# sightline-info counts NaN voxels (f32): a 2x2x1 raw volume with two NaN,
# one 1e30 and one 0.5 (little-endian bytes written by printf).
volume_test(info_counts_nan
  sh -c "printf '\\000\\000\\300\\177\\000\\000\\000\\077\\000\\000\\300\\177\\312\\362\\111\\161' > ${SL_RENDER_OUT}/nan4.raw && printf '{\"raw\":\"nan4.raw\",\"dims\":[2,2,1],\"type\":\"f32\"}' > ${SL_RENDER_OUT}/nan4.json && $<TARGET_FILE:sightline-info> ${SL_RENDER_OUT}/nan4.json | tee /dev/stderr | grep -q '\"nan_voxels\":[[:space:]]*2'")

# The precomputed gradient texture (gradient = texture) shades the smooth
# torus isosurface like the central differences of the iso golden: covered
# mean |diff| <= 1.5 (measured 0.31; unlit normals would be ~82 off).
volume_test(gradient_texture_matches
  ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:sightline-render>|--scene|${VOLUME_DIR}/iso.json|--out|${SL_RENDER_OUT}/volume_iso_gradtex.png|--samples|1|--set|params.gradient=texture"
  "-DSTEP2=$<TARGET_FILE:sightline-diff>|${SL_RENDER_OUT}/volume_iso_gradtex.png|${VOLUME_DIR}/goldens/golden/iso.png|--max-mean|1.5|--background|26,26,31"
  ${SL_STEPS})
