"""Lens models against OpenCV, an independent implementation (python3-opencv): calib3d's
projectPoints and undistortPointsIter for the full model (4, 5, 8, 12 and 14 coefficients),
cv2.fisheye for Kannala-Brandt. Per model 100 random coefficient sets within realistic ranges;
projections agree to 1e-9 relative, and zcheck's unprojection, projected by OpenCV, lands back
on the pixel."""
import math

import cv2  # python3-opencv, installed by the test command (scripts/deps.sh --test): never skipped
import numpy as np
import pytest

import zcheck

W, H = 1280, 960


def random_K(rng):
    f = rng.uniform(350, 900)
    return np.array([[f, 0, W / 2 - 0.5 + rng.uniform(-30, 30)],
                     [0, f * rng.uniform(0.98, 1.02), H / 2 - 0.5 + rng.uniform(-30, 30)],
                     [0, 0, 1]])


def random_D(rng, n):
    full = [rng.uniform(-0.3, 0.1), rng.uniform(-0.05, 0.1), rng.uniform(-1e-3, 1e-3), rng.uniform(-1e-3, 1e-3),
            rng.uniform(-0.01, 0.01), rng.uniform(-0.05, 0.05), rng.uniform(-0.02, 0.02), rng.uniform(-0.01, 0.01),
            rng.uniform(-1e-3, 1e-3), rng.uniform(-1e-4, 1e-4), rng.uniform(-1e-3, 1e-3), rng.uniform(-1e-4, 1e-4),
            rng.uniform(-0.02, 0.02), rng.uniform(-0.02, 0.02)]
    return np.array(full[:n])


def cameras(rng, make, count=100):
    """`count` cameras from make(rng) -> (camera, K, D), skipping sets zcheck refuses as folding inside the image."""
    made = 0
    for _ in range(count * 4):
        try:
            camera, K, D = make(rng)
        except zcheck.Error as e:
            assert "folds" in str(e), str(e)
            continue
        made += 1
        yield camera, K, D
        if made == count:
            return
    pytest.fail(f"only {made} of {count} coefficient sets made a lens")


def points_in_view(rng, n, max_angle):
    theta = rng.uniform(0, max_angle, n)
    phi = rng.uniform(-math.pi, math.pi, n)
    r = rng.uniform(0.5, 20, n)
    return np.column_stack([r * np.sin(theta) * np.cos(phi), r * np.sin(theta) * np.sin(phi), r * np.cos(theta)])


@pytest.mark.parametrize("n", [4, 5, 8, 12, 14])
def test_opencv_full_model_agrees_with_cv2(n):
    rng = np.random.default_rng(1000 + n)

    def make(rng):
        K, D = random_K(rng), random_D(rng, n)
        return zcheck.Camera.from_opencv(K, np.eye(3), np.zeros(3), W, H, D=D), K, D

    compared = agreed = converged = 0
    for camera, K, D in cameras(rng, make):
        pts = points_in_view(rng, 300, math.radians(50))
        mine = camera.project(pts, space="eye")
        theirs = cv2.projectPoints(pts.reshape(-1, 1, 3), np.zeros(3), np.zeros(3), K, D)[0].reshape(-1, 2)
        seen = ~np.isnan(mine[:, 0])
        assert seen.sum() > 150  # most of a 50° cone is inside the field
        scale = np.maximum(1.0, np.abs(theirs[seen]))
        assert np.max(np.abs(mine[seen] - theirs[seen]) / scale) <= 1e-9
        # zcheck's rays for pixels across the image, projected by OpenCV, land on the pixels.
        u, v = np.meshgrid(np.linspace(0, W - 1, 17), np.linspace(0, H - 1, 13))
        pixels = np.column_stack([u.ravel(), v.ravel()])
        rays = camera.unproject(pixels, np.full(len(pixels), 3.0), "distance", space="eye")
        has = ~np.isnan(rays[:, 0])
        back = cv2.projectPoints(rays[has].reshape(-1, 1, 3), np.zeros(3), np.zeros(3), K, D)[0].reshape(-1, 2)
        assert np.max(np.abs(back - pixels[has])) <= 1e-9 * max(W, H)
        # OpenCV's own iterative undistortion, run to convergence, agrees with zcheck's rays.
        normalized = cv2.undistortPointsIter(pixels[has].reshape(-1, 1, 2), K, D, None, None,
                                             (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 1000, 1e-15))
        normalized = normalized.reshape(-1, 2)
        mine_normalized = rays[has][:, :2] / rays[has][:, 2:3]
        # Where OpenCV's fixed-point iteration converged (its answer projects back onto the pixel).
        again = cv2.projectPoints(np.column_stack([normalized, np.ones(len(normalized))]).reshape(-1, 1, 3),
                                  np.zeros(3), np.zeros(3), K, D)[0].reshape(-1, 2)
        good = np.linalg.norm(again - pixels[has], axis=1) <= 1e-6
        # Both preimages project onto the pixel; where they differ, OpenCV's lies beyond the fold
        # (the distortion maps a second, farther ring onto the same pixels), zcheck's inside its field.
        same = np.linalg.norm(normalized - mine_normalized, axis=1) <= 1e-8
        beyond = np.linalg.norm(normalized, axis=1) > np.linalg.norm(mine_normalized, axis=1) + 1e-6
        assert np.all(same[good] | beyond[good])
        agreed += same[good].sum()
        converged += good.sum()
        compared += 1
    assert compared == 100
    assert agreed >= converged // 2 > 0  # most of OpenCV's converged answers are zcheck's own


def test_opencv_fisheye_agrees_with_cv2_fisheye():
    rng = np.random.default_rng(2024)

    def make(rng):
        K = random_K(rng)
        D = np.array([rng.uniform(-0.05, 0.05), rng.uniform(-0.02, 0.02), rng.uniform(-0.005, 0.005),
                      rng.uniform(-0.001, 0.001)])
        return zcheck.Camera.from_opencv(K, np.eye(3), np.zeros(3), W, H, D=D, fisheye=True), K, D

    for camera, K, D in cameras(rng, make):
        pts = points_in_view(rng, 300, math.radians(85))  # cv2.fisheye projects the front half only
        mine = camera.project(pts, space="eye")
        theirs = cv2.fisheye.projectPoints(pts.reshape(-1, 1, 3), np.zeros(3), np.zeros(3), K, D)[0].reshape(-1, 2)
        seen = ~np.isnan(mine[:, 0])
        assert seen.sum() > 150
        scale = np.maximum(1.0, np.abs(theirs[seen]))
        assert np.max(np.abs(mine[seen] - theirs[seen]) / scale) <= 1e-9
        u, v = np.meshgrid(np.linspace(0, W - 1, 17), np.linspace(0, H - 1, 13))
        pixels = np.column_stack([u.ravel(), v.ravel()])
        rays = camera.unproject(pixels, np.full(len(pixels), 3.0), "distance", space="eye")
        has = ~np.isnan(rays[:, 0]) & (rays[:, 2] > 0)
        back = cv2.fisheye.projectPoints(rays[has].reshape(-1, 1, 3), np.zeros(3), np.zeros(3), K, D)[0].reshape(-1, 2)
        assert np.max(np.abs(back - pixels[has])) <= 1e-9 * max(W, H)


def test_lens_camera_refuses_window_depth_and_names_the_model():
    K = np.array([[300.0, 0, 319.5], [0, 300.0, 239.5], [0, 0, 1]])
    camera = zcheck.Camera.from_opencv(K, np.eye(3), np.zeros(3), 640, 480, D=[0.01, 0, 0, 0], fisheye=True)
    assert camera.lens == {"model": "opencv_fisheye", "fx": 300.0, "fy": 300.0, "cx": 319.5, "cy": 239.5,
                           "k1": 0.01, "k2": 0.0, "k3": 0.0, "k4": 0.0}
    with pytest.raises(zcheck.Error, match="no depth buffer"):
        camera.unproject([[10, 10]], [0.5], "window")
    with pytest.raises(zcheck.Error, match="D holds 3 coefficients"):
        zcheck.Camera.from_opencv(K, np.eye(3), np.zeros(3), 640, 480, D=[0.1, 0, 0])
    # Eye-z along a ray 90° or more off the axis does not exist: NaN, where distance has a point.
    wide = zcheck.Camera.from_opencv(np.array([[100.0, 0, 319.5], [0, 100.0, 239.5], [0, 0, 1]]), np.eye(3),
                                     np.zeros(3), 640, 480, D=[0, 0, 0, 0], fisheye=True)
    edge = np.array([[119.5, 239.5]])  # 200 px out at f = 100: θ = 2 rad, past 90°
    assert np.isnan(wide.unproject(edge, [2.0], "eye-z", space="eye")).all()
    point = wide.unproject(edge, [2.0], "distance", space="eye")[0]
    assert point[2] < 0 and abs(np.linalg.norm(point) - 2.0) < 1e-12


def write_with_cv2_filestorage(path, K, D, fisheye=False):
    """A calibration file as OpenCV itself writes one (cv2.FileStorage, YAML or XML by the name)."""
    fs = cv2.FileStorage(str(path), cv2.FILE_STORAGE_WRITE)
    fs.write("image_width", W)
    fs.write("image_height", H)
    if fisheye:
        fs.write("fisheye_model", 1)  # as camera_calibration.cpp writes its fisheye flag
    fs.write("camera_matrix", K)
    fs.write("distortion_coefficients", D.reshape(-1, 1))
    fs.release()


def assert_projects_as(camera, pts, theirs, least_seen):
    mine = camera.project(pts, space="eye")
    seen = ~np.isnan(mine[:, 0])
    assert seen.sum() >= least_seen
    scale = np.maximum(1.0, np.abs(theirs[seen]))
    assert np.max(np.abs(mine[seen] - theirs[seen]) / scale) <= 1e-9


@pytest.mark.parametrize("n,suffix", [(4, "yml"), (5, "xml"), (8, "yml"), (12, "xml"), (14, "yml")])
def test_opencv_file_written_by_cv2_reads_as_cv2_projects(tmp_path, n, suffix):
    """zcheck's OpenCV reader (format_opencv.cpp): a file cv2.FileStorage wrote, read by
    Camera.from_file, projects points where cv2.projectPoints puts them."""
    rng = np.random.default_rng(3000 + n)
    written = iter(range(1000))

    def make(rng):
        K, D = random_K(rng), random_D(rng, n)
        path = tmp_path / f"calib_{next(written)}.{suffix}"
        write_with_cv2_filestorage(path, K, D)
        return zcheck.Camera.from_file(str(path), near=0.1, far=100.0), K, D

    for camera, K, D in cameras(rng, make, count=5):
        assert camera.lens["model"] == "opencv"
        pts = points_in_view(rng, 200, math.radians(45))
        theirs = cv2.projectPoints(pts.reshape(-1, 1, 3), np.zeros(3), np.zeros(3), K, D)[0].reshape(-1, 2)
        assert_projects_as(camera, pts, theirs, 100)


def test_opencv_fisheye_file_written_by_cv2_reads_as_cv2_fisheye_projects(tmp_path):
    rng = np.random.default_rng(3100)
    written = iter(range(1000))

    def make(rng):
        K = random_K(rng)
        D = np.array([rng.uniform(-0.05, 0.05), rng.uniform(-0.02, 0.02), rng.uniform(-0.005, 0.005),
                      rng.uniform(-0.001, 0.001)])
        path = tmp_path / f"fisheye_{next(written)}.yml"
        write_with_cv2_filestorage(path, K, D, fisheye=True)
        return zcheck.Camera.from_file(str(path), near=0.1, far=100.0), K, D

    for camera, K, D in cameras(rng, make, count=5):
        assert camera.lens["model"] == "opencv_fisheye"
        pts = points_in_view(rng, 200, math.radians(85))
        theirs = cv2.fisheye.projectPoints(pts.reshape(-1, 1, 3), np.zeros(3), np.zeros(3), K, D)[0].reshape(-1, 2)
        assert_projects_as(camera, pts, theirs, 150)


@pytest.mark.parametrize("model,n", [("plumb_bob", 5), ("rational_polynomial", 8), ("equidistant", 4)])
def test_ros_camera_info_reads_as_image_geometry_projects(tmp_path, model, n):
    """A ROS CameraInfo file (camera_calibration_parsers' layout): image_geometry hands D to
    cv2.projectPoints (plumb_bob, rational_polynomial) or cv2.fisheye.projectPoints (equidistant);
    zcheck's raw camera agrees, and the rectified one (P) stays a pinhole."""
    rng = np.random.default_rng(3200 + n)
    fisheye = model == "equidistant"
    written = iter(range(1000))
    numbers = lambda values: ", ".join(repr(float(v)) for v in values)

    def make(rng):
        K = random_K(rng)
        D = np.array([rng.uniform(-0.05, 0.05), rng.uniform(-0.02, 0.02), rng.uniform(-0.005, 0.005),
                      rng.uniform(-0.001, 0.001)]) if fisheye else random_D(rng, n)
        path = tmp_path / f"camera_{next(written)}.yaml"
        path.write_text(f"image_width: {W}\nimage_height: {H}\ncamera_name: cam\n"
                        f"camera_matrix:\n  rows: 3\n  cols: 3\n  data: [{numbers(K.ravel())}]\n"
                        f"distortion_model: {model}\n"
                        f"distortion_coefficients:\n  rows: 1\n  cols: {n}\n  data: [{numbers(D)}]\n"
                        "rectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
                        f"projection_matrix:\n  rows: 3\n  cols: 4\n"
                        f"  data: [{numbers(K[0])}, 0, {numbers(K[1])}, 0, 0, 0, 1, 0]\n")
        rectified = zcheck.Camera.from_file(f"{path}#rectified", format="ros", near=0.1, far=100.0)
        assert rectified.lens is None
        return zcheck.Camera.from_file(f"{path}#raw", format="ros", near=0.1, far=100.0), K, D

    for camera, K, D in cameras(rng, make, count=3):
        assert camera.lens["model"] == ("opencv_fisheye" if fisheye else "opencv")
        pts = points_in_view(rng, 200, math.radians(45))
        project = cv2.fisheye.projectPoints if fisheye else cv2.projectPoints
        theirs = project(pts.reshape(-1, 1, 3), np.zeros(3), np.zeros(3), K, D)[0].reshape(-1, 2)
        assert_projects_as(camera, pts, theirs, 100)


def test_undistorted_camera_is_getoptimalnewcameramatrix():
    """Camera.undistorted(alpha) computes OpenCV's getOptimalNewCameraMatrix (calib3d's rectangles
    of a 9x9 grid of undistorted pixels): exactly, against the same rectangles computed here from
    OpenCV's undistortion run to convergence; and to 1 % against cv2's own function, whose
    undistortion stops after 5 fixed-point iterations."""
    rng = np.random.default_rng(77)
    compared_with_cv2 = 0
    for trial in range(20):
        K = random_K(rng)
        mild = 0.1 if trial % 2 else 1.0  # half of them mild enough for cv2's 5 iterations
        D = mild * np.array([rng.uniform(-0.2, 0.0), rng.uniform(0.0, 0.05), rng.uniform(-1e-3, 1e-3),
                      rng.uniform(-1e-3, 1e-3), rng.uniform(-0.005, 0.005)])
        camera = zcheck.Camera.from_opencv(K, np.eye(3), np.zeros(3), W, H, D=D)
        u, v = np.meshgrid(np.arange(9) * W / 8, np.arange(9) * H / 8)  # calib3d's icvGetRectangles' grid
        grid = np.column_stack([u.ravel(), v.ravel()]).reshape(-1, 1, 2)
        plane = cv2.undistortPointsIter(grid, K, D, None, None,
                                        (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 1000, 1e-15)).reshape(9, 9, 2)
        outer = plane[..., 0].min(), plane[..., 0].max(), plane[..., 1].min(), plane[..., 1].max()
        inner = plane[:, 0, 0].max(), plane[:, -1, 0].min(), plane[0, :, 1].max(), plane[-1, :, 1].min()
        for alpha in (0.0, 0.5, 1.0):
            p = camera.undistorted(alpha).to_dict()["projection"]
            fx0, fy0 = (W - 1) / (inner[1] - inner[0]), (H - 1) / (inner[3] - inner[2])
            fx1, fy1 = (W - 1) / (outer[1] - outer[0]), (H - 1) / (outer[3] - outer[2])
            expected = [fx0 * (1 - alpha) + fx1 * alpha, fy0 * (1 - alpha) + fy1 * alpha,
                        -fx0 * inner[0] * (1 - alpha) - fx1 * outer[0] * alpha,
                        -fy0 * inner[2] * (1 - alpha) - fy1 * outer[2] * alpha]
            assert np.allclose([p["fx"], p["fy"], p["cx"], p["cy"]], expected, rtol=1e-9, atol=1e-7)
            # cv2's own function, where its 5-iteration undistortion of the grid has converged.
            plane5 = cv2.undistortPoints(grid, K, D).reshape(9, 9, 2)
            if np.max(np.abs(plane5 - plane)) < 1e-6:
                theirs = cv2.getOptimalNewCameraMatrix(K, D, (W, H), alpha)[0]
                assert np.allclose([p["fx"], p["fy"], p["cx"], p["cy"]],
                                   [theirs[0, 0], theirs[1, 1], theirs[0, 2], theirs[1, 2]], rtol=1e-6)
                compared_with_cv2 += 1
    assert compared_with_cv2 >= 3
