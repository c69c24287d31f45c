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

# sightline-trace --gpu on an LR-spline volume: tests/data/lr/refined_quadratic.lr.gz
# (a file of the reference library: the identity map v(x) = x on [0,1]^3 as a
# locally refined quadratic, 1240 elements, sides 1/16 .. 1/4), so the
# streamlines are x0 e^t, exact. 8 box seeds, rk4 h = 0.02 until they leave
# the box. CPU: within 1e-7 of x0 e^t (h^4 truncation; measured 1.1e-10 at
# h = 0.01), ending on a face; GPU double = CPU to 1e-12 of the box (same
# rows), mixed to 1e-7 (same rows); single against the exact solution to 1e-5
# (its boundary bisection in float can drop one sample, so rows may differ).
# Heuristic steps (H = 0.5 times the element's min side / 2^2) cross elements
# of different sizes: CPU within 1e-7 of x0 e^t, GPU double = CPU to 1e-12,
# mixed to 1e-7 (same rows, so the same step per element).
set(FLOW_LR ${CMAKE_SOURCE_DIR}/tests/data/lr/refined_quadratic.lr.gz)
set(FLOW_LR_ARGS ${FLOW_LR}|--seed-box|0.1,0.1,0.1,0.5,0.5,0.5,8|--solver|rk4|--step|0.02|--t-max|3)
set(FLOW_LR_HEUR ${FLOW_LR}|--seed-box|0.1,0.1,0.1,0.5,0.5,0.5,8|--solver|rk4|--step|0.5|--heuristic|--t-max|3)
file(MAKE_DIRECTORY ${FLOW_OUT}/lr)
sl_add_render_test(NAME flow.trace_lr_gpu_matches_cpu COMMAND ${CMAKE_COMMAND}
  "-DSTEP1=${FLOW_TRACE}|${FLOW_LR_ARGS}|--out|${FLOW_OUT}/lr/cpu.csv"
  "-DOUT1=traced 8 lines, .*stops: boundary 8"
  "-DSTEP2=${FLOW_CHECK}|verify-exp|${FLOW_OUT}/lr/cpu.csv|8|1e-7"
  "-DSTEP3=${FLOW_TRACE}|${FLOW_LR_ARGS}|--gpu|--precision|double|--out|${FLOW_OUT}/lr/double.csv"
  "-DOUT3=traced 8 lines, .*stops: boundary 8"
  "-DSTEP4=${FLOW_CHECK}|compare|${FLOW_OUT}/lr/cpu.csv|${FLOW_OUT}/lr/double.csv|1e-12|1"
  "-DSTEP5=${FLOW_TRACE}|${FLOW_LR_ARGS}|--gpu|--precision|mixed|--out|${FLOW_OUT}/lr/mixed.csv"
  "-DSTEP6=${FLOW_CHECK}|compare|${FLOW_OUT}/lr/cpu.csv|${FLOW_OUT}/lr/mixed.csv|1e-7|1"
  "-DSTEP7=${FLOW_TRACE}|${FLOW_LR_ARGS}|--gpu|--precision|single|--out|${FLOW_OUT}/lr/single.csv"
  "-DSTEP8=${FLOW_CHECK}|verify-exp|${FLOW_OUT}/lr/single.csv|8|1e-5"
  ${SL_STEPS})
sl_add_render_test(NAME flow.trace_lr_gpu_heuristic COMMAND ${CMAKE_COMMAND}
  "-DSTEP1=${FLOW_TRACE}|${FLOW_LR_HEUR}|--out|${FLOW_OUT}/lr/cpu_h.csv"
  "-DSTEP2=${FLOW_CHECK}|verify-exp|${FLOW_OUT}/lr/cpu_h.csv|8|1e-7"
  "-DSTEP3=${FLOW_TRACE}|${FLOW_LR_HEUR}|--gpu|--precision|double|--out|${FLOW_OUT}/lr/double_h.csv"
  "-DSTEP4=${FLOW_CHECK}|compare|${FLOW_OUT}/lr/cpu_h.csv|${FLOW_OUT}/lr/double_h.csv|1e-12|1"
  "-DSTEP5=${FLOW_TRACE}|${FLOW_LR_HEUR}|--gpu|--precision|mixed|--out|${FLOW_OUT}/lr/mixed_h.csv"
  "-DSTEP6=${FLOW_CHECK}|compare|${FLOW_OUT}/lr/cpu_h.csv|${FLOW_OUT}/lr/mixed_h.csv|1e-7|1"
  ${SL_STEPS})
