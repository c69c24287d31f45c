# Embeds every renderer/**/*.glsl into one generated C file (sl_embedded.c)
# holding a table {path below renderer/, text, size}; see renderer/gpu/sl_gpu.h.
function(sightline_embed_glsl out_var)
  file(GLOB_RECURSE glsl_files CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/renderer/*.glsl)
  set(out ${CMAKE_BINARY_DIR}/generated/sl_embedded.c)
  add_custom_command(
    OUTPUT ${out}
    COMMAND ${CMAKE_COMMAND} -DROOT=${CMAKE_SOURCE_DIR}/renderer -DOUT=${out}
            "-DFILES=${glsl_files}" -P ${CMAKE_SOURCE_DIR}/cmake/embed_files.cmake
    DEPENDS ${glsl_files} ${CMAKE_SOURCE_DIR}/cmake/embed_files.cmake
    COMMENT "Embedding shaders"
    VERBATIM)
  set(${out_var} ${out} PARENT_SCOPE)
endfunction()
