#!/usr/bin/python3
"""vtk_tubes.py — the VTK tube filter baseline of bench-tubes (bench/bench_tubes.c).

    xvfb-run -a /usr/bin/python3 bench/vtk_tubes.py --lines LINES.vtk --cameras CAMERAS.txt
        --size WxH --radius R [--sides 12] [--caps 1] [--png PREFIX]

Renders the polylines of LINES.vtk (legacy VTK POLYDATA; point scalars, when
present, are per-vertex radii: the tube filter then varies the radius by the
absolute scalar, else every tube has radius R) as vtkTubeFilter tubes with a
vtkPolyDataMapper, the way a VTK user would, with the cameras of CAMERAS.txt:
one frame a line, "VIEW INDEX ex ey ez tx ty tz ux uy uz fov_y_deg" (the
coordinates of the lines file; INDEX < 0: an untimed warm-up frame). Each
frame sets the vtkCamera (position, focal point, view up, view angle = the
vertical field of view), renders without multisampling and waits for the GL
to finish (glFinish through WaitForCompletion, then a readback of the whole
frame into host memory, as Sightline's harness does), so its wall time is
what a user waits. The image of each view's first timed frame
goes to PREFIX-VIEW.png with --png.

Prints one JSON line on stdout: {"ok": true, "filter_ms", "first_frame_ms",
"triangles", "points", "gl_renderer", "views": {VIEW: {"median_ms",
"min_ms", "max_ms", "frames"}}}, or {"ok": false, "error": "..."} (exit status 1). Debian's VTK
is built for X11 only: run under xvfb-run with /usr/bin/python3 (other Python
installs do not see Debian's modules); bench/packages.txt lists the packages.
"""
import argparse
import json
import statistics
import sys
import time

from vtk_peer_common import fail, gl_renderer_of, read_cameras


def main():
    ap = argparse.ArgumentParser(description="VTK tube filter baseline of bench-tubes")
    ap.add_argument("--lines", required=True)
    ap.add_argument("--cameras", required=True)
    ap.add_argument("--size", required=True)
    ap.add_argument("--radius", type=float, required=True)
    ap.add_argument("--sides", type=int, default=12)
    ap.add_argument("--caps", type=int, default=1)
    ap.add_argument("--png", default="")
    a = ap.parse_args()
    try:
        width, height = (int(v) for v in a.size.lower().split("x"))
    except ValueError:
        fail("--size WxH")
    try:
        import vtk
    except ImportError as e:
        fail("no VTK for %s (Debian: python3-vtk9): %s" % (sys.executable, e))
    vtk.vtkObject.GlobalWarningDisplayOff()

    frames = read_cameras(a.cameras)
    reader = vtk.vtkPolyDataReader()
    reader.SetFileName(a.lines)
    reader.Update()
    lines = reader.GetOutput()
    if lines.GetNumberOfPoints() == 0:
        fail("no points read from %s" % a.lines)

    tube = vtk.vtkTubeFilter()
    tube.SetInputData(lines)
    tube.SetRadius(a.radius)
    tube.SetNumberOfSides(a.sides)
    tube.SetCapping(1 if a.caps else 0)
    if lines.GetPointData().GetScalars() is not None:
        tube.SetVaryRadiusToVaryRadiusByAbsoluteScalar()  # radius = the scalar (per-vertex radius)
    t0 = time.perf_counter()
    tube.Update()
    filter_ms = (time.perf_counter() - t0) * 1e3
    tubes = tube.GetOutput()
    triangles = 0
    for cells in (tubes.GetStrips(), tubes.GetPolys()):
        triangles += cells.GetNumberOfConnectivityIds() - 2 * cells.GetNumberOfCells()

    mapper = vtk.vtkPolyDataMapper()
    mapper.SetInputData(tubes)
    mapper.ScalarVisibilityOff()
    actor = vtk.vtkActor()
    actor.SetMapper(mapper)
    # Sightline's default line style: colour 0.8, ambient 0.25, diffuse 0.75,
    # specular 0.3, shininess 32, one directional light at (0.3, 0.5, 1) in eye space.
    prop = actor.GetProperty()
    prop.SetColor(0.8, 0.8, 0.8)
    prop.SetAmbient(0.25)
    prop.SetDiffuse(0.75)
    prop.SetSpecular(0.3)
    prop.SetSpecularPower(32)
    renderer = vtk.vtkRenderer()
    renderer.SetBackground(0.0, 0.0, 0.0)
    renderer.AddActor(actor)
    renderer.AutomaticLightCreationOff()
    light = vtk.vtkLight()
    light.SetLightTypeToCameraLight()
    light.SetPosition(0.3, 0.5, 1.0)
    light.SetFocalPoint(0.0, 0.0, 0.0)
    renderer.AddLight(light)
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetMultiSamples(0)
    window.SetSize(width, height)
    window.AddRenderer(renderer)
    camera = renderer.GetActiveCamera()
    pixel = vtk.vtkUnsignedCharArray()

    def render(c):
        camera.SetPosition(c[0], c[1], c[2])
        camera.SetFocalPoint(c[3], c[4], c[5])
        camera.SetViewUp(c[6], c[7], c[8])
        camera.SetViewAngle(c[9])  # vertical field of view, degrees
        renderer.ResetCameraClippingRange()
        start = time.perf_counter()
        window.Render()
        window.WaitForCompletion()  # glFinish
        window.GetPixelData(0, 0, width - 1, height - 1, 1, pixel, 0)  # the whole frame into host memory
        return (time.perf_counter() - start) * 1e3

    first_frame_ms = None
    times = {}
    saved = set()
    for view, index, c in frames:
        ms = render(c)
        if first_frame_ms is None:
            first_frame_ms = ms  # uploads the mesh; not counted in any view
            continue
        if index < 0:
            continue
        times.setdefault(view, []).append(ms)
        if a.png and view not in saved:
            saved.add(view)
            grab = vtk.vtkWindowToImageFilter()
            grab.SetInput(window)
            grab.ReadFrontBufferOff()
            grab.Update()
            png = vtk.vtkPNGWriter()
            png.SetFileName("%s-%s.png" % (a.png, view))
            png.SetInputConnection(grab.GetOutputPort())
            png.Write()

    out = {"ok": True, "filter_ms": filter_ms, "first_frame_ms": first_frame_ms or 0.0,
           "triangles": triangles, "points": tubes.GetNumberOfPoints(),
           "gl_renderer": gl_renderer_of(window), "vtk": vtk.vtkVersion.GetVTKVersion(),
           "views": {v: {"median_ms": statistics.median(t), "min_ms": min(t), "max_ms": max(t), "frames": len(t)}
                     for v, t in times.items()}}
    print(json.dumps(out))


if __name__ == "__main__":
    try:
        main()
    except SystemExit:
        raise
    except Exception as e:  # report, as one JSON line, rather than a traceback
        fail("%s: %s" % (type(e).__name__, e))
