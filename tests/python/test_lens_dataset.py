"""A dataset of lens cameras verified as one command: a COLMAP model whose images use an
OPENCV_FISHEYE and an OPENCV camera, with distance maps rendered through them; one frame's map made
with the distortion left out, and one made with the next frame's camera (a list shifted by one),
are found and named."""
import json

import numpy as np
import pytest

import zcheck
from dataset_maker import Trajectory, quaternion_of
from helpers import run_cli

W, H = 160, 120
BUILTIN = "builtin:default"

LENSES = {  # COLMAP model line after "ID MODEL W H", in COLMAP's pixel coordinates (centre 0.5)
    1: ("OPENCV_FISHEYE", [60.0, 60.0, 80.0, 60.0, 0.02, -0.004, 0.0007, -0.0001]),
    2: ("OPENCV", [120.0, 121.0, 80.5, 59.5, -0.2, 0.05, 0.002, -0.001]),
}


def camera_for(model, params, pose, distortion=True):
    fx, fy, cx, cy, *d = params
    K = np.array([[fx, 0, cx - 0.5], [0, fy, cy - 0.5], [0, 0, 1]])
    if not distortion:
        return zcheck.Camera.from_opencv(K, cam_from_world=pose, width=W, height=H, near=0.05, far=100)
    return zcheck.Camera.from_opencv(K, cam_from_world=pose, width=W, height=H, near=0.05, far=100,
                                     D=np.array(d), fisheye=model == "OPENCV_FISHEYE")


@pytest.fixture(scope="module")
def lens_dataset(tmp_path_factory):
    root = tmp_path_factory.mktemp("lens_dataset")
    scene = zcheck.Scene.from_file(BUILTIN)
    checker = zcheck.Checker(scene)
    trajectory = Trajectory(scene, 6, W, H)
    model = root / "sparse"
    model.mkdir()
    (model / "cameras.txt").write_text("".join(
        f"{cid} {name} {W} {H} " + " ".join(repr(p) for p in params) + "\n" for cid, (name, params) in LENSES.items()))
    images, depth = [], root / "depth"
    depth.mkdir()
    def lens_of(i):
        return LENSES[1 if i % 2 == 0 else 2]
    for i, pose in enumerate(trajectory.poses):
        cid = 1 if i % 2 == 0 else 2
        name, params = lens_of(i)
        # COLMAP's qvec, tvec of the OpenCV cam_from_world.
        q, t = list(quaternion_of(pose[:3, :3])), list(pose[:3, 3])
        images.append(f"{i + 1} " + " ".join(repr(float(v)) for v in q + t) + f" {cid} frame_{i:03d}.png\n\n")
        distortion = i != 3  # frame 3: rendered through the pinhole of its K, the lens left out
        camera = camera_for(name, params, pose, distortion)
        if i == 4:  # frame 4: rendered with frame 5's camera, lens and pose
            camera = camera_for(*lens_of(5), trajectory.poses[5])
        distance = checker.render(camera, "distance", route="ray")
        np.save(depth / f"frame_{i:03d}.npy", np.where(np.isfinite(distance), distance, 0).astype(np.float32))
    (model / "images.txt").write_text("".join(images))
    return root


def test_a_colmap_dataset_of_fisheye_and_distorted_cameras_verifies_and_names_the_frame_without_its_lens(lens_dataset):
    results = lens_dataset / "results.jsonl"
    code, out, err = run_cli("dataset", "verify", lens_dataset / "sparse", "--scene", BUILTIN, "--depth",
                             str(lens_dataset / "depth" / "{stem}.npy"), "--quantity", "distance", "--diagnose",
                             "-o", results)
    assert code == 1, (out, err)
    records = [json.loads(line) for line in results.read_text().splitlines() if line.strip()]
    frames = [r for r in records if "frame" in r]
    assert len(frames) == 6, records
    by_name = {r["frame"]: r for r in frames}
    for i in range(6):
        record = by_name[f"frame_{i:03d}.png"]
        if i == 3:
            assert not record["consistent"], record
            assert record["diagnosis"][0]["hypothesis"] == "distortion-ignored", record["diagnosis"][:2]
        elif i == 4:
            assert not record["consistent"], record
            assert record["diagnosis"][0]["hypothesis"] == "next-frame-camera", record["diagnosis"][:2]
        else:
            assert record["consistent"], record
