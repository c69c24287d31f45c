#!/usr/bin/python3
"""vtk_ribbons.py — the VTK ribbon filter peer of bench-ribbons (bench/bench_ribbons.c).

    xvfb-run -a /usr/bin/python3 bench/vtk_ribbons.py --lines LINES.vtk --cameras CAMERAS.txt
        --size WxH --width R [--png PREFIX]

Renders the polylines of LINES.vtk (legacy VTK POLYDATA) as vtkRibbonFilter
ribbons — flat strips, what VTK and ParaView users get — with half-width R
(the filter's Width; Sightline's ribbon radius), oriented by the file's point
NORMALS (the face normals Sightline's `ribbons` uses, written by the bench;
UseDefaultNormal off, Angle 0, no width variation). Without NORMALS the
filter computes its default normals, and the JSON says so ("normals":
"vtk default"). Drawn through vtkPolyDataMapper with the cameras of
CAMERAS.txt, timed as in vtk_peer_common.time_surface (no multisampling,
glFinish and a whole-frame readback per frame).

Prints one JSON line on stdout: {"ok": true, "filter_ms", "first_frame_ms",
"triangles", "points", "mesh_bytes", "normals", "gl_renderer", "vtk",
"views": {VIEW: {"median_ms", "min_ms", "max_ms", "frames"}}}, or
{"ok": false, "error": "..."} (exit status 1). Debian's VTK is built for X11
only: run under xvfb-run with /usr/bin/python3; bench/packages.txt lists the
packages.
"""
import argparse
import json
import sys
import time

from vtk_peer_common import fail, read_cameras, time_surface, triangle_count


def main():
    ap = argparse.ArgumentParser(description="VTK ribbon filter peer of bench-ribbons")
    ap.add_argument("--lines", required=True)
    ap.add_argument("--cameras", required=True)
    ap.add_argument("--size", required=True)
    ap.add_argument("--width", type=float, required=True)
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
    has_normals = lines.GetPointData().GetNormals() is not None

    ribbon = vtk.vtkRibbonFilter()
    ribbon.SetInputData(lines)
    ribbon.SetWidth(a.width)  # half-width
    ribbon.SetAngle(0.0)
    ribbon.SetVaryWidth(0)
    ribbon.SetUseDefaultNormal(0)
    t0 = time.perf_counter()
    ribbon.Update()
    filter_ms = (time.perf_counter() - t0) * 1e3
    ribbons = ribbon.GetOutput()
    out = {"ok": True, "filter_ms": filter_ms, "triangles": triangle_count(ribbons),
           "points": ribbons.GetNumberOfPoints(), "mesh_bytes": ribbons.GetActualMemorySize() * 1024,
           "normals": "file" if has_normals else "vtk default", "vtk": vtk.vtkVersion.GetVTKVersion()}
    out.update(time_surface(vtk, ribbons, frames, width, height, a.png))
    print(json.dumps(out))


if __name__ == "__main__":
    try:
        main()
    except SystemExit:
        raise
    except Exception as e:  # report, as one JSON line, rather than a traceback
        fail("%s: %s" % (type(e).__name__, e))
