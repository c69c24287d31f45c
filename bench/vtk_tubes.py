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
"triangles", "points", "mesh_bytes", "gl_renderer", "views": {VIEW: {"median_ms",
"min_ms", "max_ms", "frames"}}}, or {"ok": false, "error": "..."} (exit status 1). Debian's VTK
is built for X11 only: run under xvfb-run with /usr/bin/python3 (other Python
installs do not see Debian's modules); bench/packages.txt lists the packages.
"""
import argparse
import json
import sys
import time

from vtk_peer_common import fail, read_cameras, time_surface, triangle_count


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
    out = {"ok": True, "filter_ms": filter_ms, "triangles": triangle_count(tubes),
           "points": tubes.GetNumberOfPoints(), "mesh_bytes": tubes.GetActualMemorySize() * 1024,
           "vtk": vtk.vtkVersion.GetVTKVersion()}
    out.update(time_surface(vtk, tubes, frames, width, height, a.png))
    print(json.dumps(out))


if __name__ == "__main__":
    try:
        main()
    except SystemExit:
        raise
    except Exception as e:  # report, as one JSON line, rather than a traceback
        fail("%s: %s" % (type(e).__name__, e))
