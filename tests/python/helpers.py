"""Shared helpers for the Python module's tests: the zcheck command, textbook matrices, scenes.

The textbook matrices are written here from the OpenGL reference pages (gluPerspective,
glFrustum, gluLookAt), independently of zcheck's C++ code, as numpy arrays for column vectors.
"""
import json
import math
import os
import subprocess
from pathlib import Path

import numpy as np

import zcheck

REPO = Path(__file__).resolve().parents[2]
ZCHECK_EXE = os.environ.get("ZCHECK_EXE", str(REPO / "build" / "cli" / "zcheck"))

W, H = 160, 120  # small images keep the suite fast

# The shared meshes (../shared/data/models beside the repository, or ZCHECK_MODELS_DIR).
MODELS = Path(os.environ.get("ZCHECK_MODELS_DIR", REPO.parent / "shared" / "data" / "models"))

# Each convention's eye axes from OpenCV's (x right, y down, looking down +z): docs/conventions.md.
# A pose in OpenCV's axes (R, t) is (A @ R, A @ t) in the convention's.
AXES_FROM_OPENCV = {"opencv": np.eye(3), "opengl": np.diag([1.0, -1.0, -1.0]), "vulkan": np.diag([1.0, -1.0, -1.0]),
                    "metal": np.diag([1.0, -1.0, -1.0]), "direct3d": np.diag([1.0, -1.0, 1.0])}


def run_cli(*args, check_rc=None):
    """Runs the zcheck command; returns (returncode, stdout, stderr)."""
    done = subprocess.run([ZCHECK_EXE, *map(str, args)], capture_output=True, text=True, timeout=120)
    if check_rc is not None:
        assert done.returncode == check_rc, f"zcheck {args}: rc {done.returncode}\n{done.stderr}"
    return done.returncode, done.stdout, done.stderr


def cli_error_message(stderr):
    """The one error line of the command, without its 'zcheck: error: ' prefix."""
    lines = stderr.strip().splitlines()
    assert len(lines) == 1, stderr
    prefix = "zcheck: error: "
    assert lines[0].startswith(prefix), stderr
    return lines[0][len(prefix):]


def write_json(path, document):
    Path(path).write_text(json.dumps(document))
    return str(path)


def gl_perspective(fovy_deg, aspect, n, f):
    """gluPerspective."""
    g = 1.0 / math.tan(math.radians(fovy_deg) / 2)
    return np.array([[g / aspect, 0, 0, 0],
                     [0, g, 0, 0],
                     [0, 0, (f + n) / (n - f), 2 * f * n / (n - f)],
                     [0, 0, -1, 0]], dtype=float)


def gl_frustum(l, r, b, t, n, f):
    """glFrustum."""
    return np.array([[2 * n / (r - l), 0, (r + l) / (r - l), 0],
                     [0, 2 * n / (t - b), (t + b) / (t - b), 0],
                     [0, 0, -(f + n) / (f - n), -2 * f * n / (f - n)],
                     [0, 0, -1, 0]], dtype=float)


def opencv_look_at(eye, target, down):
    """OpenCV's R, t (cam_from_world: x right, y down the image, z forward) of a camera at eye
    looking at target, its image's rows running towards `down` (made perpendicular to the view)."""
    eye, target, down = (np.asarray(v, dtype=float) for v in (eye, target, down))
    z = (target - eye) / np.linalg.norm(target - eye)
    x = np.cross(z, -down)
    x /= np.linalg.norm(x)
    R = np.stack([x, np.cross(z, x), z])
    return R, -R @ eye


def gl_look_at(eye, target, up):
    """gluLookAt: OpenGL eye space (x right, y up, looking down -z) from world."""
    eye, target, up = (np.asarray(v, dtype=float) for v in (eye, target, up))
    f = target - eye
    f /= np.linalg.norm(f)
    s = np.cross(f, up)
    s /= np.linalg.norm(s)
    u = np.cross(s, f)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[:3, 3] = -m[:3, :3] @ eye
    return m


def perspective_dict(eye, target, up=(0, 1, 0), fovy=60.0, near=0.5, far=50.0, width=W, height=H,
                     convention="opengl", depth_format="float32"):
    return {"convention": convention,
            "image": {"width": width, "height": height},
            "projection": {"type": "perspective", "fovy_deg": fovy, "near": near, "far": far},
            "view": {"eye": list(eye), "target": list(target), "up": list(up)},
            "depth": {"format": depth_format, "reversed": False, "range": [0, 1]}}


def quad_scene(d, upper_half_only=False, size=10.0):
    """A quad in the plane z = -d facing a camera at the origin that looks down -z; with
    upper_half_only it spans y in [0, size] (the top half of the picture)."""
    y0 = 0.0 if upper_half_only else -size
    vertices = np.array([[-size, y0, -d], [size, y0, -d], [size, size, -d], [-size, size, -d]])
    triangles = np.array([[0, 1, 2], [0, 2, 3]])
    return zcheck.Scene.from_arrays(vertices, triangles, name="quad")


def quad_camera(convention="opengl", near=0.5, far=50.0):
    return zcheck.Camera.from_dict(perspective_dict((0, 0, 0), (0, 0, -1), near=near, far=far,
                                                    convention=convention))


def without_timings(document):
    document = dict(document)
    document.pop("timings_ms")
    return document


def assert_documents_equal(a, b, path="", rel=1e-12):
    """Equal key by key; numbers within `rel` (relative) or 1e-300 absolute."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and sorted(a) == sorted(b), f"{path}: keys {sorted(a)} != {sorted(b)}"
        for key in a:
            assert_documents_equal(a[key], b[key], f"{path}.{key}", rel)
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), f"{path}: {a} != {b}"
        for i, (x, y) in enumerate(zip(a, b)):
            assert_documents_equal(x, y, f"{path}[{i}]", rel)
    elif isinstance(a, bool) or a is None or isinstance(a, str):
        assert a == b, f"{path}: {a!r} != {b!r}"
    else:
        assert isinstance(b, (int, float)) and not isinstance(b, bool), f"{path}: {a!r} != {b!r}"
        assert math.isclose(a, b, rel_tol=rel, abs_tol=1e-300), f"{path}: {a!r} != {b!r}"
