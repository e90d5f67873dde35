"""Render a mesh with Blender's Cycles through cameras of every kind zcheck.blender converts, and
write what `zcheck dataset verify` needs to check the renders' Z passes.

    blender -b --factory-startup --python-exit-code 1 -P render_and_check.py -- OUTDIR MESH.obj

(`zcheck` must be importable: PYTHONPATH=build/python.) The scene: MESH, scaled to 2 units and
standing on a ground plane, seen by four cameras over five frames (camera-bound timeline
markers switch them; camera A moves between its two frames):

    frame 1  A  perspective, HORIZONTAL fit, 32x20 mm sensor, shift (0.11, -0.06), 10 deg roll,
                object scale (1.5, 0.7, 2): Blender ignores a camera's scale
    frame 2  B  perspective, VERTICAL fit (sensor_height), shift (-0.05, 0.09), clip_start 0.5
    frame 3  C  orthographic, AUTO fit, ortho_scale 3.2, shift (0.06, -0.04)
    frame 4  D  perspective, AUTO fit, shift (0.04, 0.03)
    frame 5  A  at a second keyframed pose

rendered twice: with tall pixels (pixel_aspect 1 : 1.4, so that AUTO fits the *height* of a
160x120 image: 160·1 < 120·1.4) and with square pixels (AUTO fits the width). The render is
320x240 at 50 %, Cycles on the CPU, one sample, a 0.01 px Gaussian pixel filter.

Writes into OUTDIR:
  scene.obj                     the rendered triangles in Blender's world coordinates, every
                                coordinate printed with 9 significant digits (binary32 exact)
  tall/depth_NNNN.exr           multi-layer EXR, float32: ViewLayer.Depth.Z (the Z pass) and
  square/depth_NNNN.exr         ViewLayer.Position.X/Y/Z (the world point that depth is of)
  manifest.jsonl                both renders' frames (zcheck.blender.write_cameras), named
                                tall_NNNN and square_NNNN
  manifest_shift_flipped.jsonl  the same, but camera B's shift_x negated while writing it:
                                exactly frames tall_0002 and square_0002 must be inconsistent
  manifest_{tall,square}[_flipped].jsonl   each render's own part of those two
  checks.json                   the second route, the sample positions (below) and the
                                messages of what camera_from_object refuses: a panoramic
                                camera with a mirrored longitude range, a sheared pose, a
                                render border

The second route: Blender's own projection, bpy_extras.object_utils.world_to_camera_view (built
on Camera.view_frame, i.e. BKE_camera_view_frame_ex, not on the viewplane code zcheck.blender
follows), of the mesh's vertices against zcheck's projection of the same points through the
camera's matrices (clip_from_world, then window_from_ndc). checks.json holds the largest
difference in pixels and in eye depth; this script fails if it exceeds 1e-3 px.

The sample positions: with one sample, the Position pass holds the world point each pixel's
depth was taken at (both are sample 0's); projected through zcheck's camera it gives where in the
pixel Cycles sampled. checks.json records the largest offset from the pixel centre and how many
pixels lie beyond 2^-8 px of it in x or y (the offset zcheck's verify allows a renderer).
"""

import json
import math
import os
import sys
import time

import bpy
import numpy as np
from bpy_extras.object_utils import world_to_camera_view
from mathutils import Matrix, Vector

import zcheck
import zcheck.blender

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cycles_depth import set_up_depth_render  # noqa: E402  (beside this script)

# 160x120 rendered. The percentage divides the resolution exactly: world_to_camera_view (the
# second route) sizes the frame by the resolution before the percentage, Cycles by the rendered
# size; at 321x241 they differ by up to 0.07 px (Cycles's samples still land on zcheck's centres).
RESOLUTION = (320, 240)
PERCENTAGE = 50
PIXEL_ASPECTS = {"tall": (1.0, 1.4), "square": (1.0, 1.0)}
FRAMES = [1, 2, 3, 4, 5]
EEVEE_FRAMES = [1, 4]
TARGET = (0.0, 0.0, 0.8)
MAX_PROJECTION_DIFFERENCE_PX = 1e-3
ALLOWED_SAMPLE_OFFSET_PX = 2.0 ** -8  # zcheck verify's S (docs/verify.md)


def arguments():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if len(argv) != 2:
        raise RuntimeError("usage: blender -b --factory-startup --python-exit-code 1 -P render_and_check.py "
                           "-- OUTDIR MESH.obj")
    return os.path.abspath(argv[0]), os.path.abspath(argv[1])


def clear_scene():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)


def import_mesh(path):
    """MESH as one mesh object whose vertices are in world coordinates (identity matrix_world).
    Blender 3.4 has two OBJ importers, the C++ `wm.obj_import` (3.2+) and the Python add-on's
    `import_scene.obj` (gone in 4.0); both turn OBJ's +Y up into Blender's +Z up."""
    before = set(bpy.data.objects)
    if hasattr(bpy.ops.wm, "obj_import"):
        bpy.ops.wm.obj_import(filepath=path)
    elif hasattr(bpy.ops.import_scene, "obj"):
        bpy.ops.import_scene.obj(filepath=path)
    else:
        raise RuntimeError("this Blender has no OBJ importer (wm.obj_import or import_scene.obj)")
    meshes = [o for o in bpy.data.objects if o not in before and o.type == "MESH"]
    if not meshes:
        raise RuntimeError(f"importing {path} made no mesh object")
    bpy.ops.object.select_all(action="DESELECT")
    for o in meshes:
        o.select_set(True)
    bpy.context.view_layer.objects.active = meshes[0]
    if len(meshes) > 1:
        bpy.ops.object.join()
    obj = bpy.context.view_layer.objects.active
    bpy.ops.object.transform_apply(location=True, rotation=True, scale=True)
    # Scale to 2 units, centred over the origin, standing on z = 0.
    co = np.empty(3 * len(obj.data.vertices), dtype=np.float32)
    obj.data.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3).astype(np.float64)
    lo, hi = co.min(axis=0), co.max(axis=0)
    s = 2.0 / float((hi - lo).max())
    obj.scale = (s, s, s)
    obj.location = (-s * 0.5 * (lo[0] + hi[0]), -s * 0.5 * (lo[1] + hi[1]), -s * lo[2])
    bpy.ops.object.transform_apply(location=True, rotation=True, scale=True)
    obj.name = "mesh"
    return obj


def add_ground():
    bpy.ops.mesh.primitive_plane_add(size=8.0, location=(0.0, 0.0, -0.01))
    bpy.ops.object.transform_apply(location=True, rotation=True, scale=True)
    bpy.context.view_layer.objects.active.name = "ground"


def export_world_obj(path):
    """Every mesh object's evaluated triangles (the loop triangles Cycles renders) in world
    coordinates. Blender's own exporters print 6 decimals; 9 significant digits give back the
    binary32 coordinates Cycles traced exactly."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    offset = 1
    with open(path, "w") as out:
        out.write("# zcheck tests/blender: the scene as Cycles rendered it, world coordinates\n")
        for obj in bpy.context.scene.objects:
            if obj.type != "MESH":
                continue
            evaluated = obj.evaluated_get(depsgraph)
            mesh = evaluated.to_mesh()
            mesh.calc_loop_triangles()
            co = np.empty(3 * len(mesh.vertices), dtype=np.float32)
            mesh.vertices.foreach_get("co", co)
            co = co.reshape(-1, 3)
            world = np.array(evaluated.matrix_world)
            if not np.array_equal(world, np.eye(4)):
                # Not reached here (transforms are applied); binary64 then, not Cycles's binary32.
                co = (co.astype(np.float64) @ world[:3, :3].T + world[:3, 3]).astype(np.float32)
            tris = np.empty(3 * len(mesh.loop_triangles), dtype=np.int64)
            mesh.loop_triangles.foreach_get("vertices", tris)
            out.write(f"o {obj.name}\n")
            np.savetxt(out, co.astype(np.float64), fmt="v %.9g %.9g %.9g")
            np.savetxt(out, tris.reshape(-1, 3) + offset, fmt="f %d %d %d")
            offset += len(co)
            evaluated.to_mesh_clear()


def add_camera(name, **settings):
    data = bpy.data.cameras.new(name)
    for key, value in settings.items():
        setattr(data, key, value)
    obj = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def place(obj, location, roll_deg=0.0, scale=(1.0, 1.0, 1.0), frame=None):
    """Point obj's -Z at TARGET with +Y up, rolled about its view axis; keyframed at `frame`."""
    loc = Vector(location)
    rotation = (Vector(TARGET) - loc).to_track_quat("-Z", "Y").to_matrix().to_4x4()
    rotation = rotation @ Matrix.Rotation(math.radians(roll_deg), 4, "Z")
    obj.matrix_world = Matrix.Translation(loc) @ rotation @ Matrix.Diagonal((*scale, 1.0))
    if frame is not None:
        for path in ("location", "rotation_euler", "scale"):
            obj.keyframe_insert(data_path=path, frame=frame)


def set_up_cameras(scene):
    a = add_camera("A_persp_horizontal", type="PERSP", lens=38.0, sensor_fit="HORIZONTAL", sensor_width=32.0,
                   sensor_height=20.0, shift_x=0.11, shift_y=-0.06, clip_start=0.1, clip_end=100.0)
    place(a, (3.2, -3.6, 2.4), roll_deg=10.0, scale=(1.5, 0.7, 2.0), frame=1)
    place(a, (-3.0, -2.8, 1.6), roll_deg=-6.0, scale=(1.5, 0.7, 2.0), frame=5)
    b = add_camera("B_persp_vertical", type="PERSP", lens=30.0, sensor_fit="VERTICAL", sensor_width=36.0,
                   sensor_height=27.0, shift_x=-0.05, shift_y=0.09, clip_start=0.5, clip_end=60.0)
    place(b, (-3.5, 2.5, 2.0))
    c = add_camera("C_ortho_auto", type="ORTHO", ortho_scale=3.2, sensor_fit="AUTO", shift_x=0.06, shift_y=-0.04,
                   clip_start=0.1, clip_end=50.0)
    place(c, (0.5, -5.0, 3.0))
    d = add_camera("D_persp_auto", type="PERSP", lens=45.0, sensor_fit="AUTO", sensor_width=36.0, sensor_height=24.0,
                   shift_x=0.04, shift_y=0.03, clip_start=0.1, clip_end=100.0)
    place(d, (4.0, 1.0, 1.2), roll_deg=-15.0)
    for frame, obj in zip(FRAMES, (a, b, c, d, a)):
        scene.timeline_markers.new(f"F_{frame:02d}", frame=frame).camera = obj
    for fcurve in a.animation_data.action.fcurves:
        for point in fcurve.keyframe_points:
            point.interpolation = "CONSTANT"
    return {"A": a, "B": b, "C": c, "D": d}


def render_frames(scene, folder):
    os.makedirs(folder, exist_ok=True)
    for frame in FRAMES:
        scene.frame_set(frame)
        scene.render.filepath = os.path.join(folder, f"depth_{frame:04d}.exr")
        started = time.time()
        bpy.ops.render.render(write_still=True)
        if not os.path.isfile(scene.render.filepath):
            raise RuntimeError(f"frame {frame}: Blender wrote no {scene.render.filepath}")
        print(f"render_and_check: frame {frame} camera {scene.camera.name} rendered in {time.time() - started:.1f} s",
              flush=True)


def world_vertices(stride):
    """Every `stride`-th vertex of every mesh, plus all of the ground's, in world coordinates."""
    points = []
    for obj in bpy.context.scene.objects:
        if obj.type != "MESH":
            continue
        co = np.empty(3 * len(obj.data.vertices), dtype=np.float32)
        obj.data.vertices.foreach_get("co", co)
        co = co.reshape(-1, 3).astype(np.float64)
        points.append(co if len(co) < 100 else co[::stride])
    return np.concatenate(points)


def zcheck_pixels(camera, points):
    """Image points (x right, y down, (0, 0) the top-left corner) and eye depths of world points,
    through zcheck's matrices: clip_from_world, the perspective divide, window_from_ndc (window
    y up from the bottom edge in the opengl convention)."""
    m = camera.matrices()
    homogeneous = np.c_[points, np.ones(len(points))]
    clip = homogeneous @ m["clip_from_world"].T
    ndc = clip / clip[:, 3:4]
    window = ndc @ m["window_from_ndc"].T
    eye = homogeneous @ m["eye_from_world"].T
    return np.c_[window[:, 0], camera.height - window[:, 1]], -eye[:, 2]


def projection_route(scene, points):
    """Blender's world_to_camera_view against zcheck's camera for the current frame: the largest
    difference in pixels (over points in front of the camera) and in eye depth."""
    obj = scene.camera
    camera = zcheck.blender.camera_from_object(obj, scene)
    w, h = camera.width, camera.height
    blender = np.array([tuple(world_to_camera_view(scene, obj, Vector(p))) for p in points])
    in_front = blender[:, 2] > obj.data.clip_start
    blender_px = np.c_[blender[:, 0] * w, (1.0 - blender[:, 1]) * h]
    zcheck_px, zcheck_depth = zcheck_pixels(camera, points)
    visible = in_front & (blender_px >= 0).all(axis=1) & (blender_px[:, 0] <= w) & (blender_px[:, 1] <= h)
    px = np.abs(blender_px - zcheck_px).max(axis=1)
    depth = np.abs(blender[:, 2] - zcheck_depth)
    return {"points": int(in_front.sum()), "max_px": float(px[in_front].max()),
            "in_image": int(visible.sum()), "max_px_in_image": float(px[visible].max()),
            "max_depth_rel": float((depth[in_front] / blender[in_front, 2]).max())}


def sample_positions(scene, path):
    """Where Cycles sampled each pixel whose Z pass holds a surface: the Position pass (the same
    sample's world point) through zcheck's camera, as the offset from the pixel centre."""
    camera = zcheck.blender.camera_from_object(scene.camera, scene)
    read = lambda channel: zcheck.read_depth_map(path, camera, channel=channel)
    z = read("ViewLayer.Depth.Z")
    hit = np.isfinite(z) & (z < 1e9)
    rows, cols = np.nonzero(hit)
    points = np.c_[read("ViewLayer.Position.X")[hit], read("ViewLayer.Position.Y")[hit],
                   read("ViewLayer.Position.Z")[hit]]
    px, depth = zcheck_pixels(camera, points)
    offset = px - np.c_[cols + 0.5, rows + 0.5]
    beyond = (np.abs(offset) > ALLOWED_SAMPLE_OFFSET_PX).any(axis=1)
    return {"hit_pixels": int(hit.sum()),
            "max_offset_px": [float(np.abs(offset[:, 0]).max()), float(np.abs(offset[:, 1]).max())],
            "mean_offset_px": [float(offset[:, 0].mean()), float(offset[:, 1].mean())],
            "pixels_beyond_2^-8": int(beyond.sum()),
            "z_pass_vs_position_depth_rel": float((np.abs(z[hit] - depth) / depth).max())}


def refusals(scene):
    """What camera_from_object refuses, each with zcheck.Error naming the camera and the reason:
    {case: the message}; a case that is not refused raises."""
    def refused(case, obj, must_say):
        try:
            zcheck.blender.camera_from_object(obj, scene)
        except zcheck.Error as error:
            message = str(error)
            if f"'{obj.name}'" not in message or must_say not in message:
                raise RuntimeError(f"refusal '{case}': the message does not name '{obj.name}' and "
                                   f"'{must_say}': {message}")
            return message
        raise RuntimeError(f"refusal '{case}': camera_from_object accepted camera '{obj.name}'")

    messages = {}
    # Panoramic cameras are lens cameras now (tests/blender/render_panoramic.py); a mirrored
    # equirectangular range is what no lens model holds.
    pano = add_camera("E_panoramic", type="PANO")
    pano.data.cycles.panorama_type = "EQUIRECTANGULAR"
    pano.data.cycles.longitude_min, pano.data.cycles.longitude_max = 1.0, -1.0
    messages["panoramic"] = refused("panoramic", pano, "longitude_max")
    # A camera under a rotated, non-uniformly scaled parent: its matrix_world is sheared, which
    # removing each axis's length (as Blender does) cannot make a rotation.
    parent = bpy.data.objects.new("parent_scaled", None)
    scene.collection.objects.link(parent)
    parent.rotation_euler = (0.0, 0.0, math.radians(30.0))
    parent.scale = (1.0, 3.0, 1.0)
    sheared = add_camera("F_sheared", type="PERSP")
    sheared.parent = parent
    sheared.rotation_euler = (math.radians(40.0), 0.0, math.radians(20.0))
    bpy.context.view_layer.update()
    messages["sheared"] = refused("sheared", sheared, "not a rigid transform")
    scene.render.use_border = True
    try:
        messages["border"] = refused("border", scene.camera, "use_border")
    finally:
        scene.render.use_border = False
    for obj in (pano, sheared, parent):
        bpy.data.objects.remove(obj, do_unlink=True)
    return messages


def main():
    outdir, mesh_path = arguments()
    os.makedirs(outdir, exist_ok=True)
    scene = bpy.context.scene
    clear_scene()
    import_mesh(mesh_path)
    add_ground()
    cameras = set_up_cameras(scene)
    set_up_depth_render(scene, RESOLUTION, PERCENTAGE, position_pass=True)
    export_world_obj(os.path.join(outdir, "scene.obj"))

    points = world_vertices(stride=37)
    checks = {"frames": {}, "max_projection_px": 0.0}
    manifest, flipped = [], []
    for label, (aspect_x, aspect_y) in PIXEL_ASPECTS.items():
        scene.render.pixel_aspect_x, scene.render.pixel_aspect_y = aspect_x, aspect_y
        render_frames(scene, os.path.join(outdir, label))
        for frame in FRAMES:
            scene.frame_set(frame)
            name = f"{label}_{frame:04d}"
            route = projection_route(scene, points)
            samples = sample_positions(scene, os.path.join(outdir, label, f"depth_{frame:04d}.exr"))
            checks["frames"][name] = {"camera": scene.camera.name, "projection": route, "samples": samples}
            checks["max_projection_px"] = max(checks["max_projection_px"], route["max_px"])
            print(f"render_and_check: {name} {scene.camera.name}: world_to_camera_view vs zcheck "
                  f"{route['max_px']:.2e} px over {route['points']} points; samples up to "
                  f"({samples['max_offset_px'][0]:.4f}, {samples['max_offset_px'][1]:.4f}) px off centre, "
                  f"{samples['pixels_beyond_2^-8']} of {samples['hit_pixels']} beyond 2^-8 px", flush=True)
        options = dict(scene=scene, depth=label + "/depth_{frame:04d}.exr", quantity="eye-z", miss=">=1e9",
                       channel="ViewLayer.Depth.Z", name=label + "_{frame:04d}")
        manifest += zcheck.blender.write_cameras(os.path.join(outdir, f"manifest_{label}.jsonl"), FRAMES, **options)
        # A classic mistake, made on purpose: camera B's shift_x read with the wrong sign.
        cameras["B"].data.shift_x = -cameras["B"].data.shift_x
        try:
            flipped += zcheck.blender.write_cameras(os.path.join(outdir, f"manifest_{label}_flipped.jsonl"), FRAMES,
                                                    **options)
        finally:
            cameras["B"].data.shift_x = -cameras["B"].data.shift_x

    # Eevee, the rasterizer, through the same square-pixel cameras (frames 1 and 4, perspective):
    # its Z pass is reconstructed from a depth buffer, and nothing hit is stored as it stores it.
    # The manifest declares nothing: the test asks what verify and its diagnosis make of it.
    # Eevee needs an OpenGL context (Mesa's, headless): where Blender has none, the test says so
    # and skips these frames (no manifest_eevee.jsonl) rather than failing the Cycles checks.
    try:
        scene.render.engine = "BLENDER_EEVEE"
        scene.eevee.taa_render_samples = 1
        eevee_folder = os.path.join(outdir, "eevee")
        os.makedirs(eevee_folder, exist_ok=True)
        for frame in EEVEE_FRAMES:
            scene.frame_set(frame)
            scene.render.filepath = os.path.join(eevee_folder, f"depth_{frame:04d}.exr")
            bpy.ops.render.render(write_still=True)
            if not os.path.isfile(scene.render.filepath):
                raise RuntimeError(f"frame {frame}: Blender wrote no {scene.render.filepath}")
        zcheck.blender.write_cameras(os.path.join(outdir, "manifest_eevee.jsonl"), EEVEE_FRAMES, scene=scene,
                                     depth="eevee/depth_{frame:04d}.exr", quantity="eye-z",
                                     channel="ViewLayer.Depth.Z", name="eevee_{frame:04d}")
        print("render_and_check: Eevee rendered frames " + ", ".join(map(str, EEVEE_FRAMES)), flush=True)
    except Exception as e:  # noqa: BLE001 - any failure of the engine is reported, not fatal
        print(f"render_and_check: Eevee could not render here: {e}", flush=True)

    for name, records in (("manifest.jsonl", manifest), ("manifest_shift_flipped.jsonl", flipped)):
        with open(os.path.join(outdir, name), "w") as out:
            out.writelines(json.dumps(record) + "\n" for record in records)
    checks["refusals"] = refusals(scene)
    with open(os.path.join(outdir, "checks.json"), "w") as out:
        json.dump(checks, out, indent=1)
    print(f"render_and_check: largest projection difference {checks['max_projection_px']:.3e} px", flush=True)
    if not checks["max_projection_px"] <= MAX_PROJECTION_DIFFERENCE_PX:
        raise RuntimeError(f"render_and_check: world_to_camera_view and zcheck differ by "
                           f"{checks['max_projection_px']:.3e} px (> {MAX_PROJECTION_DIFFERENCE_PX} px)")


if __name__ == "__main__":
    main()
