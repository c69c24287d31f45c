# Camera paths through sightline-render (proto/scene.md "Paths", issue 17):
# a path of three keys renders one file per frame at 1 frame per second, and
# frame 1 (t = 1, a key) is exactly the single scene of that key's camera and
# parameters (max |dRGB| 0: the same determinism as single frames); frame 0
# is not (the twin must fail). The command line refuses a path without a
# frame-number pattern, --frames beside a path, and --path on a scene
# without one, before rendering. Videos (--video): the same path as H.264
# and VP9, read back by video-probe (tests/support/video_reader: libavformat
# and libavcodec's decoder, not the writer): codec, 3 frames, size, fps, the
# BT.709 tag, and frame 1 within a mean |dRGB| of the PNG frame 1 over its
# covered pixels (thin coloured tubes at 96x96 are the worst case of 4:2:0
# colour: measured 3.44 for H.264 at CRF 18 — 2.94 even at CRF 10 — and
# 6.10 for VP9 at CRF 24; H.264 is 1.67 at 320x320); the twin compares
# frame 0 with that PNG and must fail.
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

add_executable(video-probe ${PATHS_DIR}/video_probe.c)
target_link_libraries(video-probe PRIVATE sightline_test_support sightline_renderer)
set_target_properties(video-probe PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
set(PATHS_PROBE $<TARGET_FILE:video-probe>)
foreach(case "mp4;h264;4.5" "webm;vp9;7.5")
  list(GET case 0 ext)
  list(GET case 1 codec)
  list(GET case 2 mean)
  sl_add_render_test(NAME paths.video_${ext} COMMAND ${CMAKE_COMMAND}
    "-DSTEP1=${PATHS_RENDER}|--path|${PATHS_DIR}/helix_path.json|--out|${PATHS_OUT}/v${ext}_%02d.png|--video|${PATHS_OUT}/helix.${ext}"
    "-DOUT1=wrote video .*: 3 frames"
    "-DSTEP2=${PATHS_PROBE}|${PATHS_OUT}/helix.${ext}|--frames|3|--size|96x96|--codec|${codec}|--fps|1|--compare|${PATHS_OUT}/v${ext}_01.png|--index|1|--max-mean|${mean}"
    ${SL_STEPS})
endforeach()
sl_add_render_test(NAME paths.video_detects_wrong_frame COMMAND ${CMAKE_COMMAND}
  "-DSTEP1=${PATHS_RENDER}|--path|${PATHS_DIR}/helix_path.json|--out|${PATHS_OUT}/vw_%02d.png|--video|${PATHS_OUT}/wrong.mp4"
  "-DSTEP2=${PATHS_PROBE}|${PATHS_OUT}/wrong.mp4|--frames|3|--size|96x96|--codec|h264|--fps|1|--compare|${PATHS_OUT}/vw_01.png|--index|0|--max-mean|3"
  -DEXIT2=1 "-DERR2=FAIL: frame 0 is [0-9.]+ off"
  ${SL_STEPS})

function(paths_cli name code err)
  string(REPLACE ";" "|" args "${ARGN}")
  sl_add_render_test(NAME paths.cli.${name} COMMAND ${CMAKE_COMMAND}
    "-DSTEP1=${PATHS_RENDER}|${args}" -DEXIT1=${code} "-DERR1=${err}" ${SL_STEPS})
endfunction()
paths_cli(needs_pattern 1 "a path needs a file name pattern with one %d or %0Nd"
  --path ${PATHS_DIR}/helix_path.json --out ${PATHS_OUT}/x.png)
paths_cli(frames_beside_path 1 "renders its own frames; --frames does not apply"
  --path ${PATHS_DIR}/helix_path.json --out ${PATHS_OUT}/x_%d.png --frames 3)
paths_cli(odd_video_size 2 "video 95x96: width and height must be even"
  --path ${PATHS_DIR}/helix_path.json --video ${PATHS_OUT}/odd.mp4 --set width=95)
paths_cli(crf_without_video 1 "--crf sets the quality of --video"
  --path ${PATHS_DIR}/helix_path.json --out ${PATHS_OUT}/c_%d.png --crf 20)
paths_cli(scene_without_path 1 "the scene has no \"path\""
  --path ${PATHS_DIR}/helix_key1.json --out ${PATHS_OUT}/x_%d.png)
