# GPU golden-image tests of the `lr_volume` technique (renderer/lr_volume/)
# through sightline-regress: the suite tests/render/lr_volume/goldens/ (LR
# volumes from the lr_field generator, 128x128, limits of suite.json: mean 1
# and 0.5 % of the covered pixels over 8): a graded-knot sphere in composite
# with the adaptive step (k-d forest look-up, auto), Marschner-Lobb of degree
# 3 in MIP with a uniform step through a 4^3 k-d forest, a vector field by
# its magnitude through one k-d tree, and that field with 24 streamlines
# traced on the GPU and drawn as tubes inside it, and with 20 traced by RKF5
# in double over the volume's own k-d tree blocks, depth map checked too
# (vector_streamlines_double) (these five with "jitter": false, the midpoint
# lattice they were made with), and the graded sphere at uniform step 1 with
# the default per-pixel jitter (sphere_jitter). The
# look-up paths matter: llvmpipe drew
# a line of wrong rays through the tree look-ups' unbounded loops (fixed in
# lr_lookup.glsl); these goldens hold the fixed images. The numerical checks
# of lr_volume (against volume_dvr on the trilinear-equivalent spline,
# adaptive against uniform) are unit.test_lr_volume, those of its
# streamlines unit.test_lr_volume_streamlines.
# After a deliberate change: sightline-regress tests/render/lr_volume/goldens
# --update, look at the new goldens, and say so in the commit.
sl_add_render_test(NAME lr_volume.goldens COMMAND ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:sightline-regress>|${CMAKE_CURRENT_SOURCE_DIR}/lr_volume/goldens|--out|${SL_RENDER_OUT}/lr_volume_goldens|--jobs|2|--junit|${SL_RENDER_OUT}/lr_volume_goldens.xml"
  "-DOUT1=7 cases, 7 passed, 0 failed, 0 errors"
  ${SL_STEPS})
