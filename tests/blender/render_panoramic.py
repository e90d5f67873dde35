"""Render a closed room with Cycles through one panoramic camera of each type Blender 3.4 has,
and write what `zcheck verify` needs to check the renders' Z passes against zcheck's lens models.

    blender -b --factory-startup --python-exit-code 1 -P render_panoramic.py -- OUTDIR

(`zcheck` must be importable: PYTHONPATH=build/python.) The scene: a box of 12 x 18 x 10 units
around the camera, and a sphere and a cone inside it, so that every pixel with a ray meets a
surface and the distances vary. The camera is turned off every axis and sits off-centre. Cycles
on the CPU, one sample, a 0.01 px Gaussian pixel filter (the Z pass is sample 0's, at the pixel
centre, whatever the filter). Cameras (name: type, settings, image):

    equirect      EQUIRECTANGULAR, latitudes -70..75 deg, longitudes -150..160 deg, shift (0.05, -0.03), 96x64
    equidistant   FISHEYE_EQUIDISTANT, fisheye_fov 200 deg, shift (0.03, 0.02), 96x64 (an ellipse)
    equisolid     FISHEYE_EQUISOLID, fisheye_lens 9 mm, fisheye_fov 195 deg, AUTO fit, 64x96 (portrait:
                  sensor_width on the height)
    polynomial    FISHEYE_LENS_POLYNOMIAL, k0..k4 = (-0.002, -0.06, -5e-4, 1e-5, 0), fisheye_fov 170 deg,
                  HORIZONTAL fit, pixel aspect 1 : 1.25, 96x64
    mirrorball    MIRRORBALL, shift (0.05, 0), 64x64
    cubemap       EQUIANGULAR_CUBEMAP_FACE, shift (0.1, -0.05), 64x64

Writes into OUTDIR:
  scene.obj                   the rendered triangles in world coordinates (9 significant digits)
  depth_NNNN.exr              frame N's render: multi-layer EXR, float32, ViewLayer.Depth.Z
  outside.txt                 "NAME COUNT" a line: the pixels Cycles's formulas give no ray, for
                              the equidistant, equisolid and mirror ball cameras
  frames.txt                  "N NAME" a line: the frame of each camera, in the order above
  NAME.json                   the camera, zcheck.blender.camera_from_object's, as a camera file
  manifest.jsonl              every camera's frame (zcheck.blender.write_cameras: quantity
                              "distance" chosen for panoramic cameras)
  wrong_fov.json              equidistant's camera with fisheye_fov 3 % wider
  wrong_model.json            equisolid's camera read as an equidistant fisheye of the same fov
  refusal.txt                 camera_from_object's message for a fisheye_fov of 400 deg
"""

import json
import math
import os
import sys

import bpy
import numpy as np
from mathutils import Euler

import zcheck
import zcheck.blender

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cycles_depth import set_up_depth_render  # noqa: E402  (beside this script)

CAMERAS = [
    ("equirect", (96, 64), (1, 1), {"panorama_type": "EQUIRECTANGULAR", "latitude_min": math.radians(-70),
                                    "latitude_max": math.radians(75), "longitude_min": math.radians(-150),
                                    "longitude_max": math.radians(160)}, {"shift_x": 0.05, "shift_y": -0.03}),
    ("equidistant", (96, 64), (1, 1), {"panorama_type": "FISHEYE_EQUIDISTANT", "fisheye_fov": math.radians(200)},
     {"shift_x": 0.03, "shift_y": 0.02}),
    ("equisolid", (64, 96), (1, 1), {"panorama_type": "FISHEYE_EQUISOLID", "fisheye_lens": 9.0,
                                     "fisheye_fov": math.radians(195)}, {"sensor_fit": "AUTO", "sensor_width": 36.0}),
    ("polynomial", (96, 64), (1, 1.25), {"panorama_type": "FISHEYE_LENS_POLYNOMIAL", "fisheye_polynomial_k0": -0.002,
                                         "fisheye_polynomial_k1": -0.06, "fisheye_polynomial_k2": -5e-4,
                                         "fisheye_polynomial_k3": 1e-5, "fisheye_polynomial_k4": 0.0,
                                         "fisheye_fov": math.radians(170)},
     {"sensor_fit": "HORIZONTAL", "sensor_width": 30.0}),
    ("mirrorball", (64, 64), (1, 1), {"panorama_type": "MIRRORBALL"}, {"shift_x": 0.05}),
    ("cubemap", (64, 64), (1, 1), {"panorama_type": "EQUIANGULAR_CUBEMAP_FACE"}, {"shift_x": 0.1, "shift_y": -0.05}),
]


def build_scene():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    bpy.ops.mesh.primitive_cube_add(size=2, location=(0.5, -0.7, 0.4), scale=(6, 9, 5))
    bpy.ops.mesh.primitive_uv_sphere_add(radius=1.2, location=(2.0, 3.5, -1.0), segments=24, ring_count=12)
    bpy.ops.mesh.primitive_cone_add(radius1=1.0, depth=2.5, location=(-2.5, -1.0, 2.0), vertices=16)
    for obj in bpy.context.scene.objects:
        obj.select_set(obj.type == "MESH")
    bpy.ops.object.transform_apply(location=True, rotation=True, scale=True)


def export_world_obj(path):
    """Every mesh's evaluated loop triangles (what Cycles traces), world coordinates, 9 significant
    digits (the binary32 coordinates exactly); transforms are applied, so local is world."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    offset = 1
    with open(path, "w") as out:
        for obj in bpy.context.scene.objects:
            if obj.type != "MESH":
                continue
            mesh = obj.evaluated_get(depsgraph).to_mesh()
            mesh.calc_loop_triangles()
            co = np.empty(3 * len(mesh.vertices), dtype=np.float32)
            mesh.vertices.foreach_get("co", co)
            tris = np.empty(3 * len(mesh.loop_triangles), dtype=np.int64)
            mesh.loop_triangles.foreach_get("vertices", tris)
            out.write(f"o {obj.name}\n")
            np.savetxt(out, co.reshape(-1, 3).astype(np.float64), fmt="v %.9g %.9g %.9g")
            np.savetxt(out, tris.reshape(-1, 3) + offset, fmt="f %d %d %d")
            offset += len(co) // 3
            obj.evaluated_get(depsgraph).to_mesh_clear()


def add_camera(scene, name, pano, data_settings):
    data = bpy.data.cameras.new(name)
    data.type = "PANO"
    data.clip_start, data.clip_end = 0.01, 1000.0
    for key, value in pano.items():
        setattr(data.cycles, key, value)
    for key, value in data_settings.items():
        setattr(data, key, value)
    obj = bpy.data.objects.new(name, data)
    scene.collection.objects.link(obj)
    obj.location = (0.3, -0.4, 0.2)
    obj.rotation_euler = Euler((math.radians(80), math.radians(10), math.radians(25)))
    return obj


def outside_field(name, size, aspect, pano, data_settings):
    """How many pixel centres Cycles gives no ray, by the kernel's formulas (kernel/camera/
    projection.h, with u = (col + 0.5)/W + shift_x, v = (row_from_bottom + 0.5)/H + shift_y),
    written here apart from zcheck: outside the equidistant's r = 1, the equisolid's
    R = 2f sin(fov/4), the mirror ball's unit disc. None for the other types."""
    width, height = size
    u = (np.arange(width) + 0.5)[None, :] / width + data_settings.get("shift_x", 0.0)
    v = (np.arange(height) + 0.5)[:, None] / height + data_settings.get("shift_y", 0.0)
    kind = pano["panorama_type"]
    if kind in ("FISHEYE_EQUIDISTANT", "MIRRORBALL"):
        return int(((2 * u - 1) ** 2 + (2 * v - 1) ** 2 > 1).sum())
    if kind == "FISHEYE_EQUISOLID":
        # AUTO fit: sensor_width on the longer side (blender_camera_sync).
        xr, yr = width * aspect[0], height * aspect[1]
        s = data_settings["sensor_width"]
        sw, sh = (s, s * yr / xr) if xr > yr else (s * xr / yr, s)
        rmax = 2 * pano["fisheye_lens"] * math.sin(pano["fisheye_fov"] / 4)
        return int((np.hypot((u - 0.5) * sw, (v - 0.5) * sh) > rmax).sum())
    return None


def main():
    out = sys.argv[sys.argv.index("--") + 1]
    os.makedirs(out, exist_ok=True)
    scene = bpy.context.scene
    build_scene()
    set_up_depth_render(scene)
    export_world_obj(os.path.join(out, "scene.obj"))
    cameras = {}
    for frame, (name, size, aspect, pano, data_settings) in enumerate(CAMERAS, start=1):
        obj = add_camera(scene, name, pano, data_settings)
        cameras[name] = obj
        scene.timeline_markers.new(f"F_{frame:02d}", frame=frame).camera = obj
    for frame, (name, size, aspect, pano, data_settings) in enumerate(CAMERAS, start=1):
        scene.frame_set(frame)
        scene.render.resolution_x, scene.render.resolution_y = size
        scene.render.pixel_aspect_x, scene.render.pixel_aspect_y = aspect
        scene.camera = cameras[name]
        scene.render.filepath = os.path.join(out, f"depth_{frame:04d}.exr")
        bpy.ops.render.render(write_still=True)
        camera = zcheck.blender.camera_from_object(cameras[name], scene)
        with open(os.path.join(out, f"{name}.json"), "w") as f:
            f.write(camera.to_json())
        print(f"render_panoramic: {name} rendered, camera {json.loads(camera.to_json())['lens']}", flush=True)
    # The manifest: each frame's size set by a frame-change handler, as a pipeline would key it.
    sizes = {frame: (size, aspect) for frame, (_, size, aspect, _, _) in enumerate(CAMERAS, start=1)}

    def size_for_frame(scene, *args):
        size, aspect = sizes[scene.frame_current]
        scene.render.resolution_x, scene.render.resolution_y = size
        scene.render.pixel_aspect_x, scene.render.pixel_aspect_y = aspect

    bpy.app.handlers.frame_change_pre.append(size_for_frame)
    scene.frame_set(1)
    records = zcheck.blender.write_cameras(os.path.join(out, "manifest.jsonl"), sorted(sizes), scene=scene,
                                           depth="depth_{frame:04d}.exr", miss=">=1e9", channel="ViewLayer.Depth.Z")
    with open(os.path.join(out, "outside.txt"), "w") as f:
        for camera in CAMERAS:
            if outside_field(*camera) is not None:
                f.write(f"{camera[0]} {outside_field(*camera)}\n")
    with open(os.path.join(out, "frames.txt"), "w") as f:
        for frame, (name, *_) in enumerate(CAMERAS, start=1):
            f.write(f"{frame} {name}\n")
    bpy.app.handlers.frame_change_pre.remove(size_for_frame)
    # Wrong cameras: the fov 3 % wider; the equisolid fisheye read as equidistant.
    wrong = json.loads(open(os.path.join(out, "equidistant.json")).read())
    wrong["lens"]["fisheye_fov"] *= 1.03
    json.dump(wrong, open(os.path.join(out, "wrong_fov.json"), "w"))
    wrong = json.loads(open(os.path.join(out, "equisolid.json")).read())
    wrong["lens"] = {"model": "blender_fisheye_equidistant", "fisheye_fov": wrong["lens"]["fisheye_fov"],
                     "shift_x": wrong["lens"]["shift_x"], "shift_y": wrong["lens"]["shift_y"]}
    json.dump(wrong, open(os.path.join(out, "wrong_model.json"), "w"))
    # A refusal: fisheye_fov beyond 2 pi (Blender allows 10 pi).
    cameras["equidistant"].data.cycles.fisheye_fov = math.radians(400)
    try:
        zcheck.blender.camera_from_object(cameras["equidistant"], scene)
        message = "accepted"
    except zcheck.Error as error:
        message = str(error)
    with open(os.path.join(out, "refusal.txt"), "w") as f:
        f.write(message + "\n")
    print(f"render_panoramic: wrote {len(records)} frames, quantities {sorted({r['quantity'] for r in records})}",
          flush=True)


if __name__ == "__main__":
    main()
