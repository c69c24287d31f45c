# The headless GL context's error paths and device choice (renderer/gpu/egl_context.c),
# and the sightline-render command line checks that happen before rendering
# (tools/sightline_render.c). Each test runs sightline-render in a fresh
# process (the EGL environment variables act at driver load) through the step
# runner tests/steps.cmake, and names the exact exit code
# (1 usage, 2 bad input, 3 GPU) and a stderr regex, so a crash or a sanitizer
# report cannot pass for an expected failure. The in-process candidate loop
# (fallback from a failing candidate, explicit choices not falling back) is
# tests/unit/test_gpu.c.
set(GPU_OUT ${SL_RENDER_OUT}/gpu)
file(MAKE_DIRECTORY ${GPU_OUT})
set(GPU_RENDER $<TARGET_FILE:sightline-render>)
set(GPU_DIFF $<TARGET_FILE:sightline-diff>)
set(GPU_STEPS ${SL_STEPS})
set(GPU_TINY ${CMAKE_CURRENT_SOURCE_DIR}/tubes_mesh/tiny.json)

# gpu_case(NAME name EXIT code ERR regex [OUT regex] [ENV VAR=value ...] ARGS sightline-render args...)
function(gpu_case)
  cmake_parse_arguments(G "" "NAME;EXIT;ERR;OUT" "ENV;ARGS" ${ARGN})
  string(REPLACE ";" "|" args "${G_ARGS}")
  set(extra)
  if(DEFINED G_OUT)
    list(APPEND extra "-DOUT1=${G_OUT}")
  endif()
  sl_add_render_test(NAME ${G_NAME} COMMAND ${CMAKE_COMMAND}
    "-DSTEP1=${GPU_RENDER}|${args}" -DEXIT1=${G_EXIT} "-DERR1=${G_ERR}" ${extra} ${GPU_STEPS})
  if(G_ENV)
    set_property(TEST render.${G_NAME} APPEND PROPERTY ENVIRONMENT ${G_ENV})
  endif()
endfunction()

set(GPU_ARGS --scene ${GPU_TINY} --out ${GPU_OUT}/tiny.png)

# ---- EGL: no display, no 4.5 context, bad overrides (exit 3), good overrides.
# An EGL vendor list naming no file: libglvnd finds no vendor, so no display at all.
gpu_case(NAME gpu.no_egl_display EXIT 3
  ERR "GPU: no EGL display: neither a GPU device \\(EGL_EXT_platform_device\\) nor Mesa surfaceless is available"
  ENV __EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json ARGS ${GPU_ARGS})
# Mesa capped at GL 3.3: every candidate fails the 4.5 core context; the message names each.
gpu_case(NAME gpu.no_gl45_context EXIT 3
  ERR "GPU: no usable OpenGL 4\\.5 core context: [^\n]*Mesa surfaceless: cannot create an OpenGL 4\\.5 core context \\(EGL error 0x[0-9a-f]+\\)"
  ENV MESA_GL_VERSION_OVERRIDE=3.3 ARGS ${GPU_ARGS})
foreach(bad abc -1 1x)
  gpu_case(NAME gpu.bad_device_${bad} EXIT 3
    ERR "GPU: SIGHTLINE_EGL_DEVICE must be 'software' or a device index \\(0, 1, \\.\\.\\.\\), got '${bad}'"
    ENV SIGHTLINE_EGL_DEVICE=${bad} ARGS ${GPU_ARGS})
endforeach()
gpu_case(NAME gpu.device_99_missing EXIT 3
  ERR "GPU: EGL device 99 requested but only [0-9]+ device\\(s\\) exist"
  ENV SIGHTLINE_EGL_DEVICE=99 ARGS ${GPU_ARGS})
# Forced software: Mesa's software device or surfaceless, llvmpipe, labelled software.
gpu_case(NAME gpu.device_software EXIT 0
  ERR "sightline: OpenGL renderer: llvmpipe [^\n]*\\(software\\)" OUT "wrote [^\n]*tiny\\.png"
  ENV SIGHTLINE_EGL_DEVICE=software ARGS ${GPU_ARGS})
# Device 0 by index: whatever it is (Mesa's software device in CI), labelled from its renderer string.
gpu_case(NAME gpu.device_0 EXIT 0
  ERR "sightline: OpenGL renderer: [^\n]+ \\((software|hardware)\\)" OUT "wrote [^\n]*tiny\\.png"
  ENV SIGHTLINE_EGL_DEVICE=0 ARGS ${GPU_ARGS})
# More MSAA samples than the GPU offers (llvmpipe: 4) is a GPU limit: exit 3, checked before rendering.
gpu_case(NAME gpu.samples_above_limit EXIT 3
  ERR "GPU: 16 MSAA samples requested, this GPU offers at most [0-9]+\nsightline-render: lower --samples"
  ENV SIGHTLINE_EGL_DEVICE=software ARGS ${GPU_ARGS} --samples 16)

# ---- sightline-render arguments and outputs, all refused before the GPU is
# touched: each regex is anchored at the start of stderr, where the renderer
# line would be had a context been made (and the dataset and render follow it).
gpu_case(NAME cli.frames_not_integer EXIT 1 ERR "^sightline-render: --frames must be an integer in \\[1, 100000\\], got '3x'"
  ARGS ${GPU_ARGS} --frames 3x)
gpu_case(NAME cli.samples_not_integer EXIT 1 ERR "^sightline-render: --samples must be an integer in \\[0, 16\\], got '2\\.0'"
  ARGS ${GPU_ARGS} --samples 2.0)
gpu_case(NAME cli.stray_argument EXIT 1 ERR "^sightline-render: unexpected argument 'extra'" ARGS ${GPU_ARGS} extra)
gpu_case(NAME cli.option_without_value EXIT 1 ERR "^sightline-render: --depth needs a value" ARGS ${GPU_ARGS} --depth)
gpu_case(NAME cli.unknown_option EXIT 1 ERR "^sightline-render: unknown option '--colour'" ARGS ${GPU_ARGS} --colour red)
foreach(case
    "out_folder_missing|--out ${GPU_OUT}/no_such_folder/x.png|--out [^\n]*no_such_folder/x\\.png: folder [^\n]* does not exist"
    "out_extension|--out ${GPU_OUT}/x.bmp|--out [^\n]*x\\.bmp: unknown extension \\(expected \\.png, \\.jpg, \\.jpeg\\)"
    "out_is_folder|--out ${GPU_OUT}/folder.png|--out [^\n]*folder\\.png: is a folder"
    "depth_extension|--out ${GPU_OUT}/x.png --depth ${GPU_OUT}/x.png|--depth [^\n]*x\\.png: unknown extension \\(expected \\.pfm\\)"
    "stats_unwritable|--out ${GPU_OUT}/x.png --stats /proc/sightline_stats.json|--stats /proc/sightline_stats\\.json: cannot create files in /proc"
    "stats_extension|--out ${GPU_OUT}/x.png --stats ${GPU_OUT}/stats.txt|--stats [^\n]*stats\\.txt: unknown extension \\(expected \\.json\\)")
  string(REPLACE "|" ";" parts "${case}")
  list(GET parts 0 name)
  list(GET parts 1 outs)
  list(GET parts 2 regex)
  separate_arguments(outs)
  gpu_case(NAME cli.${name} EXIT 2 ERR "^sightline-render: ${regex}" ARGS --scene ${GPU_TINY} ${outs})
endforeach()
file(MAKE_DIRECTORY ${GPU_OUT}/folder.png)
# --export on a technique without export_geometry: a usage error once the scene
# names the technique, before the GPU, listing the techniques that export.
gpu_case(NAME cli.export_not_offered EXIT 1
  ERR "^sightline-render: technique 'tubes_mesh' exports nothing \\(--export is offered by: [^)\n]+\\)"
  ARGS ${GPU_ARGS} --export ${GPU_OUT}/tiny.csv)
# --stats always holds "prepare_extra", the technique's named numbers: an
# empty object for volume_dvr, which reports none (a 16^3 volume, 16x16).
sl_add_render_test(NAME cli.stats_prepare_extra COMMAND ${CMAKE_COMMAND}
  "-DSTEP1=${GPU_RENDER}|--scene|${CMAKE_CURRENT_SOURCE_DIR}/volume_dvr/composite.json|--set|width=16|--set|height=16|--set|dataset={\"generator\":\"marschner_lobb\",\"size\":16}|--samples|1|--out|${GPU_OUT}/extra.png|--stats|${GPU_OUT}/extra.json"
  "-DSTEP2=${CMAKE_COMMAND}|-E|cat|${GPU_OUT}/extra.json"
  "-DOUT2=\"prepare_extra\":[ \t]*{[ \t\n]*}"
  ${GPU_STEPS})
# Scene checks (exit 2): the range of elevation, orbit_frames without an orbit.
gpu_case(NAME cli.elevation_out_of_range EXIT 2
  ERR "^sightline-render: [^\n]*camera\\.orbit\\.elevation must be in \\[-89\\.9, 89\\.9\\] degrees, got 100"
  ARGS ${GPU_ARGS} --set camera.orbit.elevation=100)
gpu_case(NAME cli.orbit_frames_needs_orbit EXIT 2
  ERR "^(sightline-render: note: [^\n]*\n)*sightline-render: [^\n]*orbit_frames turns an orbit camera, but this camera is eye/target/up"
  ARGS ${GPU_ARGS} --set camera.eye=[0,0,5] --set camera.target=[0,0,0] --set orbit_frames=4)
# An orbit field set on an eye/target/up camera switches it to an orbit (eye, target
# and up dropped) and says so; it is not an "orbit camera's up" error.
gpu_case(NAME cli.orbit_replaces_eye_target_up EXIT 0
  ERR "note: --set camera\\.orbit\\.distance=2 replaces the scene's eye/target/up camera with an orbit"
  ARGS ${GPU_ARGS} --set camera.eye=[0,0,5] --set camera.target=[0,0,0] --set camera.up=[0,1,0]
       --set camera.orbit.distance=2)

# ---- orbit_frames through --frames: the last frame written is frame N-1, at
# azimuth + (N-1) 360 / orbit_frames. Frame 2 of 4 equals one frame at
# azimuth + 180 exactly (same camera in double), and differs from frame 0.
set(ORBIT_SCENE --scene ${CMAKE_CURRENT_SOURCE_DIR}/tubes_mesh/tornado.json
  "--set|dataset={\"generator\":\"tornado\",\"lines\":30,\"seed\":1}" --set width=64 --set height=64
  --set camera.orbit.azimuth=10)
string(REPLACE ";" "|" orbit_args "${ORBIT_SCENE}")
sl_add_render_test(NAME cli.orbit_frames COMMAND ${CMAKE_COMMAND}
  "-DSTEP1=${GPU_RENDER}|${orbit_args}|--set|orbit_frames=4|--frames|3|--out|${GPU_OUT}/orbit_f2.png"
  "-DSTEP2=${GPU_RENDER}|${orbit_args}|--set|camera.orbit.azimuth=190|--out|${GPU_OUT}/orbit_az190.png"
  "-DSTEP3=${GPU_DIFF}|${GPU_OUT}/orbit_f2.png|${GPU_OUT}/orbit_az190.png|--max-abs|0"
  "-DSTEP4=${GPU_RENDER}|${orbit_args}|--set|orbit_frames=4|--frames|1|--out|${GPU_OUT}/orbit_f0.png"
  "-DSTEP5=${GPU_DIFF}|${GPU_OUT}/orbit_f0.png|${GPU_OUT}/orbit_f2.png|--max-abs|0"
  -DEXIT5=1 "-DOUT5=\"failed\":[ \t]*\\[\"max_abs\"\\]"
  ${GPU_STEPS})
