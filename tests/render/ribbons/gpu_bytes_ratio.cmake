# gpu_bytes_ratio.cmake — checks that one sightline-render --stats JSON reports at
# least MIN_RATIO times the gpu_bytes of another (the ribbons memory target: the
# static mesh at least 5x the pulling pipeline's GPU memory).
# usage: cmake -DLARGE=a.json -DSMALL=b.json -DMIN_RATIO=5 -P gpu_bytes_ratio.cmake
# Prints "gpu_bytes LARGE / SMALL = x.yy"; exit 1 with "FAIL: ..." when below.
cmake_minimum_required(VERSION 3.25)
foreach(var LARGE SMALL MIN_RATIO)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "gpu_bytes_ratio.cmake: -D${var}= is required")
  endif()
endforeach()
file(READ "${LARGE}" large_json)
file(READ "${SMALL}" small_json)
string(JSON large GET "${large_json}" gpu_bytes)
string(JSON small GET "${small_json}" gpu_bytes)
if(NOT large MATCHES "^[0-9]+$" OR NOT small MATCHES "^[1-9][0-9]*$")
  message(FATAL_ERROR "FAIL: gpu_bytes not positive integers: ${large} (${LARGE}), ${small} (${SMALL})")
endif()
math(EXPR hundredths "${large} * 100 / ${small}")
math(EXPR whole "${hundredths} / 100")
math(EXPR frac "${hundredths} % 100")
if(frac LESS 10)
  set(frac "0${frac}")
endif()
message("gpu_bytes ${large} / ${small} = ${whole}.${frac}")
math(EXPR need "${small} * ${MIN_RATIO}")
if(large LESS need)
  message(FATAL_ERROR "FAIL: gpu_bytes ratio ${whole}.${frac} is below ${MIN_RATIO} (${large} / ${small})")
endif()
