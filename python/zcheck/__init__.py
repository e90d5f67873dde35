"""zcheck — check a graphics transform chain by computing every pixel's depth twice.

The ray route (Embree) follows the camera's definition; the raster route (a software z-buffer)
follows its matrices. If view, projection, depth mapping, viewport orientation and pixel-centre
convention agree, both depths agree within a stated tolerance at every pixel.

    import zcheck
    scene = zcheck.Scene.from_file("builtin:default")        # or Scene.from_arrays(V, F)
    camera = scene.default_camera                            # or Camera.from_file / from_dict /
                                                             #    from_opencv / from_matrices
    checker = zcheck.Checker(scene)                          # BVH and rasterizer, built once
    report = checker.check(camera)                           # report.consistent, report.to_dict()
    z = checker.render(camera, "eye-z")                      # (H, W) float32, row 0 at the top
    checker.verify(camera, my_depth, "eye-z").consistent     # a depth map from your renderer

Conventions every function follows:
  * images are numpy arrays of shape (height, width[, channels]); row 0 is the TOP row; pixel
    (col, row) is array[row, col] and its centre is the image point (col + 0.5, row + 0.5);
  * matrices are numpy 4x4 arrays written for column vectors, M[r, c] with p' = M @ p, named
    dest_from_src (eye_from_world maps world points into eye space; cam_from_world is OpenCV's
    [R | t]; world_from_cam is the camera's pose, "c2w");
  * depth quantities: "window" (the depth-buffer value), "ndc" (z_ndc), "eye-z" (planar depth
    along the viewing axis, positive) and "distance" (Euclidean range from the centre of
    projection); functions that read depth take the quantity as a required argument;
  * bad input raises zcheck.Error (a ValueError) with the one-line message the zcheck command
    prints after "zcheck: error: ".
"""

import json as _json
import math as _math
import numbers as _numbers

from ._zcheck import (  # noqa: F401
    Camera,
    Checker,
    Error,
    Report,
    Scene,
    __version__,
    builtin_scenes,
    cached_buffer_bytes,
    conventions,
    depth_formats,
    depth_quantities,
    kernel_form,
    kernel_forms_supported,
    mistakes,
    pixel_classes,
    quantities,
    release_cached_buffers,
    routes,
    unproject,
)

__all__ = [
    "Camera",
    "Checker",
    "Error",
    "Report",
    "Scene",
    "__version__",
    "builtin_scenes",
    "cached_buffer_bytes",
    "conventions",
    "depth_formats",
    "depth_quantities",
    "kernel_form",
    "kernel_forms_supported",
    "mistakes",
    "pixel_classes",
    "quantities",
    "read_depth_map",
    "release_cached_buffers",
    "routes",
    "unproject",
]


def _jsonable(value, path):
    """The camera dict as plain JSON values: numpy arrays and scalars become lists and numbers,
    +-inf becomes "inf"/"-inf" (the camera file's spelling of an infinite far plane) and NaN
    "nan" (which the camera reader then refuses by key, as it would in a file)."""
    if isinstance(value, dict):
        out = {}
        for key, item in value.items():
            if not isinstance(key, str):
                raise Error(f"camera dict: key {key!r}{' in ' + repr(path) if path else ''} is not a string")
            out[key] = _jsonable(item, f"{path}.{key}" if path else key)
        return out
    if hasattr(value, "tolist") and not isinstance(value, (str, bytes)):  # numpy arrays and scalars
        return _jsonable(value.tolist(), path)
    if isinstance(value, (list, tuple)):
        return [_jsonable(item, path) for item in value]
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return value
    if isinstance(value, _numbers.Integral):
        return int(value)
    if isinstance(value, _numbers.Real):
        v = float(value)
        if _math.isnan(v):
            return "nan"
        if _math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return v
    raise Error(f"camera dict: '{path}' has a value of type {type(value).__name__}, which JSON cannot hold")


def _camera_from_dict(cls, d, source="camera dict"):
    """A camera from a dict with the camera file's keys (see docs/camera.md, "The camera file"):

        zcheck.Camera.from_dict({
            "convention": "opengl",
            "image": {"width": 640, "height": 480},
            "projection": {"type": "perspective", "fovy_deg": 60, "near": 0.1, "far": 100},
            "view": {"eye": [0, 1, 3], "target": [0, 0, 0], "up": [0, 1, 0]},
            "depth": {"format": "float32", "reversed": False, "range": [0, 1]}})

    Values may be numpy arrays or scalars; math.inf is written "inf" (an infinite far plane).
    Unknown keys, wrong types and invalid values raise zcheck.Error with the camera file's
    messages, beginning with `source` ("camera dict") instead of "camera file 'PATH'".
    """
    if not isinstance(d, dict):
        raise Error(f"{source}: must be a dict with the camera file's keys, got {type(d).__name__}")
    return cls.from_json(_json.dumps(_jsonable(d, "")), source)


Camera.from_dict = classmethod(_camera_from_dict)


def _files():
    """zcheck._zcheck_files, imported on first use: it links OpenImageIO, whose start-up
    (~0.5 s) `import zcheck` should not pay when no image file is read."""
    from . import _zcheck_files
    return _zcheck_files


def read_depth_map(path, camera, *, quantity=None, channel=None, scale=None, offset=None, miss=None, sidecar=None):
    """Read a depth map file as `zcheck verify` and `zcheck unproject` do: EXR (multi-layer too), PFM,
TIFF, or a 16-bit PNG with scale, told apart by their first bytes. Returns an (H, W) float64 array,
row 0 at the top (PFM's bottom-to-top rows are flipped), NaN where the file marks a miss.

camera:   the map must have the camera's size.
quantity: prefer that quantity's channel (window, ndc, Z for eye-z, distance) when the file has it;
channel:  or read exactly this channel (an error listing the channels if there is none of that
          name). Without either: the only channel, else the one named as depth (Z, depth, *.Z as in
          Blender's ViewLayer.Depth.Z, *.depth); several or none is an error that lists them.
scale:    stored value = (depth - offset) x scale; integer files need it (1000 for millimetres,
          5000 for many RGB-D sets, 256 for KITTI), float files are divided by it.
offset:   added to every depth after scale (default 0).
miss:     the stored value that marks "no surface" (0, 65535, 1e10, float("inf"), "nan") or a
          comparison as a string (">=1e9"), compared before scale and offset. Without it, 0 is a
          miss in integer files; NaN always is. 8-bit files are refused (8 bits cannot hold depth).
sidecar:  a JSON file whose "channel", "miss", "scale" and "offset" keys apply where the arguments
          above are not given (other keys ignored), as `--sidecar` does.
    """
    return _files().read_depth_map(str(path), camera, quantity=quantity, channel=channel, scale=scale, offset=offset,
                                   miss=miss, sidecar=None if sidecar is None else str(sidecar))


def _verify_file(self, camera, path, quantity=None, *, channel=None, scale=None, offset=None, miss=None, sidecar=None,
                 quantum=None, rel_tolerance=None, abs_tolerance=None, allow_holes=None, noise_model=None, diagnose=False,
                 threads=None):
    """A depth map file against the ground truth, exactly as `zcheck verify --depth-map PATH --quantity Q
[--channel C] [--scale S] [--offset O] [--miss M] [--sidecar F] [--quantum Q] [--rel-tolerance R]
[--abs-tolerance A] [--allow-holes] [--noise-model M] [--diagnose]` does it: the file read as read_depth_map reads it
(channel, scale, offset, miss, sidecar), with the file's storage quantum (1/scale for integer files,
binary16's or binary32's own step for float files) and what the map declares (quantum, rel_tolerance,
abs_tolerance, allow_holes, noise_model: see Checker.verify). to_dict() equals `zcheck verify --json`'s document but
for timings; its depth_map entry names the channel read.
    """
    return _files().verify_file(self, camera, str(path), quantity, channel=channel, miss=miss, scale=scale,
                                offset=offset, sidecar=None if sidecar is None else str(sidecar), quantum=quantum,
                                rel_tolerance=rel_tolerance, abs_tolerance=abs_tolerance, allow_holes=allow_holes,
                                noise_model=noise_model, diagnose=diagnose, threads=threads)


_verify_file.__name__ = _verify_file.__qualname__ = "verify_file"
Checker.verify_file = _verify_file

for _name in ("Camera", "Checker", "Error", "Report", "Scene", "read_depth_map", "unproject"):
    try:
        globals()[_name].__module__ = "zcheck"
    except (AttributeError, TypeError):  # pragma: no cover - builtin functions keep theirs
        pass
del _name
