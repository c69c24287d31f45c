"""vtk_peer_common.py — what the VTK peer scripts share (bench/vtk_tubes.py,
bench/vtk_ribbons.py, bench/vtk_volume.py): the failure line, the camera
file the bench harness writes (one frame a line, "VIEW INDEX ex ey ez tx ty
tz ux uy uz fov_y_deg", INDEX < 0 an untimed warm-up), the GL renderer name
of a render window, and the timed surface loop of the line peers
(time_surface: Sightline's default material and light, no multisampling,
glFinish and a whole-frame readback per frame). Imported from the scripts'
own folder; the vtk module is passed in, never imported here.
"""
import json
import statistics
import sys
import time


def fail(message):
    """Prints {"ok": false, "error": message} and exits with status 1."""
    print(json.dumps({"ok": False, "error": message}))
    sys.stdout.flush()
    sys.exit(1)


def read_cameras(path):
    """[(view, index, [10 numbers]), ...] from the harness's camera file."""
    frames = []
    with open(path) as f:
        for number, line in enumerate(f, 1):
            fields = line.split()
            if not fields or fields[0].startswith("#"):
                continue
            if len(fields) != 12:
                fail("%s:%d: want VIEW INDEX and 10 numbers" % (path, number))
            frames.append((fields[0], int(fields[1]), [float(v) for v in fields[2:]]))
    return frames


def gl_renderer_of(window):
    """The "OpenGL renderer string" of a vtkRenderWindow, or "unknown"."""
    try:
        for line in window.ReportCapabilities().splitlines():
            if line.startswith("OpenGL renderer string:"):
                return line.split(":", 1)[1].strip()
    except Exception:  # only informative
        pass
    return "unknown"


def triangle_count(polydata):
    """Triangles of a surface's strips and polygons (a strip of k ids is k - 2 triangles)."""
    triangles = 0
    for cells in (polydata.GetStrips(), polydata.GetPolys()):
        triangles += cells.GetNumberOfConnectivityIds() - 2 * cells.GetNumberOfCells()
    return triangles


def time_surface(vtk, surface, frames, width, height, png_prefix=""):
    """Renders surface (vtkPolyData) through a vtkPolyDataMapper for every
    camera of frames (read_cameras) and returns the result dict's common part:
    {"first_frame_ms", "gl_renderer", "views": {VIEW: {"median_ms", "min_ms",
    "max_ms", "frames"}}}. The first frame uploads the mesh and is counted in
    no view; INDEX < 0 frames are warm-ups. Each frame sets the vtkCamera
    (position, focal point, view up, view angle = the vertical field of view),
    renders, waits for the GL (WaitForCompletion = glFinish) and reads the
    whole frame into host memory, as Sightline's harness does. With
    png_prefix, each view's first timed frame goes to PREFIX-VIEW.png."""
    mapper = vtk.vtkPolyDataMapper()
    mapper.SetInputData(surface)
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
        if png_prefix and view not in saved:
            saved.add(view)
            grab = vtk.vtkWindowToImageFilter()
            grab.SetInput(window)
            grab.ReadFrontBufferOff()
            grab.Update()
            png = vtk.vtkPNGWriter()
            png.SetFileName("%s-%s.png" % (png_prefix, view))
            png.SetInputConnection(grab.GetOutputPort())
            png.Write()
    return {"first_frame_ms": first_frame_ms or 0.0, "gl_renderer": gl_renderer_of(window),
            "views": {v: {"median_ms": statistics.median(t), "min_ms": min(t), "max_ms": max(t), "frames": len(t)}
                      for v, t in times.items()}}
