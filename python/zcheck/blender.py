"""zcheck.blender — Blender's cameras as zcheck cameras, and an animation's cameras as a manifest.

Runs inside Blender (3.x; `bpy` is imported inside the functions only, so this module imports
anywhere, and the formulas below can be tested without Blender):

    import zcheck, zcheck.blender
    camera = zcheck.blender.camera_from_object(bpy.data.objects["Camera"], bpy.context.scene)
    zcheck.blender.write_cameras("renders/manifest.jsonl", range(1, 251), depth="depth_{frame:04d}.exr",
                                 miss=">=1e9")
    # then: zcheck dataset verify renders/manifest.jsonl --scene mesh.obj --quantity eye-z

Blender's camera model, read from Blender's source and followed here formula by formula:
`BKE_camera_params_compute_viewplane` (source/blender/blenkernel/intern/camera.c, later
camera.cc), which Cycles repeats in `blender_camera_viewplane` (intern/cycles/blender/camera.cpp).

  * Pose. `obj.matrix_world` is the camera's pose, world_from_camera (camera-to-world). The
    camera looks down its local -Z with +Y up and +X right: zcheck's "opengl" eye axes.
    Blender takes the object's scale out of the view (`normalize_m4` in
    `BKE_camera_multiview_model_matrix`; `transform_clear_scale` in Cycles's
    `blender_camera_matrix`), so a scaled camera object renders as an unscaled one; this
    module does the same: each axis of matrix_world is normalised, as Blender's own
    `world_to_camera_view` does (`matrix_world.normalized()`). What normalising cannot make
    rigid (a shear from a non-uniformly scaled, rotated parent; a mirror from a negative
    scale) is refused by zcheck's pose rule, with its message.
  * Image. width = resolution_x * resolution_percentage // 100, likewise height (integer
    division, as Blender sizes the render: `BKE_render_resolution`, Cycles's
    `render_resolution_x`), and the sensor fit and aspect follow that size, as Cycles's do.
    (Blender's `world_to_camera_view` takes the aspect of the size before the percentage: where
    the division truncates, 321x241 at 50 % say, it misses Cycles's pixels by up to 0.07 px;
    this module does not.) Row 0 is the top row of the saved image (Blender's buffers are
    bottom-up; its image files are not). The centre of pixel (col, row) is the image point
    (col + 0.5, row + 0.5): Cycles samples raster x + a filter offset symmetric about 0.5, so
    an unshifted camera has its principal point at (width/2, height/2), pixel_center 0.5.
  * Units. lens, sensor_width and sensor_height in millimetres (only their ratio matters;
    lens_unit "FOV" is another view of `lens`, which is what Blender stores); shift_x and
    shift_y in fractions of the fitted image dimension (below); ortho_scale, clip_start and
    clip_end in Blender units, the units of matrix_world and of the meshes' coordinates
    (unit_settings.scale_length is display only and not applied).
  * Depth. Cycles's Z pass (view layer `use_pass_z`, channel `ViewLayer.Depth.Z` of a
    multi-layer EXR; save it as float32, `color_depth = "32"`) is planar depth along the
    viewing axis, zcheck's "eye-z", positive in front; where no surface is hit it holds 1e10
    (give miss=">=1e9"). It is the depth of the pixel's first sample, which Cycles 3.x aims at
    the pixel centre whatever the pixel filter (`integrate_camera_sample`: filter_u = filter_v
    = 0.5 for sample 0); it lands half a step of the filter's 1024-entry table off the centre:
    0.0005 px for the box filter (whose width Cycles fixes at 1 px) and for the default
    Blackman-Harris 1.5 px, ~3e-6 px for a 0.01 px Gaussian, all inside the 2^-8 px zcheck
    allows (measured with the Position pass in tests/blender). Depth of field and motion blur
    move the rays off the pinhole: their depth maps differ from it.

Panoramic cameras (type "PANO", Cycles 3.4: `cam.data.cycles.panorama_type`; Blender 4's
`cam.data.panorama_type` is read too) become lens cameras, the model of each type Cycles's kernel
renders (kernel/camera/projection.h, the *_to_direction functions; lens.h and docs/camera.md):
EQUIRECTANGULAR -> "equirectangular" (latitude/longitude ranges in degrees, moved by the shift),
FISHEYE_EQUIDISTANT -> "blender_fisheye_equidistant", FISHEYE_EQUISOLID ->
"blender_fisheye_equisolid", FISHEYE_LENS_POLYNOMIAL -> "blender_fisheye_lens_polynomial",
MIRRORBALL -> "blender_mirror_ball", EQUIANGULAR_CUBEMAP_FACE ->
"blender_equiangular_cubemap_face". For them shift_x and shift_y are in whole image widths and
heights (Cycles's panoramic viewplane is [shift_x, 1 + shift_x] x [shift_y, 1 + shift_y]), and the
equisolid and polynomial fisheyes take the sensor after Cycles's own sensor fit
(`blender_camera_sync`: AUTO fits sensor_width to the longer side, horizontal only when strictly
wider). Their Z pass is not planar: it is the Euclidean distance from the camera's centre,
zcheck's "distance" (`camera_z_depth`), at the pixel centre; pixels with no ray (outside a
fisheye's circle or a mirror ball's disc) hold 1e10 like the background, so give miss=">=1e9".

Not supported, and refused with zcheck.Error naming the setting: a render border
(`render.use_border`: the image then covers part of the frame), multi-view / stereo rendering
(`render.use_multiview`: each view has its own camera), and the panoramic settings no one-to-one
lens holds: a mirrored equirectangular range (longitude_max <= longitude_min, likewise
latitude), a shift that takes an equirectangular image past a pole or beyond +-360 degrees, a
fisheye_fov beyond 2 pi, a cubemap face shifted beyond 0.5, a lens polynomial with k0 > 0 or one
that folds inside the image (the lens model's message, which names the parameter).
"""

import json as _json
import math as _math
import numbers as _numbers
import os as _os

import numpy as _np

from . import Camera, Error

__all__ = ["camera_from_object", "depth_quantity", "write_cameras"]


def _image_size(render):
    """The rendered image's (width, height) in pixels: the resolution scaled by its percentage,
    integer division as `BKE_render_resolution` (blenkernel/intern/scene.cc) and Cycles's
    `render_resolution_x`/`_y` compute it."""
    width = render.resolution_x * render.resolution_percentage // 100
    height = render.resolution_y * render.resolution_percentage // 100
    if width < 1 or height < 1:
        raise Error(f"Blender render size {render.resolution_x}x{render.resolution_y} at "
                    f"{render.resolution_percentage} % is {width}x{height} pixels: no image")
    return width, height


def _world_from_camera(obj):
    """obj.matrix_world with its scale removed, as a 4x4 float64 array (column vectors): each of
    the first three columns (the camera's x, y, z axes in world) divided by its length, as
    Blender's `normalize_m4` does in `BKE_camera_multiview_model_matrix`. A zero-length axis
    (scale 0) has no direction and is refused."""
    m = _np.array([[float(obj.matrix_world[r][c]) for c in range(4)] for r in range(4)])
    for axis in range(3):
        length = float(_np.linalg.norm(m[:3, axis]))
        if not (length > 0.0 and _math.isfinite(length)):
            raise Error(f"Blender camera '{obj.name}': matrix_world's {'xyz'[axis]} axis has length {length!r} "
                        f"(a scale of 0): the camera has no orientation")
        m[:3, axis] /= length
    return m


def _fit_and_viewfac(cam, width, height, aspect_x, aspect_y):
    """The resolved sensor fit ("HORIZONTAL" or "VERTICAL"), the sensor dimension it spans (mm)
    and viewfac (pixel units) as BKE_camera_params_compute_viewplane computes them."""
    # ycor = aspy / aspx: the height of a pixel in units of its width.
    ycor = aspect_y / aspect_x
    # BKE_camera_sensor_size: VERTICAL fits sensor_height; HORIZONTAL and AUTO fit
    # sensor_width ("for auto, sensor_x is both x and y").
    sensor = cam.sensor_height if cam.sensor_fit == "VERTICAL" else cam.sensor_width
    # BKE_camera_sensor_fit(sensor_fit, aspx * winx, aspy * winy): AUTO is horizontal when the
    # image is at least as wide as tall *in displayed size* (pixels times their aspect).
    fit = cam.sensor_fit
    if fit == "AUTO":
        fit = "HORIZONTAL" if aspect_x * width >= aspect_y * height else "VERTICAL"
    # viewfac = winx (HOR) or ycor * winy (VERT): the fitted dimension in pixel-width units.
    viewfac = float(width) if fit == "HORIZONTAL" else ycor * height
    return fit, sensor, viewfac, ycor


def _panoramic_settings(cam):
    """Where the panoramic settings live: the camera data itself in Blender 4 (panorama_type moved
there), Cycles's add-on settings `cam.cycles` in 3.x."""
    if hasattr(cam, "panorama_type"):
        return cam
    settings = getattr(cam, "cycles", None)
    if settings is None or not hasattr(settings, "panorama_type"):
        raise Error(f"Blender camera data '{cam.name}' is panoramic but has no panorama_type (is the Cycles "
                    f"add-on enabled?)")
    return settings


def _fitted_sensor(cam, width, height, aspect_x, aspect_y):
    """Cycles's sensor size (mm) for its panoramic fisheyes, after its sensor fit
    (`blender_camera_sync`, intern/cycles/blender/camera.cpp): with xr = width * pixel_aspect_x and
    yr = height * pixel_aspect_y, AUTO fits sensor_width to the horizontal only when xr > yr
    (strictly), HORIZONTAL fits sensor_width, VERTICAL sensor_height; the other side follows the
    displayed aspect, so the fisheye's circle is round on the displayed image."""
    xr, yr = width * aspect_x, height * aspect_y
    if cam.sensor_fit == "AUTO":
        horizontal, size = xr > yr, cam.sensor_width
    elif cam.sensor_fit == "HORIZONTAL":
        horizontal, size = True, cam.sensor_width
    else:
        horizontal, size = False, cam.sensor_height
    if horizontal:
        return float(size), float(size) * yr / xr
    return float(size) * xr / yr, float(size)


def _panoramic_lens(obj, cam, scene, width, height, where):
    """The zcheck lens object (dict) of a panoramic camera (the module's docstring)."""
    settings = _panoramic_settings(cam)
    kind = settings.panorama_type
    shift_x, shift_y = float(cam.shift_x), float(cam.shift_y)
    if kind == "EQUIRECTANGULAR":
        # Cycles: longitude = longitude_min + u * (max - min), u = x/W + shift_x; latitude =
        # latitude_min + v * (max - min), v = 1 - y/H + shift_y: the shift moves both ranges.
        lon_min, lon_max = float(settings.longitude_min), float(settings.longitude_max)
        lat_min, lat_max = float(settings.latitude_min), float(settings.latitude_max)
        if not lon_max > lon_min:
            raise Error(f"{where}: longitude_max ({_math.degrees(lon_max):g} deg) is not greater than longitude_min "
                        f"({_math.degrees(lon_min):g} deg): a mirrored panorama, which zcheck does not model")
        if not lat_max > lat_min:
            raise Error(f"{where}: latitude_max ({_math.degrees(lat_max):g} deg) is not greater than latitude_min "
                        f"({_math.degrees(lat_min):g} deg): a mirrored panorama, which zcheck does not model")
        lon_span, lat_span = lon_max - lon_min, lat_max - lat_min
        lon = [_math.degrees(lon_min + shift_x * lon_span), _math.degrees(lon_max + shift_x * lon_span)]
        lat = [_math.degrees(lat_min + shift_y * lat_span), _math.degrees(lat_max + shift_y * lat_span)]
        if lat[0] < -90 - 1e-9 or lat[1] > 90 + 1e-9:
            raise Error(f"{where}: shift_y {shift_y:g} takes the panorama's latitudes to {lat[0]:g}..{lat[1]:g} deg, "
                        f"past a pole, where Cycles's rows repeat other rows' rays")
        if lon[0] < -360 or lon[1] > 360:
            raise Error(f"{where}: shift_x {shift_x:g} takes the panorama's longitudes to {lon[0]:g}..{lon[1]:g} deg, "
                        f"beyond +-360 deg")
        # Rounding in the conversion must not step over the poles the model refuses to pass.
        lat = [max(lat[0], -90.0), min(lat[1], 90.0)]
        return {"model": "equirectangular", "lon_min_deg": lon[0], "lon_max_deg": lon[1],
                "lat_min_deg": lat[0], "lat_max_deg": lat[1]}
    shift = {"shift_x": shift_x, "shift_y": shift_y}
    if kind == "FISHEYE_EQUIDISTANT":
        return {"model": "blender_fisheye_equidistant", "fisheye_fov": float(settings.fisheye_fov), **shift}
    if kind in ("FISHEYE_EQUISOLID", "FISHEYE_LENS_POLYNOMIAL"):
        sensor_w, sensor_h = _fitted_sensor(cam, width, height, scene.render.pixel_aspect_x,
                                            scene.render.pixel_aspect_y)
        sensor = {"fitted_sensor_width": sensor_w, "fitted_sensor_height": sensor_h}
        if kind == "FISHEYE_EQUISOLID":
            return {"model": "blender_fisheye_equisolid", "fisheye_lens": float(settings.fisheye_lens),
                    "fisheye_fov": float(settings.fisheye_fov), **sensor, **shift}
        k = {f"fisheye_polynomial_k{i}": float(getattr(settings, f"fisheye_polynomial_k{i}")) for i in range(5)}
        return {"model": "blender_fisheye_lens_polynomial", **k, "fisheye_fov": float(settings.fisheye_fov),
                **sensor, **shift}
    if kind == "MIRRORBALL":
        return {"model": "blender_mirror_ball", **shift}
    if kind == "EQUIANGULAR_CUBEMAP_FACE":
        return {"model": "blender_equiangular_cubemap_face", **shift}
    raise Error(f"{where}: panorama_type '{kind}' is not one zcheck models (EQUIRECTANGULAR, FISHEYE_EQUIDISTANT, "
                f"FISHEYE_EQUISOLID, FISHEYE_LENS_POLYNOMIAL, MIRRORBALL, EQUIANGULAR_CUBEMAP_FACE)")


def depth_quantity(obj):
    """What Cycles's Z pass holds for camera object `obj`: "distance" (from the camera's centre,
    `camera_z_depth`) for a panoramic camera, "eye-z" (planar) for perspective and orthographic."""
    return "distance" if obj.data.type == "PANO" else "eye-z"


def camera_from_object(obj, scene):
    """A zcheck.Camera for a Blender camera object as `scene` renders it.

obj:   a camera object (obj.type "CAMERA") whose data is of type "PERSP", "ORTHO" or "PANO"; its pose is
       obj.matrix_world as it is now (call scene.frame_set(f) first for frame f), scale removed
       as Blender removes it.
scene: the scene whose render settings size the image: resolution_x/y, resolution_percentage,
       pixel_aspect_x/y (the fit of an AUTO sensor depends on them).

With ycor = pixel_aspect_y / pixel_aspect_x; the fit horizontal for HORIZONTAL, vertical for
VERTICAL, and for AUTO horizontal iff width * pixel_aspect_x >= height * pixel_aspect_y;
viewfac = width (horizontal fit) or ycor * height (vertical); sensor = sensor_height for
VERTICAL, else sensor_width (AUTO too, whichever way it fits):
  perspective cameras become pinhole intrinsics (pixels, pixel_center 0.5)
       fx = lens * viewfac / sensor,   fy = fx / ycor,
       cx = width/2 - shift_x * viewfac,   cy = height/2 + shift_y * viewfac / ycor;
  orthographic ones an orthographic box (camera units)
       right, left = shift_x * ortho_scale +- ortho_scale * width / (2 viewfac),
       top, bottom = shift_y * ortho_scale +- ortho_scale * ycor * height / (2 viewfac).
  panoramic ones a lens camera (the module's docstring), projection near and far only.
Near and far are clip_start and clip_end; the convention "opengl" (Blender's camera axes).
Raises zcheck.Error, naming the camera, for another kind of object, a render border, multi-view
rendering, a scale-0 axis, a pose that is sheared or mirrored, or panoramic settings no lens model
holds (the module's docstring).
    """
    if getattr(obj, "type", None) != "CAMERA":
        raise Error(f"Blender object '{getattr(obj, 'name', obj)}' is of type {getattr(obj, 'type', None)!r}, "
                    f"not a camera")
    cam = obj.data
    render = scene.render
    where = f"Blender camera '{obj.name}'"
    if cam.type not in ("PERSP", "ORTHO", "PANO"):
        raise Error(f"{where} is of type '{cam.type}': zcheck models perspective (PERSP), orthographic (ORTHO) "
                    f"and panoramic (PANO) cameras")
    if render.use_border:
        raise Error(f"{where}: scene '{scene.name}' renders a border (render.use_border): the image covers "
                    f"part of the camera's frame; turn the border off to render frames for zcheck")
    if render.use_multiview:
        raise Error(f"{where}: scene '{scene.name}' renders several views (render.use_multiview): each view "
                    f"has its own camera; turn multi-view off to render frames for zcheck")

    width, height = _image_size(render)
    fit, sensor, viewfac, ycor = _fit_and_viewfac(cam, width, height, render.pixel_aspect_x, render.pixel_aspect_y)
    near, far = float(cam.clip_start), float(cam.clip_end)
    world_from_cam = _world_from_camera(obj)

    if cam.type == "PANO":
        # Cycles's panoramic frame is Blender's camera turned (blender_camera_matrix); the formulas
        # of the lens models are written back in Blender's camera axes, zcheck's "opengl" eye.
        return Camera.from_dict({
            "convention": "opengl",
            "image": {"width": width, "height": height},
            "projection": {"near": near, "far": far},
            "lens": _panoramic_lens(obj, cam, scene, width, height, where),
            "view": {"world_from_eye": world_from_cam.reshape(-1).tolist(), "layout": "row-major", "vectors": "column"},
        }, source=where)

    if cam.type == "PERSP":
        # BKE_camera_params_compute_viewplane, perspective: the viewplane lies at distance
        # clip_start and spans x in [-winx/2, winx/2] + dx, y in [-ycor*winy/2, ycor*winy/2] + dy,
        # with dx = shiftx * viewfac, dy = shifty * viewfac, all times
        # pixsize = sensor * clip_start / lens / viewfac. Image column c (0 at the left edge)
        # maps linearly onto x, so x/(-z) = (c - W/2 + shift_x*viewfac) * sensor/(lens*viewfac):
        #   c = lens*viewfac/sensor * x/(-z) + W/2 - shift_x*viewfac.
        # Rows r from the bottom map onto y in steps of ycor (viewdy = ycor * pixsize), so
        #   r_bottom = fx/ycor * y/(-z) + H/2 - shift_y*viewfac/ycor,
        # and from the top (r = H - r_bottom, y down in OpenCV's camera) cy = H/2 + shift_y*viewfac/ycor.
        fx = cam.lens * viewfac / sensor
        fy = fx / ycor
        cx = 0.5 * width - cam.shift_x * viewfac
        cy = 0.5 * height + cam.shift_y * viewfac / ycor
        K = _np.array([[fx, 0.0, cx], [0.0, fy, cy], [0.0, 0.0, 1.0]])
        try:
            return Camera.from_opencv(K, width=width, height=height, world_from_cam=world_from_cam,
                                      convention="opengl", pixel_center=0.5, near=near, far=far)
        except Error as error:  # zcheck's pose and intrinsics rules, said of this camera
            raise Error(f"{where}: {error}") from None

    # BKE_camera_params_compute_viewplane, orthographic: pixsize = ortho_scale / viewfac ("scale
    # == 1.0 means exact 1 to 1 mapping"), the same viewplane in camera units:
    #   x in [-W/2 + shift_x*viewfac, W/2 + shift_x*viewfac] * ortho_scale/viewfac,
    #   y in [-ycor*H/2 + shift_y*viewfac, ycor*H/2 + shift_y*viewfac] * ortho_scale/viewfac,
    # so shift is in units of ortho_scale (BKE_camera_view_frame_ex: r_shift = shiftx * ortho_scale).
    scale = cam.ortho_scale / viewfac
    half_w = 0.5 * width * scale
    half_h = 0.5 * ycor * height * scale
    shift_x = cam.shift_x * cam.ortho_scale
    shift_y = cam.shift_y * cam.ortho_scale
    # source=where: the camera reader's messages then begin with this camera's name.
    return Camera.from_dict({
        "convention": "opengl",
        "image": {"width": width, "height": height},
        "projection": {"type": "orthographic", "left": shift_x - half_w, "right": shift_x + half_w,
                       "bottom": shift_y - half_h, "top": shift_y + half_h, "near": near, "far": far},
        "view": {"world_from_eye": world_from_cam.reshape(-1).tolist(), "layout": "row-major", "vectors": "column"},
    }, source=where)


def write_cameras(path, frames, *, scene=None, depth="depth_{frame:04d}.exr", quantity=None, miss=None,
                  channel=None, name="frame_{frame:04d}"):
    """Write an animation's cameras as a zcheck manifest (JSON Lines, one frame a line), for
`zcheck dataset verify PATH --scene MESH`.

path:     the manifest to write (replaced if it exists).
frames:   frame numbers (integers); for each, scene.frame_set(frame) and the scene's active
          camera then (scene.camera, which camera-bound timeline markers switch) with its pose,
          lens and render settings at that frame. The scene is returned to its current frame
          afterwards.
scene:    the scene (default: bpy.context.scene).
depth:    each frame's depth map file, a str.format pattern of `frame`, relative to the manifest's
          folder as the manifest reader resolves it ("depth_{frame:04d}.exr" for a render output
          path "//depth_####.exr" beside the manifest).
quantity: what the maps hold; None: what Cycles's Z pass holds for the frame's camera
          (depth_quantity: "eye-z", or "distance" for a panoramic camera).
miss:     the stored value marking "no surface" (">=1e9" for the Z pass's 1e10), or None.
channel:  the channel to read ("ViewLayer.Depth.Z"), or None for the reader's choice (the one
          channel named as depth).
name:     each frame's name in the manifest and in the results, a str.format pattern of `frame`.

Returns the manifest's records (dicts), in frame order. Raises zcheck.Error, naming the frame,
when a frame has no active camera or its camera cannot be converted (camera_from_object).
    """
    import bpy

    scene = scene if scene is not None else bpy.context.scene
    frames = list(frames)
    for frame in frames:
        if isinstance(frame, bool) or not isinstance(frame, _numbers.Integral):
            raise Error(f"write_cameras: frame {frame!r} is not an integer frame number")
    records = []
    current = scene.frame_current, scene.frame_subframe
    try:
        for frame in frames:
            scene.frame_set(int(frame))
            obj = scene.camera
            if obj is None:
                raise Error(f"write_cameras: scene '{scene.name}' has no active camera at frame {frame}")
            try:
                camera = camera_from_object(obj, scene)
            except Error as error:
                raise Error(f"write_cameras: frame {frame}: {error}") from None
            record = {"frame": name.format(frame=frame),
                      "camera": _json.loads(camera.to_json()),  # the camera file's JSON, as written
                      "depth": depth.format(frame=frame),
                      "quantity": quantity if quantity is not None else depth_quantity(obj)}
            if miss is not None:
                record["miss"] = miss
            if channel is not None:
                record["channel"] = channel
            records.append(record)
    finally:
        scene.frame_set(current[0], subframe=current[1])
    folder = _os.path.dirname(_os.fspath(path))
    if folder:
        _os.makedirs(folder, exist_ok=True)
    with open(path, "w", encoding="utf-8") as out:
        for record in records:
            out.write(_json.dumps(record) + "\n")
    return records
