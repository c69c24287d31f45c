"""vtk_peer_common.py — what the VTK peer scripts share (bench/vtk_tubes.py,
bench/vtk_volume.py): the failure line, the camera file the bench harness
writes (one frame a line, "VIEW INDEX ex ey ez tx ty tz ux uy uz fov_y_deg",
INDEX < 0 an untimed warm-up) and the GL renderer name of a render window.
Imported from the scripts' own folder; no VTK import here.
"""
import json
import sys


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
