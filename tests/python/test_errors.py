"""Errors: zcheck.Error with the command line's one-line messages; array mistakes named by argument."""
import json

import numpy as np
import pytest

import zcheck
from helpers import H, W, cli_error_message, quad_camera, quad_scene, run_cli

GOOD = {"image": {"width": W, "height": H},
        "projection": {"type": "perspective", "fovy_deg": 50, "near": 0.1, "far": 100},
        "view": {"eye": [1.2, 2.4, 5.5], "target": [-0.3, 0.9, -4.0]}}


def changed(path, value):
    """GOOD with one key (a.b.c) set, or deleted when value is ...; a deep copy."""
    document = json.loads(json.dumps(GOOD))
    *parents, last = path.split(".")
    node = document
    for key in parents:
        node = node.setdefault(key, {})
    if value is ...:
        del node[last]
    else:
        node[last] = value
    return document


BAD_CAMERAS = [
    ("projection.fovy_deg", 200),           # invalid value
    ("projection.fovy_deg", "60"),          # wrong type
    ("projection.fov", 60),                 # unknown key
    ("view.up", [0, 0]),                    # wrong length
    ("projection", ...),                    # missing
    ("projection.far", 0.05),               # far < near
    ("convention", "opengles"),             # unknown preset
    ("depth", {"format": "unorm32"}),       # unknown format
    ("view", {"eye_from_world": [2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1],
              "layout": "row-major", "vectors": "column"}),  # not rigid
]


@pytest.mark.parametrize("key,value", BAD_CAMERAS)
def test_bad_camera_messages_equal_the_cli(tmp_path, key, value):
    document = changed(key, value)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(document))
    rc, _, err = run_cli("check", "--camera", path)
    assert rc == 2
    cli = cli_error_message(err)
    with pytest.raises(zcheck.Error) as from_file:
        zcheck.Camera.from_file(str(path))
    assert str(from_file.value) == cli
    with pytest.raises(zcheck.Error) as from_dict:
        zcheck.Camera.from_dict(document)
    source = f"camera file '{path}'"
    assert cli.startswith(source)
    assert str(from_dict.value) == "camera dict" + cli[len(source):]


def test_json_text_errors_equal_the_cli(tmp_path):
    for text in ['{"projection": {"type": "perspective"}, "projection": {}}', '{"image": ', '[1, 2]']:
        path = tmp_path / "bad.json"
        path.write_text(text)
        _, _, err = run_cli("check", "--camera", path)
        with pytest.raises(zcheck.Error) as caught:
            zcheck.Camera.from_json(text, f"camera file '{path}'")
        assert str(caught.value) == cli_error_message(err)
    with pytest.raises(zcheck.Error, match="^camera dict: must be a dict"):
        zcheck.Camera.from_dict([1, 2])


def test_scene_file_errors_equal_the_cli(tmp_path):
    for name in [str(tmp_path / "missing.obj"), "builtin:nonesuch", "builtin:terrain?n=1", str(tmp_path)]:
        rc, _, err = run_cli("check", "--scene", name)
        assert rc == 2
        with pytest.raises(zcheck.Error) as caught:
            zcheck.Scene.from_file(name)
        assert str(caught.value) == cli_error_message(err)


def test_quantity_and_route_names(tmp_path, default_checker, small_camera, small_camera_file):
    z = default_checker.render(small_camera, "eye-z")
    path = tmp_path / "z.pfm"
    run_cli("export", "--camera", small_camera_file, "-o", path, check_rc=0)
    _, _, err = run_cli("verify", "--camera", small_camera_file, "--depth-map", path, "--quantity", "eye_z")
    with pytest.raises(zcheck.Error) as caught:
        default_checker.verify(small_camera, z, "eye_z")
    assert str(caught.value) == cli_error_message(err)
    with pytest.raises(zcheck.Error, match="^unknown quantity 'depth' .*eye-z.*primitive-id"):
        default_checker.render(small_camera, "depth")
    with pytest.raises(zcheck.Error, match="^unknown route 'gpu' \\(expected ray or raster\\)"):
        default_checker.render(small_camera, "eye-z", "gpu")
    with pytest.raises(zcheck.Error, match="dtype must be float32 or float64, got int32"):
        default_checker.render(small_camera, "eye-z", dtype=np.int32)
    # the quantity is required (mixing them up is what zcheck catches): a zcheck.Error, not pybind11's TypeError
    with pytest.raises(zcheck.Error, match="^quantity is required"):
        default_checker.verify(small_camera, z)


@pytest.mark.parametrize("vertices,triangles,message", [
    (np.zeros((4, 2)), [[0, 1, 2]], r"^Scene.from_arrays: vertices must have shape \(N, 3\) with N >= 1, got \(4, 2\)$"),
    (np.zeros((0, 3)), [[0, 1, 2]], r"vertices must have shape \(N, 3\) with N >= 1, got \(0, 3\)"),
    (np.eye(3), np.array([[0, 1, 2.0]]), "triangles must be an integer array of vertex indices, got dtype float64"),
    (np.eye(3), [0, 1, 2], r"triangles must have shape \(M, 3\) with M >= 1, got \(3,\)"),
    (np.eye(3), [[0, 1, 3]], r"triangles\[0, 2\] = 3 is not a vertex index \(0..2 for 3 vertices\)"),
    (np.eye(3), [[0, -1, 2]], r"triangles\[0, 1\] = -1 is not a vertex index"),
    (np.eye(3), np.array([[0, 1, 2]], dtype=np.uint64) | np.uint64(1 << 63),
     r"triangles\[0, 0\] = .* is not a vertex index"),
    ([[0, 0, 0], [1, np.nan, 0], [0, 1, 0]], [[0, 1, 2]], r"vertices\[1, 1\] = nan is not finite"),
    ([[0, 0, 0], [1e39, 0, 0], [0, 1, 0]], [[0, 1, 2]], r"vertices\[1, 0\] = 1e\+39 does not fit in binary32"),
    ([[0, 0, 0], [1e16, 0, 0], [0, 1, 0]], [[0, 1, 2]], r"^scene 'arrays' has a vertex coordinate 1\d+, beyond the ±1e15"),
    ([[0, 0, 0], [1, 1, 1], [2, 2, 2]], [[0, 1, 2]], "all its 1 triangles are degenerate"),
    ([["a", "b", "c"]], [[0, 0, 0]], "vertices must be an array of numbers"),
])
def test_scene_from_arrays_refusals(vertices, triangles, message):
    with pytest.raises(zcheck.Error, match=message):
        zcheck.Scene.from_arrays(vertices, triangles)


def test_depth_array_refusals(default_checker, small_camera):
    z = default_checker.render(small_camera, "eye-z")
    with pytest.raises(zcheck.Error, match=r"^depth must have shape \(120, 160\) = \(camera.height, camera.width\), "
                                           r"got \(160, 120\)$"):
        default_checker.verify(small_camera, z.T, "eye-z")
    with pytest.raises(zcheck.Error, match=r"got \(120, 160, 1\)"):
        zcheck.unproject(small_camera, z[..., None], "eye-z")
    with pytest.raises(zcheck.Error, match=r"^depth is an integer array \(uint16\): give scale="):
        default_checker.verify(small_camera, np.ones((H, W), np.uint16), "eye-z")
    with pytest.raises(zcheck.Error, match="^depth must be an array of numbers \\(float or integer\\), got dtype bool"):
        default_checker.diagnose(small_camera, z > 0, "eye-z")
    with pytest.raises(zcheck.Error, match="^scale must be a positive finite number, got -2"):
        default_checker.verify(small_camera, z, "eye-z", scale=-2)
    with pytest.raises(zcheck.Error, match="^space must be eye or world, got 'camera'"):
        zcheck.unproject(small_camera, z, "eye-z", space="camera")
    with pytest.raises(zcheck.Error, match="^stride must be in 1..16384, got 0"):
        zcheck.unproject(small_camera, z, "eye-z", stride=0)


def test_from_opencv_refusals():
    K = np.array([[100.0, 0, 79.5], [0, 100, 59.5], [0, 0, 1]])
    R, t = np.eye(3), np.zeros(3)
    at = "^Camera.from_opencv: "
    cases = [
        (dict(K=K[:2]), r"K must be a 3x3 matrix, got shape \(2, 3\)"),
        (dict(K=K + [[0, 1, 0], [0, 0, 0], [0, 0, 0]]), r"K\[0, 1\] \(skew\) must be 0"),
        (dict(K=K * 2), r"K must have the form \[\[fx, 0, cx\], \[0, fy, cy\], \[0, 0, 1\]\]"),
        (dict(R=R * 1.1), "'R' is not a rigid transform: its 3x3 rotation part is not orthonormal"),
        (dict(R=R[:2]), r"R must be a 3x3 matrix, got shape \(2, 3\)"),
        (dict(t=np.zeros(4)), r"t must have 3 elements \(shape \(3,\) or \(3, 1\)\), got shape \(4,\)"),
        (dict(R=np.diag([1.0, -1, 1])), "the rotation of 'R' has determinant -1: a reflection"),
        (dict(pixel_center=0.25), "K: pixel_center must be 0.0 .* or 0.5 .*, got 0.25"),
        (dict(width=None), "width and height \\(the image size in pixels\\) are required"),
        (dict(world_from_cam=np.eye(4)), "give the view as exactly one of R and t, cam_from_world= or world_from_cam="),
        (dict(R=None, t=None, cam_from_world=np.eye(4)[:2]), r"cam_from_world must be a 4x4 or 3x4 matrix, got shape"),
        (dict(R=None, t=None, world_from_cam=np.diag([1, 1, 1, 2.0])), "world_from_cam must have the last row 0 0 0 1"),
        (dict(K=K * [[-1], [1], [1]]), "K: the focal length fx must be a positive finite number of pixels, got -100"),
        (dict(far=0.01), "'projection.far' must be > projection.near"),
        (dict(convention="opengles"), "convention is invalid: "),
        (dict(depth_format="float16"), "depth_format is invalid: "),
    ]
    for change, message in cases:
        arguments = dict(K=K, R=R, t=t, width=W, height=H)
        arguments.update(change)
        with pytest.raises(zcheck.Error, match=at + message):
            zcheck.Camera.from_opencv(**{k: v for k, v in arguments.items() if v is not None or k == "width"})


def test_from_matrices_refusals():
    P = np.array([[1.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, -1.002, -0.2002], [0, 0, -1, 0]])
    at = "^Camera.from_matrices: "
    with pytest.raises(zcheck.Error, match=at + r"clip_from_eye must be a 4x4 matrix, got shape \(3, 4\)"):
        zcheck.Camera.from_matrices(P[:3], np.eye(4), W, H)
    with pytest.raises(zcheck.Error, match=at + "'eye_from_world' is not a rigid transform"):
        zcheck.Camera.from_matrices(P, np.diag([1, 2, 1, 1.0]), W, H)
    with pytest.raises(zcheck.Error, match=at + "give the view as exactly one of eye_from_world and world_from_eye="):
        zcheck.Camera.from_matrices(P, None, W, H)
    with pytest.raises(zcheck.Error, match=at + r"clip_from_eye\[2, 2\] is not finite \(nan\)"):
        zcheck.Camera.from_matrices(np.where(P == -1.002, np.nan, P), np.eye(4), W, H)
    with pytest.raises(zcheck.Error, match=at + "vectors must be \"column\""):
        zcheck.Camera.from_matrices(P, np.eye(4), W, H, vectors="columns")
    # the camera's own message, naming the matrix and asking about the convention
    with pytest.raises(zcheck.Error, match=at + "camera matrix 'projection.clip_from_eye' puts the near plane at eye-z "
                                                ".*is 'convention' or 'depth.reversed' right"):
        zcheck.Camera.from_matrices(P, np.diag([1, 1, -1, 1.0]), W, H, convention="direct3d")
    # a view whose rotation mirrors the picture in the convention's eye space (the pose rule)
    with pytest.raises(zcheck.Error, match=at + "the rotation of 'eye_from_world' has determinant 1: a reflection"):
        zcheck.Camera.from_matrices(P, np.eye(4), W, H, convention="direct3d")
    with pytest.raises(zcheck.Error, match="'image.width' must be in 1..16384 pixels, got 0"):
        zcheck.Camera.from_matrices(P, np.eye(4), 0, H)


def test_errors_are_one_line():
    with pytest.raises(zcheck.Error) as caught:
        zcheck.Scene.from_arrays(quad_scene(1).vertices[:, :2], [[0, 1, 2]])
    assert "\n" not in str(caught.value)
    assert isinstance(caught.value, ValueError)
    with pytest.raises(zcheck.Error, match="^threads must be in 1..1024, got 2000"):
        zcheck.Checker(quad_scene(1)).render(quad_camera(), "eye-z", threads=2000)


def test_regression_integral_float_image_sizes_were_refused_by_pybind11(tmp_path):
    """instant-ngp writes "w": 640.0: an integral float is a size; 640.5, a string or a bool is a
    zcheck.Error naming the argument (pybind11's own TypeError never reaches the user)."""
    K = np.array([[100.0, 0, 79.5], [0, 100, 59.5], [0, 0, 1]])
    R, t = np.eye(3), np.array([0.0, 0, 5])
    by_int = zcheck.Camera.from_opencv(K, R, t, W, H)
    by_float = zcheck.Camera.from_opencv(K, R, t, float(W), np.float32(H))
    assert (by_float.width, by_float.height) == (W, H)
    assert np.array_equal(by_int.matrices()["clip_from_world"], by_float.matrices()["clip_from_world"])
    P = np.array([[1.0, 0, 0, 0], [0, 1, 0, 0], [0, 0, -1.002, -0.2002], [0, 0, -1, 0]])
    assert zcheck.Camera.from_matrices(P, np.eye(4), width=float(W), height=float(H)).width == W
    assert by_int.replace(width=2.0 * W).width == 2 * W
    path = tmp_path / "camera.json"
    path.write_text(json.dumps(GOOD))
    assert zcheck.Camera.from_file(str(path), width=float(W), height=float(H)).height == H
    for value, message in [(W + 0.5, f"width must be a whole number of pixels, got {W + 0.5}"),
                           ("160", "width must be a number, got str"),
                           (True, "width must be a number, got bool")]:
        with pytest.raises(zcheck.Error, match="^Camera.from_opencv: " + message):
            zcheck.Camera.from_opencv(K, R, t, value, H)
        with pytest.raises(zcheck.Error, match="^Camera.replace: " + message):
            by_int.replace(width=value)
