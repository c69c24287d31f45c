# Camera paths through sightline-render (proto/scene.md "Paths", issue 17):
# a path of three keys renders one file per frame at 1 frame per second, and
# frame 1 (t = 1, a key) is exactly the single scene of that key's camera and
# parameters (max |dRGB| 0: the same determinism as single frames); frame 0
# is not (the twin must fail). The command line refuses a path without a
# frame-number pattern, --frames beside a path, and --path on a scene
# without one, before rendering.
set(PATHS_DIR ${CMAKE_CURRENT_SOURCE_DIR}/paths)
set(PATHS_OUT ${SL_RENDER_OUT}/paths)
file(MAKE_DIRECTORY ${PATHS_OUT})
set(PATHS_RENDER $<TARGET_FILE:sightline-render>)
set(PATHS_DIFF $<TARGET_FILE:sightline-diff>)

sl_add_render_test(NAME paths.key_frame_is_the_scene COMMAND ${CMAKE_COMMAND}
  "-DSTEP1=${PATHS_RENDER}|--path|${PATHS_DIR}/helix_path.json|--out|${PATHS_OUT}/helix_%02d.png"
  "-DOUT1=wrote 3 frames .*2.00 s of path at 1 fps"
  "-DSTEP2=${PATHS_RENDER}|--scene|${PATHS_DIR}/helix_key1.json|--out|${PATHS_OUT}/helix_key1.png"
  "-DSTEP3=${PATHS_DIFF}|${PATHS_OUT}/helix_01.png|${PATHS_OUT}/helix_key1.png|--max-abs|0"
  "-DSTEP4=${CMAKE_COMMAND}|-E|cat|${PATHS_OUT}/helix_02.png"
  ${SL_STEPS})
sl_add_render_test(NAME paths.detects_other_frame COMMAND ${CMAKE_COMMAND}
  "-DSTEP1=${PATHS_RENDER}|--path|${PATHS_DIR}/helix_path.json|--out|${PATHS_OUT}/other_%02d.png"
  "-DSTEP2=${PATHS_RENDER}|--scene|${PATHS_DIR}/helix_key1.json|--out|${PATHS_OUT}/other_key1.png"
  "-DSTEP3=${PATHS_DIFF}|${PATHS_OUT}/other_00.png|${PATHS_OUT}/other_key1.png|--max-abs|0"
  -DEXIT3=1 "-DOUT3=\"pass\":[ \t]*false"
  ${SL_STEPS})

function(paths_cli name err)
  string(REPLACE ";" "|" args "${ARGN}")
  sl_add_render_test(NAME paths.cli.${name} COMMAND ${CMAKE_COMMAND}
    "-DSTEP1=${PATHS_RENDER}|${args}" -DEXIT1=1 "-DERR1=${err}" ${SL_STEPS})
endfunction()
paths_cli(needs_pattern "a path needs a file name pattern with one %d or %0Nd"
  --path ${PATHS_DIR}/helix_path.json --out ${PATHS_OUT}/x.png)
paths_cli(frames_beside_path "renders its own frames; --frames does not apply"
  --path ${PATHS_DIR}/helix_path.json --out ${PATHS_OUT}/x_%d.png --frames 3)
paths_cli(scene_without_path "the scene has no \"path\""
  --path ${PATHS_DIR}/helix_key1.json --out ${PATHS_OUT}/x_%d.png)
