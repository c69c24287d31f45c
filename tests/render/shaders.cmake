# Compiles every embedded shader stage file on its own (tests/render/shaders_check.c):
# each .vert/.tesc/.tese/.geom/.frag/.comp.glsl under renderer/, with its
# includes resolved and every #if variant its technique can select; every
# other .glsl must be included by a stage file. The negative tests feed
# shaders-check broken files from tests/render/shaders/ and expect exit 1 with
# the file, the mapped line and the compiler's log.
add_executable(shaders-check ${CMAKE_CURRENT_SOURCE_DIR}/shaders_check.c)
target_link_libraries(shaders-check PRIVATE sightline_renderer)
set_target_properties(shaders-check PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)

sl_add_render_test(NAME shaders.compile_all COMMAND shaders-check)
sl_add_render_test(NAME shaders.detects_compile_error
  COMMAND ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:shaders-check>|--file|${CMAKE_CURRENT_SOURCE_DIR}/shaders/broken.frag.glsl"
  -DEXIT1=1 "-DERR1=FAIL [^\n]*broken\\.frag\\.glsl \\(fragment shader\\)[^\n]*\n  [^\n]*broken\\.frag\\.glsl:11[^\n]*error"
  ${SL_STEPS})
sl_add_render_test(NAME shaders.detects_missing_include
  COMMAND ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:shaders-check>|--file|${CMAKE_CURRENT_SOURCE_DIR}/shaders/missing_include.vert.glsl"
  -DEXIT1=1 "-DERR1=missing_include\\.vert\\.glsl:3: #include \"gpu/glsl/no_such_file\\.glsl\": no such embedded file"
  ${SL_STEPS})
sl_add_render_test(NAME shaders.detects_variant_error
  COMMAND ${CMAKE_COMMAND}
  "-DSTEP1=$<TARGET_FILE:shaders-check>|--file|${CMAKE_CURRENT_SOURCE_DIR}/shaders/broken_variant.comp.glsl"
  -DEXIT1=1 "-DERR1=FAIL [^\n]*broken_variant\\.comp\\.glsl \\(compute shader, MODE=2 \\)[^\n]*\n  [^\n]*broken_variant\\.comp\\.glsl:12[^\n]*undeclared_value"
  "-DOUT1=ok   [^\n]*broken_variant\\.comp\\.glsl +compute +MODE=1"
  ${SL_STEPS})
