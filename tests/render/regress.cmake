# sightline-regress (tools/sightline_regress.c, issue 17) on real suites. The
# ribbons goldens (tests/render/ribbons/goldens) are copied to a scratch
# folder: as they are, every case passes; with one golden perturbed (+5 on its
# drawn pixels by golden-offset) the run exits 1, prints that one case as
# FAIL and its JUnit report lists exactly one failure, in that case; --update
# then rewrites that golden only ("golden changed", the others "golden
# unchanged") and the next run passes again. A suite of a path (3 frames, one
# golden a frame) and a still case with a depth check round-trips from empty
# goldens (a first run fails: "no golden"). A suite whose expect file has a
# typo, or one that belongs to no case, is refused with exit 2. The tubes_mesh
# goldens (tests/render/tubes_mesh/goldens) are cases that name a scene of
# that folder and --set overrides in their expect files.
set(RG_OUT ${SL_RENDER_OUT}/regress)
set(RG_REGRESS $<TARGET_FILE:sightline-regress>)
set(RG_SRC ${CMAKE_CURRENT_SOURCE_DIR})

sl_add_render_test(NAME regress.perturbed_golden COMMAND ${CMAKE_COMMAND}
  "-DSTEP1=${CMAKE_COMMAND}|-E|rm|-rf|${RG_OUT}/perturbed"
  "-DSTEP2=${CMAKE_COMMAND}|-E|copy_directory|${RG_SRC}/ribbons/goldens|${RG_OUT}/perturbed/ribbons/goldens"
  "-DSTEP3=${CMAKE_COMMAND}|-E|copy|${RG_SRC}/ribbons/s_curve.vtk|${RG_SRC}/ribbons/helix_base.vtk|${RG_SRC}/ribbons/bifurcation.vtk|${RG_OUT}/perturbed/ribbons"
  "-DSTEP4=${RG_REGRESS}|${RG_OUT}/perturbed/ribbons/goldens|--out|${RG_OUT}/perturbed/out|--jobs|2"
  "-DOUT4=4 cases, 4 passed, 0 failed"
  "-DSTEP5=$<TARGET_FILE:golden-offset>|${RG_SRC}/ribbons/goldens/golden/face_on.png|${RG_OUT}/perturbed/ribbons/goldens/golden/face_on.png|26,26,31|5"
  "-DSTEP6=${RG_REGRESS}|${RG_OUT}/perturbed/ribbons/goldens|--out|${RG_OUT}/perturbed/out|--junit|${RG_OUT}/perturbed/junit.xml"
  -DEXIT6=1 "-DOUT6=FAIL    face_on: frame 0: max_mean exceeded.*4 cases, 3 passed, 1 failed, 0 errors"
  "-DSTEP7=${CMAKE_COMMAND}|-E|cat|${RG_OUT}/perturbed/junit.xml"
  "-DOUT7=tests=\"4\" failures=\"1\" errors=\"0\""
  "-DSTEP8=${CMAKE_COMMAND}|-E|cat|${RG_OUT}/perturbed/junit.xml"
  "-DOUT8=name=\"face_on\" time=\"[0-9.]+\">[^<]*<failure message=\"frame 0: max_mean"
  "-DSTEP9=${RG_REGRESS}|${RG_OUT}/perturbed/ribbons/goldens|--out|${RG_OUT}/perturbed/out|--update"
  "-DOUT9=UPDATED face_on: golden changed.*same    helix: golden unchanged.*1 goldens updated, 3 unchanged"
  "-DSTEP10=${RG_REGRESS}|${RG_OUT}/perturbed/ribbons/goldens|--out|${RG_OUT}/perturbed/out"
  "-DOUT10=4 cases, 4 passed, 0 failed"
  ${SL_STEPS})

sl_add_render_test(NAME regress.path_round_trip COMMAND ${CMAKE_COMMAND}
  "-DSTEP1=${CMAKE_COMMAND}|-E|rm|-rf|${RG_OUT}/path"
  "-DSTEP2=${CMAKE_COMMAND}|-E|copy_directory|${RG_SRC}/regress/path_suite|${RG_OUT}/path/regress/path_suite"
  "-DSTEP3=${CMAKE_COMMAND}|-E|copy|${RG_SRC}/ribbons/helix_base.vtk|${RG_OUT}/path/ribbons/helix_base.vtk"
  "-DSTEP4=${RG_REGRESS}|${RG_OUT}/path/regress/path_suite|--out|${RG_OUT}/path/out"
  -DEXIT4=1 "-DOUT4=FAIL    flight: no golden .*flight/00000.png"
  "-DSTEP5=${RG_REGRESS}|${RG_OUT}/path/regress/path_suite|--out|${RG_OUT}/path/out|--update"
  "-DOUT5=2 goldens updated, 0 unchanged, 0 errors"
  "-DSTEP6=${CMAKE_COMMAND}|-E|cat|${RG_OUT}/path/regress/path_suite/golden/flight/00002.png"
  "-DSTEP7=${RG_REGRESS}|${RG_OUT}/path/regress/path_suite|--out|${RG_OUT}/path/out|--jobs|2"
  "-DOUT7=2 cases, 2 passed, 0 failed, 0 errors"
  ${SL_STEPS})

sl_add_render_test(NAME regress.bad_suite COMMAND ${CMAKE_COMMAND}
  "-DSTEP1=${RG_REGRESS}|${RG_SRC}/regress/bad_suite|--out|${RG_OUT}/bad"
  -DEXIT1=2 "-DERR1=tiny.expect.json: max_meen: unknown field"
  ${SL_STEPS})
# An expect file that is no case's (no NAME.json beside it, no "scene") is refused too.
sl_add_render_test(NAME regress.orphan_expect COMMAND ${CMAKE_COMMAND}
  "-DSTEP1=${RG_REGRESS}|${RG_SRC}/regress/orphan_suite|--out|${RG_OUT}/orphan"
  -DEXIT1=2 "-DERR1=lost.expect.json has no case lost.json and names no scene"
  ${SL_STEPS})
