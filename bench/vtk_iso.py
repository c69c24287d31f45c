#!/usr/bin/python3
"""vtk_iso.py — VTK's isosurface as the peer of bench-particles (bench/bench_particles.c).

    xvfb-run -a /usr/bin/python3 bench/vtk_iso.py --raw VOL.raw --type int16 --dims X Y Z
        --spacing SX SY SZ --origin OX OY OZ --iso V --cameras CAMERAS.txt --size WxH [--png PREFIX]

What a VTK user draws for an isosurface picture: vtkFlyingEdges3D (VTK's
fastest contour filter; vtkMarchingCubes when this VTK lacks it) with
normals, on the volume of VOL.raw (x fastest, native byte order, values at
voxel centres), then the mesh through vtkPolyDataMapper with the cameras of
CAMERAS.txt, timed as vtk_peer_common.time_surface does (glFinish and a
whole-frame readback per frame). Extraction is timed alone (Update of the
filter, the volume already in memory).

Prints one JSON line: {"ok": true, "filter", "filter_ms", "triangles",
"mesh_bytes", "first_frame_ms", "gl_renderer", "vtk", "views": {VIEW:
{"median_ms", "min_ms", "max_ms", "frames"}}}, or {"ok": false, "error"}
(exit status 1). Debian's VTK is built for X11 only: run under xvfb-run
with /usr/bin/python3; bench/packages.txt lists the packages.
"""
import argparse
import json
import os
import sys
import time

from vtk_peer_common import fail, read_cameras, time_surface, triangle_count


def main():
    ap = argparse.ArgumentParser(description="VTK isosurface peer of bench-particles")
    ap.add_argument("--raw", required=True)
    ap.add_argument("--type", required=True, choices=["float32", "int16", "uint16", "uint8"])
    ap.add_argument("--dims", type=int, nargs=3, required=True)
    ap.add_argument("--spacing", type=float, nargs=3, required=True)
    ap.add_argument("--origin", type=float, nargs=3, required=True)
    ap.add_argument("--iso", type=float, required=True)
    ap.add_argument("--cameras", required=True)
    ap.add_argument("--size", required=True)
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
    sizes = {"float32": 4, "int16": 2, "uint16": 2, "uint8": 1}
    voxels = a.dims[0] * a.dims[1] * a.dims[2]
    if os.path.getsize(a.raw) != voxels * sizes[a.type]:
        fail("%s holds %d bytes, dims and type say %d" % (a.raw, os.path.getsize(a.raw), voxels * sizes[a.type]))
    reader = vtk.vtkImageReader2()  # no numpy needed
    reader.SetFileName(a.raw)
    reader.SetFileDimensionality(3)
    reader.SetDataExtent(0, a.dims[0] - 1, 0, a.dims[1] - 1, 0, a.dims[2] - 1)
    reader.SetDataSpacing(*a.spacing)
    reader.SetDataOrigin(*a.origin)
    reader.SetNumberOfScalarComponents(1)
    {"float32": reader.SetDataScalarTypeToFloat, "int16": reader.SetDataScalarTypeToShort,
     "uint16": reader.SetDataScalarTypeToUnsignedShort, "uint8": reader.SetDataScalarTypeToUnsignedChar}[a.type]()
    if sys.byteorder == "little":
        reader.SetDataByteOrderToLittleEndian()
    else:
        reader.SetDataByteOrderToBigEndian()
    reader.Update()
    image = reader.GetOutput()

    if hasattr(vtk, "vtkFlyingEdges3D"):
        iso = vtk.vtkFlyingEdges3D()
        name = "vtkFlyingEdges3D"
    else:
        iso = vtk.vtkMarchingCubes()
        name = "vtkMarchingCubes"
    iso.SetInputData(image)
    iso.SetValue(0, a.iso)
    iso.ComputeNormalsOn()
    iso.ComputeScalarsOff()
    t0 = time.perf_counter()
    iso.Update()
    filter_ms = (time.perf_counter() - t0) * 1e3
    mesh = iso.GetOutput()
    if mesh.GetNumberOfPoints() == 0:
        fail("no isosurface at %g" % a.iso)
    out = {"ok": True, "filter": name, "filter_ms": filter_ms, "triangles": triangle_count(mesh),
           "mesh_bytes": mesh.GetActualMemorySize() * 1024, "vtk": vtk.vtkVersion.GetVTKVersion()}
    out.update(time_surface(vtk, mesh, frames, width, height, a.png))
    print(json.dumps(out))


if __name__ == "__main__":
    try:
        main()
    except SystemExit:
        raise
    except Exception as e:  # report, as one JSON line, rather than a traceback
        fail("%s: %s" % (type(e).__name__, e))
