# sightline-lrfit command line (tools/sightline_lrfit.c): bad options are
# refused with exit 2 and a sentence; a small fit of the analytic abc field
# runs, reports its final statistics and writes a .lr.gz file whose first
# lines are the LRsplines header (order 3, dim 3, not rational).
set(lrfit_out ${CMAKE_BINARY_DIR}/lrfit-test)
file(MAKE_DIRECTORY ${lrfit_out})
add_test(NAME tools.lrfit_refuses COMMAND ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:sightline-lrfit>" -DEXIT1=2 "-DERR1=no VOLUME given"
  "-DSTEP2=$<TARGET_FILE:sightline-lrfit>|field:abc:8" -DEXIT2=2 "-DERR2=no --out file given"
  "-DSTEP3=$<TARGET_FILE:sightline-lrfit>|field:abc:8|--out|${lrfit_out}/x.lr|--degree|7" -DEXIT3=2 "-DERR3=bad value for --degree"
  "-DSTEP4=$<TARGET_FILE:sightline-lrfit>|field:abc:8|--out|${lrfit_out}/x.lr|--tol|-1" -DEXIT4=2 "-DERR4=bad value for --tol"
  "-DSTEP5=$<TARGET_FILE:sightline-lrfit>|field:abc:8|--out|${lrfit_out}/x.lr|--frobnicate|1" -DEXIT5=2 "-DERR5=unknown option --frobnicate"
  "-DSTEP6=$<TARGET_FILE:sightline-lrfit>|field:abc:8|--out|${lrfit_out}/x.lr|--max-levels" -DEXIT6=2 "-DERR6=--max-levels needs a value"
  "-DSTEP7=$<TARGET_FILE:sightline-lrfit>|field:nope:8|--out|${lrfit_out}/x.lr" -DEXIT7=1 "-DERR7=unknown field 'nope'"
  "-DSTEP8=$<TARGET_FILE:sightline-lrfit>|tornado|--out|${lrfit_out}/x.lr" -DEXIT8=1 "-DERR8=not a scalar volume or vector field"
  ${SL_STEPS})
add_test(NAME tools.lrfit_abc COMMAND ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:sightline-lrfit>|field:abc:12|--tol|0.2|--max-levels|2|--out|${lrfit_out}/abc.lr.gz"
  "-DOUT1=final: [0-9]+ elements, [0-9]+ basis functions.*wrote"
  "-DSTEP2=gzip|-dc|${lrfit_out}/abc.lr.gz"
  "-DOUT2=^# LRSPLINE VOLUME\n#\tp1\tp2\tp3\tNbasis\tNline\tNel\tdim\trat\n\t3\t3\t3\t[0-9]+\t[0-9]+\t[0-9]+\t3\t0\n# Basis functions:\n0: \\["
  ${SL_STEPS})
set_tests_properties(tools.lrfit_refuses tools.lrfit_abc PROPERTIES ENVIRONMENT "${SL_TEST_ENV}" TIMEOUT 300)
