"""Datasets made at test time (nothing is downloaded): a trajectory of cameras around a shared
mesh, written in the formats datasets come in, with depth maps rendered by zcheck's raster route
(the route `verify` does not use for its truth) and written by writers independent of zcheck
(numpy, h5py, a PNG encoder here, OpenImageIO's oiiotool, COLMAP's model_converter), and copies
broken the way datasets break.

Every format's conventions are written here from the formats' own documentation, not from
zcheck's importers: COLMAP world-to-camera quaternions in OpenCV axes with pixel centres at +0.5,
nerfstudio camera-to-world matrices in OpenGL axes with centres at +0.5 and millimetre PNGs,
OpenCV FileStorage with centres at 0.
"""
import base64
import json
import math
import shutil
import struct
import subprocess
import zlib
from pathlib import Path

import numpy as np

import zcheck
from helpers import gl_look_at

W, H = 320, 240
FX = FY = 300.0
CX, CY = W / 2, H / 2  # COLMAP's and nerfstudio's coordinates: a centred camera
FRAMES = 24
OPENCV_TO_OPENGL = np.diag([1.0, -1.0, -1.0, 1.0])  # flips y and z: one camera frame to the other


def look_at_cam_from_world(eye, target, up=(0.0, 1.0, 0.0)):
    """OpenCV's [R | t] (x right, y down, z forward) of a camera at `eye` looking at `target`:
    gluLookAt's OpenGL eye space with y and z flipped."""
    return OPENCV_TO_OPENGL @ gl_look_at(eye, target, up)


def quaternion_of(r):
    """Hamilton (w, x, y, z) of a rotation matrix, w >= 0 (Shepperd's method)."""
    t = np.trace(r)
    if t > 0:
        s = 2 * math.sqrt(1 + t)
        q = [s / 4, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s]
    else:
        i = int(np.argmax(np.diag(r)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2 * math.sqrt(1 + r[i, i] - r[j, j] - r[k, k])
        q = [0.0] * 4
        q[0] = (r[k, j] - r[j, k]) / s
        q[1 + i] = s / 4
        q[1 + j] = (r[j, i] + r[i, j]) / s
        q[1 + k] = (r[k, i] + r[i, k]) / s
    q = np.array(q)
    return q if q[0] >= 0 else -q


def write_png16(path, codes):
    """A 16-bit greyscale PNG (big-endian samples, filter 0 on every row)."""
    codes = np.asarray(codes, dtype=">u2")
    h, w = codes.shape
    raw = b"".join(b"\x00" + codes[row].tobytes() for row in range(h))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    Path(path).write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 16, 0, 0, 0, 0)) +
                           chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def write_exr(path, depth):
    """A float EXR through OpenImageIO's oiiotool, from a PFM written here (rows bottom to top)."""
    pfm = Path(str(path) + ".pfm")
    data = np.ascontiguousarray(np.asarray(depth, "<f4")[::-1])
    pfm.write_bytes(b"Pf\n%d %d\n-1\n" % (data.shape[1], data.shape[0]) + data.tobytes())
    subprocess.run(["oiiotool", str(pfm), "-d", "float", "-o", str(path)], check=True, capture_output=True)
    pfm.unlink()


def write_colmap_depth(path, depth):
    """COLMAP's dense depth map: "W&H&C&", then float32 rows; 0 where there is no depth."""
    d = np.where(np.isfinite(depth), depth, 0).astype("<f4")
    Path(path).write_bytes(b"%d&%d&1&" % (d.shape[1], d.shape[0]) + d.tobytes())


def write_hdf5(path, **datasets):
    import h5py
    with h5py.File(path, "w") as f:
        for name, values in datasets.items():
            f.create_dataset(name, data=np.asarray(values, np.float32))


class Trajectory:
    """`frames` cameras on a ring around the scene's bounds, `orbit` times their half-diagonal from
    its centre and looking at it; intrinsics FX, FY, CX, CY scaled to a `width` x `height` image."""

    def __init__(self, scene, frames=FRAMES, width=W, height=H, orbit=2.2):
        self.width, self.height = width, height
        self.fx = FX * width / W
        self.cx, self.cy = width / 2, height / 2
        lo, hi = scene.bounds
        self.center = (lo + hi) / 2
        radius = np.linalg.norm(hi - lo) / 2
        self.poses = []  # OpenCV cam_from_world, 4x4
        self.clip = []   # the renderer's near and far: hugging the scene, as a renderer's would
        for i in range(frames):
            a = 2 * math.pi * i / frames
            eye = self.center + radius * np.array([orbit * math.sin(a), 0.8 + 0.3 * math.sin(3 * a), orbit * math.cos(a)])
            self.poses.append(look_at_cam_from_world(eye, self.center))
            d = np.linalg.norm(eye - self.center)
            self.clip.append((0.5 * (d - radius), 1.5 * (d + radius)))
        self.names = [f"frame_{i:03d}.png" for i in range(frames)]
        self.k = np.array([[self.fx, 0, self.cx - 0.5], [0, self.fx, self.cy - 0.5], [0, 0, 1]])  # OpenCV's coordinates

    def camera(self, i, near=None, far=None):
        """The frame's camera as zcheck sees it, near and far hugging the scene (for rendering)."""
        return zcheck.Camera.from_opencv(self.k, cam_from_world=self.poses[i], width=self.width, height=self.height,
                                         near=near or self.clip[i][0], far=far or self.clip[i][1])


class DatasetMaker:
    def __init__(self, root, mesh, frames=FRAMES, width=W, height=H, orbit=2.2):
        self.root = Path(root)
        self.root.mkdir(parents=True, exist_ok=True)
        self.mesh = str(mesh)
        self.scene = zcheck.Scene.from_file(self.mesh)
        self.checker = zcheck.Checker(self.scene)
        self.trajectory = Trajectory(self.scene, frames, width, height, orbit)
        self.frames = frames
        self._eye_z = {}
        self._distance = {}

    # ---- depth, by the raster route ----------------------------------------------------
    def eye_z(self, i):
        if i not in self._eye_z:
            self._eye_z[i] = self.checker.render(self.trajectory.camera(i), "eye-z", route="raster")
        return self._eye_z[i]

    def distance(self, i):
        if i not in self._distance:
            self._distance[i] = self.checker.render(self.trajectory.camera(i), "distance", route="raster")
        return self._distance[i]

    @staticmethod
    def millimetres(depth, per_metre=1000.0):
        codes = np.where(np.isfinite(depth), np.round(depth * per_metre), 0)
        assert codes.max() <= 65535, f"depth up to {np.nanmax(depth[np.isfinite(depth)])} does not fit 16 bits at {per_metre}"
        return codes.astype(np.uint16)

    # ---- COLMAP ---------------------------------------------------------------------------
    def colmap_text(self, folder, cx=None, broken_cx=()):
        """cameras.txt and images.txt; frames in `broken_cx` use a second camera whose principal
        point is OpenCV's (W − 1)/2 written where COLMAP's W/2 belongs."""
        folder = self.root / folder
        folder.mkdir(parents=True, exist_ok=True)
        t = self.trajectory
        cameras = [f"1 PINHOLE {t.width} {t.height} {t.fx!r} {t.fx!r} {t.cx!r} {t.cy!r}"]
        if broken_cx:
            cameras.append(f"2 PINHOLE {t.width} {t.height} {t.fx!r} {t.fx!r} {t.cx - 0.5!r} {t.cy - 0.5!r}")
        (folder / "cameras.txt").write_text("# Camera list with one line of data per camera:\n"
                                            "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
                                            f"# Number of cameras: {len(cameras)}\n" + "\n".join(cameras) + "\n")
        lines = ["# Image list with two lines of data per image:",
                 "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME",
                 "#   POINTS2D[] as (X, Y, POINT3D_ID)",
                 f"# Number of images: {self.frames}, mean observations per image: 0"]
        for i, (pose, name) in enumerate(zip(self.trajectory.poses, self.trajectory.names)):
            q, t = quaternion_of(pose[:3, :3]), pose[:3, 3]
            camera = 2 if i in broken_cx else 1
            lines.append(" ".join([str(i + 1)] + [repr(float(v)) for v in (*q, *t)] + [str(camera), name]))
            lines.append("")
        (folder / "images.txt").write_text("\n".join(lines) + "\n")
        (folder / "points3D.txt").write_text("# 3D point list with one line of data per point:\n"
                                             "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
                                             "# Number of points: 0, mean track length: 0\n")
        return folder

    def colmap_convert(self, input_folder, folder, output_type):
        """The model COLMAP itself writes (its model_converter; output_type BIN or TXT)."""
        folder = self.root / folder
        folder.mkdir(parents=True, exist_ok=True)
        subprocess.run(["colmap", "model_converter", "--input_path", str(input_folder), "--output_path", str(folder),
                        "--output_type", output_type], check=True, capture_output=True)
        return folder

    def colmap_depth_maps(self, folder, flip=()):
        folder = self.root / folder
        folder.mkdir(parents=True, exist_ok=True)
        for i, name in enumerate(self.trajectory.names):
            depth = self.eye_z(i)
            write_colmap_depth(folder / f"{name}.geometric.bin", depth[::-1] if i in flip else depth)
        return folder

    # ---- nerfstudio -------------------------------------------------------------------------
    def transforms(self, name="transforms.json", broken=None, missing=(), per_unit=1000.0, camera_of=None,
                   float_npy=False):
        """transforms.json with 16-bit millimetre PNGs. `broken` maps a frame to how it breaks:
        "y-flip", "inverted-extrinsic", "opencv-axes", "distance", "centimetres". `camera_of(i)`, when
        given, is the frame whose camera frame i's entry lists (its map stays frame i's): a list
        shifted by one, or shuffled. `float_npy`: the maps as float32 .npy in scene units (metres), with
        no depth_unit_scale_factor in the file (so nerfstudio's default 1e-3 applies to them)."""
        broken = broken or {}
        depth_dir = self.root / (Path(name).stem + "_depth")
        depth_dir.mkdir(parents=True, exist_ok=True)
        frames = []
        for i, (pose, image) in enumerate(zip(self.trajectory.poses, self.trajectory.names)):
            how = broken.get(i)
            if camera_of is not None:
                pose = self.trajectory.poses[camera_of(i)]
            c2w_gl = np.linalg.inv(pose) @ OPENCV_TO_OPENGL  # camera-to-world, OpenGL camera axes
            matrix = {"inverted-extrinsic": np.linalg.inv(c2w_gl), "opencv-axes": np.linalg.inv(pose)}.get(how, c2w_gl)
            depth = self.distance(i) if how == "distance" else self.eye_z(i)
            codes = self.millimetres(depth, per_unit / 10 if how == "centimetres" else per_unit)
            if how == "y-flip":
                codes = codes[::-1]
            depth_path = depth_dir / image
            if float_npy:
                depth_path = depth_path.with_suffix(".npy")
                np.save(depth_path, np.where(np.isfinite(depth), depth, 0).astype(np.float32))
            elif i not in missing:
                write_png16(depth_path, codes)
            frames.append({"file_path": f"images/{image}", "depth_file_path": str(depth_path.relative_to(self.root)),
                           "transform_matrix": matrix.tolist()})
        t = self.trajectory
        document = {"camera_model": "OPENCV", "fl_x": t.fx, "fl_y": t.fx, "cx": t.cx, "cy": t.cy, "w": float(t.width),
                    "h": float(t.height),
                    "k1": 0.0, "k2": 0.0, "p1": 0.0, "p2": 0.0, "frames": frames}
        path = self.root / name
        path.write_text(json.dumps(document, indent=1))
        return path

    # ---- Agisoft Metashape ------------------------------------------------------------------
    def metashape(self, name="cameras.xml", drop_scale=False):
        """cameras.xml as Metashape exports it (its manual's camera model and its export scripts):
        a frame sensor with f and cx, cy as offsets from the image centre (top-left pixel centre
        at 0.5), each camera's camera-to-chunk <transform> row-major in OpenCV axes, and the chunk's
        <transform> (world = s·R·p + t) after the cameras; every third camera in a <group>, one
        more disabled camera (its pose sheared: it must be skipped). Depth maps: depth/{stem}.npy,
        float32 eye-z. `drop_scale`: the chunk's <scale> left out, as a converter that ignores it
        would write the file."""
        t = self.trajectory
        angle = math.radians(25.0)
        axis = np.array([1.0, 2.0, 2.0]) / 3.0
        k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        rotation = np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k  # Rodrigues
        translation, scale = np.array([4.0, -1.5, 0.25]), 1.75
        depth = self.root / "depth"
        depth.mkdir(exist_ok=True)

        def camera_xml(i, label, pose, extra=""):
            world_from_camera = np.linalg.inv(pose)
            rc = rotation.T @ world_from_camera[:3, :3]
            tc = rotation.T @ (world_from_camera[:3, 3] - translation) / scale
            m = np.eye(4)
            m[:3, :3], m[:3, 3] = rc, tc
            numbers = " ".join(repr(float(v)) for v in m.reshape(-1))
            return (f'      <camera id="{i}" sensor_id="0" component_id="0" label="{label}"{extra}>\n'
                    f"        <transform>{numbers}</transform>\n"
                    "        <rotation_covariance>1e-06 0 0 0 1e-06 0 0 0 1e-06</rotation_covariance>\n"
                    "        <orientation>1</orientation>\n      </camera>\n")

        grouped, loose = [], []
        for i, (pose, image) in enumerate(zip(t.poses, t.names)):
            label = image.replace(".png", ".JPG")
            np.save(depth / (label.rsplit(".", 1)[0] + ".npy"), self.eye_z(i).astype(np.float32))
            (grouped if i % 3 == 0 else loose).append(camera_xml(i, label, pose))
        sheared = t.poses[0].copy()
        sheared[0, 1] += 0.5  # not a rotation: read, it would fail the whole file
        loose.append(camera_xml(len(t.poses), "disabled.JPG", sheared, ' enabled="false"'))
        similarity = ("    <transform>\n"
                      f"      <rotation locked=\"false\">{' '.join(repr(float(v)) for v in rotation.reshape(-1))}</rotation>\n"
                      f"      <translation locked=\"false\">{' '.join(repr(float(v)) for v in translation)}</translation>\n"
                      + ("" if drop_scale else f"      <scale locked=\"false\">{scale!r}</scale>\n") +
                      "    </transform>\n")
        text = ('<?xml version="1.0" encoding="UTF-8"?>\n<document version="1.5.0">\n  <chunk label="Chunk 1" enabled="true">\n'
                '    <sensors next_id="1">\n      <sensor id="0" label="camera" type="frame">\n'
                f'        <resolution width="{t.width}" height="{t.height}"/>\n'
                '        <property name="pixel_width" value="0.0039"/>\n        <bands><band label="Red"/></bands>\n'
                '        <data_type>uint8</data_type>\n        <calibration type="frame" class="adjusted">\n'
                f'          <resolution width="{t.width}" height="{t.height}"/>\n'
                f"          <f>{t.fx!r}</f>\n          <cx>{t.cx - t.width / 2!r}</cx>\n          <cy>{t.cy - t.height / 2!r}</cy>\n"
                "        </calibration>\n      </sensor>\n    </sensors>\n"
                '    <cameras next_id="99" next_group_id="1">\n      <group id="0" label="Group 1" type="folder">\n'
                + "".join("  " + c.replace("\n      ", "\n        ") for c in grouped) + "      </group>\n" + "".join(loose) +
                "    </cameras>\n" + similarity +
                '    <reference>LOCAL_CS["Local Coordinates (m)",LOCAL_DATUM["Local Datum",0],UNIT["metre",1]]</reference>\n'
                "  </chunk>\n</document>\n")
        path = self.root / name
        path.write_text(text)
        return path

    # ---- a manifest over every other format ----------------------------------------------
    def opencv_file(self, i):
        """OpenCV FileStorage YAML of frame i: camera_matrix (centre of the top-left pixel at 0),
        R and T world-to-camera."""
        path = self.root / "opencv" / f"frame_{i:03d}.yml"
        path.parent.mkdir(parents=True, exist_ok=True)
        k, pose = self.trajectory.k, self.trajectory.poses[i]

        def matrix(name, rows, cols, values):
            data = ", ".join(repr(float(v)) for v in np.ravel(values))
            return f"{name}: !!opencv-matrix\n   rows: {rows}\n   cols: {cols}\n   dt: d\n   data: [ {data} ]\n"

        path.write_text("%YAML:1.0\n---\n" + f"image_width: {self.trajectory.width}\nimage_height: {self.trajectory.height}\n" + matrix("camera_matrix", 3, 3, k) +
                        matrix("distortion_coefficients", 5, 1, np.zeros(5)) + matrix("R", 3, 3, pose[:3, :3]) +
                        matrix("T", 3, 1, pose[:3, 3]))
        return path

    def gltf_with_cameras(self, name="scene.gltf"):
        """The mesh and one perspective camera node per frame (camera-to-world, OpenGL axes)."""
        vertices = np.asarray(self.scene.vertices, "<f4")
        triangles = np.asarray(self.scene.triangles, "<u4")
        blob = vertices.tobytes() + triangles.tobytes()
        yfov = 2 * math.atan(self.trajectory.height / 2 / self.trajectory.fx)
        nodes = [{"mesh": 0, "name": "mesh"}]
        for i, pose in enumerate(self.trajectory.poses):
            c2w = np.linalg.inv(pose) @ OPENCV_TO_OPENGL
            nodes.append({"name": f"cam_{i:03d}", "camera": 0, "matrix": c2w.T.ravel().tolist()})  # column-major
        document = {
            "asset": {"version": "2.0"},
            "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
            "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": vertices.nbytes},
                            {"buffer": 0, "byteOffset": vertices.nbytes, "byteLength": triangles.nbytes}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(vertices), "type": "VEC3",
                           "min": vertices.min(0).tolist(), "max": vertices.max(0).tolist()},
                          {"bufferView": 1, "componentType": 5125, "count": triangles.size, "type": "SCALAR"}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
            "cameras": [{"type": "perspective", "perspective": {"yfov": yfov, "aspectRatio": self.trajectory.width / self.trajectory.height,
                                                                "znear": min(n for n, _ in self.trajectory.clip),
                                                                "zfar": max(f for _, f in self.trajectory.clip)}}],
            "nodes": nodes,
            "scenes": [{"nodes": list(range(len(nodes)))}],
            "scene": 0,
        }
        path = self.root / name
        path.write_text(json.dumps(document))
        return path

    def ros_frame(self, i):
        """ROS CameraInfo of frame i (the calibration file's form) and, since CameraInfo has no
        pose — its optical frame is the world — the mesh moved into that frame, as an OBJ."""
        folder = self.root / "ros"
        folder.mkdir(parents=True, exist_ok=True)
        k = self.trajectory.k
        p = np.hstack([k, np.zeros((3, 1))])
        data = lambda m: ", ".join(repr(float(v)) for v in np.ravel(m))  # noqa: E731
        info = folder / f"frame_{i:03d}.yaml"
        info.write_text(f"image_width: {self.trajectory.width}\nimage_height: {self.trajectory.height}\ncamera_name: cam\n"
                        f"camera_matrix:\n  rows: 3\n  cols: 3\n  data: [{data(k)}]\n"
                        "distortion_model: plumb_bob\n"
                        "distortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [0, 0, 0, 0, 0]\n"
                        "rectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
                        f"projection_matrix:\n  rows: 3\n  cols: 4\n  data: [{data(p)}]\n")
        pose = self.trajectory.poses[i]
        vertices = np.asarray(self.scene.vertices, float) @ pose[:3, :3].T + pose[:3, 3]
        mesh = folder / f"frame_{i:03d}.obj"
        with mesh.open("w") as f:
            f.writelines(f"v {x!r} {y!r} {z!r}\n" for x, y, z in vertices.astype(np.float32).astype(float))
            f.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in np.asarray(self.scene.triangles))
        return info, mesh

    def manifest(self, name, colmap_folder, transforms_path, gltf_path, broken_lines=()):
        """A manifest whose frames use every camera format and every depth format:
        COLMAP references with .npy, transforms references with the PNGs, OpenCV files with EXR,
        inline zcheck cameras with HDF5 (BlenderProc's depth and distance), glTF cameras with
        COLMAP depth maps, ROS CameraInfo files with 16-bit PNGs and a scene of their own (the
        mesh in the camera's frame)."""
        depth_dir = self.root / "manifest_depth"
        depth_dir.mkdir(parents=True, exist_ok=True)
        colmap_depth = self.colmap_depth_maps("manifest_colmap_depth")
        lines = []
        transforms = json.loads(Path(transforms_path).read_text())
        for i, image in enumerate(self.trajectory.names):
            kind = i % 6
            line = {"frame": f"f{i:03d}", "quantity": "eye-z"}
            if kind == 0:
                np.save(depth_dir / f"{i:03d}.npy", self.eye_z(i))
                line.update(camera=f"{Path(colmap_folder).name}#{image}", depth=f"manifest_depth/{i:03d}.npy")
            elif kind == 1:
                line.update(camera=f"{Path(transforms_path).name}#{image}", depth=transforms["frames"][i]["depth_file_path"])
            elif kind == 2:
                write_exr(depth_dir / f"{i:03d}.exr", self.eye_z(i))
                line.update(camera=str(self.opencv_file(i).relative_to(self.root)), depth=f"manifest_depth/{i:03d}.exr")
            elif kind == 3:
                write_hdf5(depth_dir / f"{i:03d}.h5", depth=self.eye_z(i), distance=self.distance(i))
                camera = json.loads(self.trajectory.camera(i).to_json())
                line.update(camera=camera, depth=f"manifest_depth/{i:03d}.h5", channel="depth")
            elif kind == 4:
                line.update(camera=f"{Path(gltf_path).name}#cam_{i:03d}",
                            depth=str((colmap_depth / f"{image}.geometric.bin").relative_to(self.root)))
            else:
                info, mesh = self.ros_frame(i)
                write_png16(depth_dir / f"{i:03d}.png", self.millimetres(self.eye_z(i)))
                line.update(camera=str(info.relative_to(self.root)), depth=f"manifest_depth/{i:03d}.png", scale=1000,
                            scene=str(mesh.relative_to(self.root)))
            lines.append(json.dumps(line))
        for at in sorted(broken_lines, reverse=True):
            lines[at] = lines[at][: len(lines[at]) // 2]  # cut off mid-line: malformed JSON
        path = self.root / name
        path.write_text("\n".join(lines) + "\n")
        return path


def has(program):
    return shutil.which(program) is not None
