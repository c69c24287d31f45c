#!/usr/bin/python3
"""vtk_volume.py — VTK's volume mappers as the peers of bench-volume-dvr (bench/bench_volume_dvr.c).

    xvfb-run -a /usr/bin/python3 bench/vtk_volume.py --raw VOL.raw --type float32 --dims X Y Z
        --spacing SX SY SZ --origin OX OY OZ --tf "v,r,g,b,a;..." --step S --mapper gpu|fixed
        --cameras CAMERAS.txt --size WxH --background R,G,B [--png PREFIX]

Renders the volume of VOL.raw (x fastest, native little-endian, values at
voxel centres as vtkImageData places them) with vtkGPUVolumeRayCastMapper or
vtkFixedPointVolumeRayCastMapper, the way a VTK user would: composite
blending, trilinear interpolation, no shading, a colour and a scalar-opacity
transfer function through the same control points, sample distance = step x
the smallest spacing, and the scalar opacity unit distance = the smallest
spacing (VTK's own opacity correction: the TF is per that distance, as ours
is per step_ref). Cameras as bench/vtk_tubes.py: one frame a line, "VIEW
INDEX ex ey ez tx ty tz ux uy uz fov_y_deg" (INDEX < 0: an untimed warm-up).
Each frame sets the vtkCamera, renders, waits for the GL (WaitForCompletion)
and reads the frame back into host memory, so its wall time is what a user
waits. --png writes the first timed frame of each view to PREFIX-VIEW.png.

Prints one JSON line: {"ok": true, "first_frame_ms", "gl_renderer",
"views": {VIEW: {"median_ms", "min_ms", "max_ms", "frames"}}}, or
{"ok": false, "error": "..."} (exit status 1).
"""
import argparse
import json
import statistics
import sys
import time

from vtk_peer_common import fail, gl_renderer_of, read_cameras


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--raw", required=True)
    ap.add_argument("--type", required=True, choices=["float32", "int16", "uint16", "uint8"])
    ap.add_argument("--dims", type=int, nargs=3, required=True)
    ap.add_argument("--spacing", type=float, nargs=3, required=True)
    ap.add_argument("--origin", type=float, nargs=3, required=True)
    ap.add_argument("--tf", required=True)
    ap.add_argument("--step", type=float, required=True)
    ap.add_argument("--mapper", choices=["gpu", "fixed"], required=True)
    ap.add_argument("--cameras", required=True)
    ap.add_argument("--size", required=True)
    ap.add_argument("--background", default="0.1,0.1,0.12")
    ap.add_argument("--png")
    a = ap.parse_args()
    try:
        import vtk
        from vtk.util import numpy_support
        import numpy
    except Exception as e:  # the package is optional (bench/packages.txt)
        fail("cannot import vtk/numpy: %s" % e)
    w, h = (int(v) for v in a.size.split("x"))
    dtype = {"float32": numpy.float32, "int16": numpy.int16, "uint16": numpy.uint16, "uint8": numpy.uint8}[a.type]
    data = numpy.fromfile(a.raw, dtype=dtype)
    if data.size != a.dims[0] * a.dims[1] * a.dims[2]:
        fail("%s holds %d values, dims say %d" % (a.raw, data.size, a.dims[0] * a.dims[1] * a.dims[2]))
    image = vtk.vtkImageData()
    image.SetDimensions(*a.dims)
    image.SetSpacing(*a.spacing)
    image.SetOrigin(*a.origin)
    arr = numpy_support.numpy_to_vtk(data, deep=True)
    arr.SetName("values")
    image.GetPointData().SetScalars(arr)
    color = vtk.vtkColorTransferFunction()
    opacity = vtk.vtkPiecewiseFunction()
    for point in a.tf.split(";"):
        v, r, g, b, al = (float(x) for x in point.split(","))
        color.AddRGBPoint(v, r, g, b)
        opacity.AddPoint(v, al)
    hmin = min(a.spacing)
    prop = vtk.vtkVolumeProperty()
    prop.SetColor(color)
    prop.SetScalarOpacity(opacity)
    prop.SetInterpolationTypeToLinear()
    prop.ShadeOff()
    prop.SetScalarOpacityUnitDistance(hmin)
    if a.mapper == "gpu":
        mapper = vtk.vtkGPUVolumeRayCastMapper()
        mapper.SetAutoAdjustSampleDistances(0)
        mapper.SetSampleDistance(a.step * hmin)
        mapper.SetUseJittering(0)
    else:
        mapper = vtk.vtkFixedPointVolumeRayCastMapper()
        mapper.SetAutoAdjustSampleDistances(0)
        mapper.SetSampleDistance(a.step * hmin)
        mapper.SetInteractiveSampleDistance(a.step * hmin)
        mapper.SetImageSampleDistance(1.0)
    mapper.SetBlendModeToComposite()
    mapper.SetInputData(image)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)
    ren = vtk.vtkRenderer()
    ren.AddVolume(volume)
    ren.SetBackground(*(float(x) for x in a.background.split(",")))
    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetMultiSamples(0)
    win.AddRenderer(ren)
    win.SetSize(w, h)
    cam = ren.GetActiveCamera()
    frames = read_cameras(a.cameras)
    times, first_ms, written = {}, None, set()
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(win)
    grab.ReadFrontBufferOff()
    for view, index, c in frames:
        cam.SetPosition(c[0], c[1], c[2])
        cam.SetFocalPoint(c[3], c[4], c[5])
        cam.SetViewUp(c[6], c[7], c[8])
        cam.SetViewAngle(c[9])
        ren.ResetCameraClippingRange()
        t0 = time.perf_counter()
        win.Render()
        win.WaitForCompletion()
        grab.Modified()
        grab.Update()
        ms = (time.perf_counter() - t0) * 1000.0
        if first_ms is None:
            first_ms = ms
        if index >= 0:
            times.setdefault(view, []).append(ms)
            if a.png and view not in written:
                png = vtk.vtkPNGWriter()
                png.SetFileName("%s-%s.png" % (a.png, view))
                png.SetInputConnection(grab.GetOutputPort())
                png.Write()
                written.add(view)
    renderer = gl_renderer_of(win)
    out = {"ok": True, "first_frame_ms": first_ms, "gl_renderer": renderer, "views": {}}
    for view, v in times.items():
        out["views"][view] = {"median_ms": statistics.median(v), "min_ms": min(v), "max_ms": max(v), "frames": len(v)}
    print(json.dumps(out))


if __name__ == "__main__":
    main()
