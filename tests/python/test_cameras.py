"""Cameras from files, dicts, OpenCV intrinsics/extrinsics and raw matrices, against textbook
matrices built here in numpy and against the command line."""
import json
import math

import numpy as np
import pytest

import zcheck
from helpers import H, W, gl_frustum, gl_look_at, gl_perspective, run_cli

# the default scene's own camera (builtin:default), at 160x120
EYE, TARGET, FOVY, NEAR, FAR = (1.2, 2.4, 5.5), (-0.3, 0.9, -4.0), 55.0, 0.1, 100.0
GL_FROM_CV = np.diag([1.0, -1.0, -1.0, 1.0])  # OpenCV camera axes -> OpenGL camera axes (its own inverse)


def opencv_pose():
    """K, R, t of the default camera in OpenCV conventions, derived here from gluLookAt."""
    fy = (H / 2) / math.tan(math.radians(FOVY) / 2)
    K = np.array([[fy, 0, (W - 1) / 2], [0, fy, (H - 1) / 2], [0, 0, 1]])
    cam_from_world = GL_FROM_CV @ gl_look_at(EYE, TARGET, (0, 1, 0))
    return K, cam_from_world[:3, :3], cam_from_world[:3, 3]


def renders_match(checker, a, b, rtol=1e-6, quantity="eye-z"):
    za, zb = checker.render(a, quantity, dtype=np.float64), checker.render(b, quantity, dtype=np.float64)
    hit_a, hit_b = np.isfinite(za), np.isfinite(zb)
    both = hit_a & hit_b
    return (np.count_nonzero(hit_a != hit_b) <= 2 and both.sum() > 0.5 * W * H
            and np.allclose(za[both], zb[both], rtol=rtol, atol=0))


def test_matrices_are_the_textbook_ones_and_the_clis(small_camera, small_camera_file):
    m = small_camera.matrices()
    assert np.allclose(m["clip_from_eye"], gl_perspective(FOVY, W / H, NEAR, FAR), rtol=1e-12, atol=1e-15)
    assert np.allclose(m["eye_from_world"], gl_look_at(EYE, TARGET, (0, 1, 0)), rtol=1e-12, atol=1e-15)
    assert np.allclose(m["clip_from_world"], m["clip_from_eye"] @ m["eye_from_world"], rtol=1e-12, atol=1e-15)
    assert np.allclose(m["window_from_ndc"], [[W / 2, 0, 0, W / 2], [0, H / 2, 0, H / 2],
                                              [0, 0, 0.5, 0.5], [0, 0, 0, 1]])
    assert (m["near"], m["far"]) == (NEAR, FAR)
    _, out, _ = run_cli("matrices", "--camera", small_camera_file, check_rc=0)
    cli = json.loads(out)
    for key in ("eye_from_world", "world_from_eye", "clip_from_eye", "eye_from_clip", "clip_from_world",
                "window_from_ndc", "ndc_from_window"):
        assert np.array_equal(m[key], np.array(cli[key])), key


def test_camera_file_dict_and_json_round_trip(tmp_path, small_camera):
    d = small_camera.to_dict()
    assert d["projection"] == {"type": "perspective", "fovy_deg": FOVY, "near": NEAR, "far": FAR}
    again = zcheck.Camera.from_dict(d)
    assert again.to_dict() == d and again.to_json() == small_camera.to_json()
    path = tmp_path / "c.json"
    path.write_text(small_camera.to_json())
    assert zcheck.Camera.from_file(str(path)).to_dict() == d
    # numpy values and math.inf are accepted in a dict
    d["view"]["eye"] = np.array(EYE)
    d["projection"]["far"] = math.inf
    d["image"]["width"] = np.int64(W)
    infinite = zcheck.Camera.from_dict(d)
    assert infinite.far == math.inf and infinite.to_dict()["projection"]["far"] == "inf"
    assert (infinite.width, infinite.height, infinite.convention, infinite.projection_type) == (W, H, "opengl",
                                                                                                "perspective")


def test_pixel_ray_and_point_at_equal_the_cli(small_camera, small_camera_file):
    _, out, _ = run_cli("unproject", "--camera", small_camera_file, "--pixel", "17,101", check_rc=0)
    cli = json.loads(out)
    ray = small_camera.pixel_ray(17, 101)
    assert ray["pixel"] == tuple(cli["pixel"]) and ray["window"] == tuple(cli["window"])
    for space in ("eye", "world"):
        for key in ("origin", "direction", "t_near", "t_far"):
            assert np.array_equal(ray[space][key], cli["ray"][space][key]), (space, key)
    _, out, _ = run_cli("unproject", "--camera", small_camera_file, "--pixel", "17,101", "--depth", "7.5",
                        "--quantity", "distance", check_rc=0)
    cli = json.loads(out)["point"]
    point = small_camera.point_at(17, 101, 7.5, "distance")
    for key in ("eye", "world", "eye_z", "distance"):
        assert np.array_equal(point[key], cli[key]), key
    assert point["distance"] == pytest.approx(7.5, rel=1e-14)
    with pytest.raises(zcheck.Error, match=r"pixel \(160, 0\) is outside the 160x120 image"):
        small_camera.pixel_ray(W, 0)


def test_from_opencv_equals_the_look_at_camera(default_checker, small_camera):
    K, R, t = opencv_pose()
    cv = zcheck.Camera.from_opencv(K, R, t, W, H, near=NEAR, far=FAR)
    assert (cv.convention, cv.projection_type, cv.width, cv.height) == ("opencv", "pinhole", W, H)
    assert renders_match(default_checker, cv, small_camera)
    assert renders_match(default_checker, cv, small_camera, quantity="distance")
    assert default_checker.check(cv).consistent
    # the eye axes are exactly OpenCV's: eye_from_world = [R t; 0 1]
    assert np.array_equal(cv.matrices()["eye_from_world"][:3], np.hstack([R, t[:, None]]))


def test_from_opencv_projects_like_K_R_t(default_checker):
    K, R, t = opencv_pose()
    cv = zcheck.Camera.from_opencv(K, R, t, W, H, near=NEAR, far=FAR)
    colmap = zcheck.Camera.from_opencv(K, R, t, W, H, near=NEAR, far=FAR, pixel_center=0.5)
    col, row, depth = 37, 81, 6.0

    def world_point(u, v):  # the point at eye-z `depth` that K[R|t] projects to (u, v)
        return R.T @ (depth * np.linalg.solve(K, [u, v, 1.0]) - t)

    def off_ray(camera, point):
        ray = camera.pixel_ray(col, row)["world"]
        v = point - ray["origin"]
        return np.linalg.norm(v - np.dot(v, ray["direction"]) * ray["direction"])

    x_cv, x_colmap = world_point(col, row), world_point(col + 0.5, row + 0.5)
    p = K @ (R @ x_cv + t)
    assert np.allclose(p[:2] / p[2], [col, row], atol=1e-9)
    # OpenCV: the centre of pixel (col, row) is (col, row); COLMAP: (col + 0.5, row + 0.5)
    assert off_ray(cv, x_cv) < 1e-9 and off_ray(colmap, x_colmap) < 1e-9
    half_pixel = 0.5 * math.hypot(1, 1) * depth / K[0, 0]
    assert off_ray(cv, x_colmap) == pytest.approx(half_pixel, rel=0.02)
    assert np.allclose(cv.point_at(col, row, depth, "eye-z")["world"], x_cv, atol=1e-9)
    assert np.allclose(colmap.point_at(col, row, depth, "eye-z")["world"], x_colmap, atol=1e-9)
    # and through the matrices: the window point of x_cv is the pixel centre (col + 0.5, row + 0.5)
    m = cv.matrices()
    clip = m["clip_from_world"] @ np.append(x_cv, 1.0)
    window = m["window_from_ndc"] @ (clip / clip[3])
    assert np.allclose(window[:2], [col + 0.5, row + 0.5], atol=1e-9)
    # the half-pixel shift changes the picture; the COLMAP camera with cx, cy + 0.5 is the OpenCV one
    assert not renders_match(default_checker, cv, colmap)
    K_colmap = K + np.array([[0, 0, 0.5], [0, 0, 0.5], [0, 0, 0]])
    shifted = zcheck.Camera.from_opencv(K_colmap, R, t, W, H, near=NEAR, far=FAR, pixel_center=0.5)
    assert shifted.to_dict() == cv.to_dict()


def test_from_opencv_alternative_extrinsics(default_checker):
    K, R, t = opencv_pose()
    cv = zcheck.Camera.from_opencv(K, R, t, W, H, near=NEAR, far=FAR)
    reference = default_checker.render(cv, "eye-z")
    Rt = np.hstack([R, t[:, None]])
    same = [zcheck.Camera.from_opencv(K, width=W, height=H, cam_from_world=Rt, near=NEAR, far=FAR),
            zcheck.Camera.from_opencv(K, width=W, height=H, cam_from_world=np.vstack([Rt, [0, 0, 0, 1]]),
                                      near=NEAR, far=FAR),
            zcheck.Camera.from_opencv(K, R=R, t=t.reshape(3, 1), width=W, height=H, near=NEAR, far=FAR)]
    for camera in same:
        assert np.array_equal(default_checker.render(camera, "eye-z"), reference)
    # camera-to-world (the pose), in OpenCV axes and in OpenGL axes (nerfstudio, Blender)
    world_from_cam = np.linalg.inv(np.vstack([Rt, [0, 0, 0, 1]]))
    pose = zcheck.Camera.from_opencv(K, width=W, height=H, world_from_cam=world_from_cam, near=NEAR, far=FAR)
    assert np.allclose(pose.matrices()["eye_from_world"], cv.matrices()["eye_from_world"], atol=1e-12)
    assert renders_match(default_checker, pose, cv, rtol=1e-9)
    gl_pose = world_from_cam @ GL_FROM_CV
    gl = zcheck.Camera.from_opencv(K, width=W, height=H, world_from_cam=gl_pose, convention="opengl",
                                   near=NEAR, far=FAR)
    assert gl.convention == "opengl"
    assert renders_match(default_checker, gl, cv, rtol=1e-9)
    # a pinhole camera file with the same numbers is the same camera
    as_file = {"convention": "opencv", "image": {"width": W, "height": H},
               "projection": {"type": "pinhole", "fx": K[0, 0], "fy": K[1, 1], "cx": K[0, 2], "cy": K[1, 2],
                              "near": NEAR, "far": FAR},
               "view": {"eye_from_world": np.vstack([Rt, [0, 0, 0, 1]]).ravel(), "layout": "row-major",
                        "vectors": "column"}}
    from_dict = zcheck.Camera.from_dict(as_file)
    assert from_dict.to_dict() == cv.to_dict()
    assert np.array_equal(default_checker.render(from_dict, "eye-z"), reference)


def test_from_matrices_equals_the_perspective_camera(default_checker, small_camera):
    P, V = gl_perspective(FOVY, W / H, NEAR, FAR), gl_look_at(EYE, TARGET, (0, 1, 0))
    camera = zcheck.Camera.from_matrices(P, V, W, H)
    assert (camera.projection_type, camera.convention) == ("matrix", "opengl")
    assert camera.near == pytest.approx(NEAR, rel=1e-12) and camera.far == pytest.approx(FAR, rel=1e-9)
    assert renders_match(default_checker, camera, small_camera)
    assert default_checker.check(camera).consistent
    # the same matrices for row vectors, the pose instead of the view matrix
    rows = zcheck.Camera.from_matrices(P.T, V.T, W, H, vectors="row")
    assert np.array_equal(default_checker.render(rows, "eye-z"), default_checker.render(camera, "eye-z"))
    pose = zcheck.Camera.from_matrices(P, width=W, height=H, world_from_eye=np.linalg.inv(V))
    assert renders_match(default_checker, pose, camera, rtol=1e-9)
    # GLM's column-major storage pasted as rows is the transpose: another camera (near 0.83, far 1.25
    # here), which sees nothing of the scene: check() refuses it as the command does
    wrong = zcheck.Camera.from_matrices(P.T, V, W, H)
    assert wrong.near == pytest.approx(1 / 1.2022022022, rel=1e-6) and wrong.far < 1.5
    with pytest.raises(zcheck.Error, match="^nothing to compare: neither route sees any surface of 'builtin:default'"):
        default_checker.check(wrong)


def test_from_matrices_glfrustum_and_direct3d(default_checker):
    l, r, b, t = -0.03, 0.05, -0.02, 0.04
    frustum = zcheck.Camera.from_dict({"image": {"width": W, "height": H},
                                       "projection": {"type": "frustum", "left": l, "right": r, "bottom": b,
                                                      "top": t, "near": NEAR, "far": FAR},
                                       "view": {"eye": list(EYE), "target": list(TARGET)}})
    V = gl_look_at(EYE, TARGET, (0, 1, 0))
    matrix = zcheck.Camera.from_matrices(gl_frustum(l, r, b, t, NEAR, FAR), V, W, H)
    assert renders_match(default_checker, matrix, frustum)
    # D3DXMatrixPerspectiveFovLH as D3DX prints it (row vectors), and the direct3d view: OpenGL's with z negated
    ys = 1 / math.tan(math.radians(FOVY) / 2)
    d3d = np.array([[ys / (W / H), 0, 0, 0], [0, ys, 0, 0], [0, 0, FAR / (FAR - NEAR), 1],
                    [0, 0, -NEAR * FAR / (FAR - NEAR), 0]])
    view = (np.diag([1.0, 1.0, -1.0, 1.0]) @ V).T
    camera = zcheck.Camera.from_matrices(d3d, view, W, H, convention="direct3d", vectors="row")
    perspective = zcheck.Camera.from_dict({"image": {"width": W, "height": H},
                                           "projection": {"type": "perspective", "fovy_deg": FOVY, "near": NEAR,
                                                          "far": FAR},
                                           "view": {"eye": list(EYE), "target": list(TARGET)}})
    assert renders_match(default_checker, camera, perspective)
    assert default_checker.check(camera).consistent


def test_regression_a_ros_calibration_with_an_empty_d_was_refused(tmp_path):
    """camera_calibration_parsers writes an empty D as rows 1, cols 0, data []: a pinhole (the
    raw camera and the rectified alike), whose pixel (10, 20) at eye-z 2 lies at K⁻¹(10, 20, 1)·2.
    A matrix side beyond any camera matrix's is refused naming the key."""
    K = np.array([[50.0, 0, 31.5], [0, 50.0, 23.5], [0, 0, 1]])
    text = ("image_width: 64\nimage_height: 48\ncamera_name: cam\n"
            "camera_matrix:\n  rows: 3\n  cols: 3\n  data: [50, 0, 31.5, 0, 50, 23.5, 0, 0, 1]\n"
            "distortion_model: plumb_bob\ndistortion_coefficients:\n  rows: 1\n  cols: 0\n  data: []\n"
            "rectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
            "projection_matrix:\n  rows: 3\n  cols: 4\n  data: [50, 0, 31.5, 0, 0, 50, 23.5, 0, 0, 0, 1, 0]\n")
    path = tmp_path / "camera_info.yaml"
    path.write_text(text)
    for frame in ("raw", "rectified"):
        camera = zcheck.Camera.from_file(f"{path}#{frame}", format="ros", near=0.1, far=100.0)
        assert camera.lens is None
        eye = camera.point_at(10, 20, 2.0, "eye-z")["eye"]
        assert np.allclose(np.abs(eye), np.abs(2.0 * np.linalg.solve(K, [10, 20, 1.0])), atol=1e-12)
    path.write_text(text.replace("cols: 0", "cols: 70"))
    with pytest.raises(zcheck.Error, match=r"'distortion_coefficients.cols' must be a whole number of matrix rows "
                                           r"or columns in 0..64, got 70"):
        zcheck.Camera.from_file(f"{path}#raw", format="ros", near=0.1, far=100.0)
