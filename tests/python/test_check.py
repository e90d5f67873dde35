"""zcheck.Checker.check against `zcheck check` on the same inputs; module attributes; threads."""
import json
import threading
import time

import numpy as np
import pytest

import zcheck
from helpers import H, W, assert_documents_equal, run_cli, without_timings


def test_version_matches_the_command():
    _, out, _ = run_cli("--version", check_rc=0)
    assert zcheck.__version__ == out.strip()
    assert zcheck.__version__.count(".") == 2


def test_module_lists():
    assert zcheck.conventions == ["opengl", "direct3d", "vulkan", "metal", "opencv"]
    assert zcheck.depth_quantities == ["window", "ndc", "eye-z", "distance"]
    assert zcheck.quantities[:4] == zcheck.depth_quantities
    assert "primitive-id" in zcheck.quantities and "normal" in zcheck.quantities
    assert zcheck.depth_formats == ["float32", "unorm24", "unorm16"]
    assert "builtin:default" in zcheck.builtin_scenes
    assert zcheck.pixel_classes[0] == "both-miss" and zcheck.pixel_classes[1] == "agree"
    names = [m["name"] for m in zcheck.mistakes]
    assert "y-flip" in names and "distance-as-eye-z" in names
    assert issubclass(zcheck.Error, ValueError)


def test_check_default_camera_equals_cli_json(default_checker):
    """The whole `check --json` document, key by key, but for the timings."""
    _, out, _ = run_cli("check", "--json", check_rc=0)
    cli = json.loads(out)
    report = default_checker.check()
    py = report.to_dict()
    assert_documents_equal(without_timings(py), without_timings(cli))
    assert sorted(py["timings_ms"]) == sorted(cli["timings_ms"])
    # the properties read the same report
    pixels = cli["pixels"]
    assert report.consistent is cli["consistent"] is True
    assert (report.both_hit, report.both_miss, report.ray_only, report.raster_only) == (
        pixels["both_hit"], pixels["both_miss"], pixels["ray_only"], pixels["raster_only"])
    assert (report.agree, report.edge_surface, report.depth_errors, report.coverage_unexplained) == (
        pixels["agree"], pixels["edge_surface"], pixels["depth_errors"], pixels["coverage_unexplained"])
    assert report.max_error_over_tolerance == pytest.approx(cli["depth_error"]["max_over_tolerance"], rel=1e-12)
    assert report.width * report.height == pixels["total"] == 640 * 480
    assert report.to_dict() == json.loads(report.to_json())


def test_check_small_camera_file_equals_cli(default_checker, small_camera_file):
    """A camera file read by both, with the command's --width/--depth-format overrides mirrored by replace()."""
    camera = zcheck.Camera.from_file(small_camera_file)
    for extra, replaced in [((), camera),
                            (("--depth-format", "unorm16"), camera.replace(depth_format="unorm16")),
                            (("--convention", "vulkan", "--reversed-z"), camera.replace(convention="vulkan", reversed=True))]:
        rc, out, _ = run_cli("check", "--json", "--camera", small_camera_file, *extra)
        cli = json.loads(out)
        report = default_checker.check(replaced)
        assert rc == (0 if report.consistent else 1)
        assert_documents_equal(without_timings(report.to_dict()), without_timings(cli))


def test_summary_equals_cli_text_but_timings(default_checker, small_camera_file):
    _, out, _ = run_cli("check", "--camera", small_camera_file, check_rc=0)
    summary = default_checker.check(zcheck.Camera.from_file(small_camera_file)).summary()
    strip = lambda text: [line for line in text.splitlines() if not line.startswith("timings")]
    assert strip(summary) == strip(out)
    assert "verdict    CONSISTENT" in summary


def test_report_images(default_checker, small_camera):
    report = default_checker.check(small_camera)
    classes = report.pixel_classes
    assert classes.shape == (H, W) and classes.dtype == np.uint8
    counts = np.bincount(classes.ravel(), minlength=len(zcheck.pixel_classes))
    assert counts[zcheck.pixel_classes.index("agree")] == report.agree
    assert counts[zcheck.pixel_classes.index("both-miss")] == report.both_miss
    ray_missed = np.isin(classes, [zcheck.pixel_classes.index(name)
                                   for name in ("both-miss", "raster-only-edge", "raster-only")])
    ray = report.ray_window_depth
    assert ray.shape == (H, W) and ray.dtype == np.float64
    assert np.all(ray[ray_missed] == small_camera.clear_value)
    assert np.all(ray[~ray_missed] < 1.0)
    agree = classes == zcheck.pixel_classes.index("agree")
    assert np.all(report.error_over_tolerance[agree] <= 1.0)
    # the raster route stores float32 values of the same depths
    assert np.allclose(report.compared_window_depth[agree], ray[agree], rtol=0, atol=1e-5)


def test_check_without_pixels_reports_the_same_and_refuses_the_arrays(default_checker, small_camera):
    """keep_pixels=False: tile by tile, as `zcheck check` without --out; the same report."""
    kept = default_checker.check(small_camera)
    tiled = default_checker.check(small_camera, keep_pixels=False)
    assert_documents_equal(without_timings(tiled.to_dict()), without_timings(kept.to_dict()), rel=0)
    assert tiled.to_dict()["timings_ms"]["tile_by_tile"] is True
    assert kept.to_dict()["timings_ms"]["tile_by_tile"] is False
    for name in ("pixel_classes", "error_over_tolerance", "ray_window_depth", "compared_window_depth"):
        with pytest.raises(zcheck.Error, match="keep_pixels=False"):
            getattr(tiled, name)
    # and the command, which checks tile by tile without --out, prints that same report
    _, out, _ = run_cli("check", "--json", check_rc=0)
    assert_documents_equal(without_timings(json.loads(out)),
                           without_timings(default_checker.check(keep_pixels=False).to_dict()), rel=0)


def test_nothing_to_compare_is_refused_like_the_cli(default_checker, tmp_path):
    camera = {"image": {"width": W, "height": H},
              "projection": {"type": "perspective", "fovy_deg": 40, "near": 0.1, "far": 100},
              "view": {"eye": [0, 1, 50], "target": [0, 1, 100]}}
    path = tmp_path / "away.json"
    path.write_text(json.dumps(camera))
    rc, _, err = run_cli("check", "--camera", path)
    assert rc == 2
    with pytest.raises(zcheck.Error) as caught:
        default_checker.check(zcheck.Camera.from_dict(camera))
    assert "zcheck: error: " + str(caught.value) == err.strip()


def test_threads_argument(default_checker, small_camera):
    one = default_checker.check(small_camera, threads=1).to_dict()
    two = default_checker.check(small_camera, threads=2).to_dict()
    assert without_timings(one) == without_timings(two)
    with pytest.raises(zcheck.Error, match="threads must be in 1..1024, got 0"):
        default_checker.check(small_camera, threads=0)


def test_concurrent_checks_give_identical_results(default_checker, small_camera):
    results, errors = [None, None], []

    def work(k):
        try:
            results[k] = default_checker.check(small_camera).to_dict()
        except Exception as e:  # pragma: no cover - reported below
            errors.append(e)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=60)
    assert not errors and all(not t.is_alive() for t in threads)
    assert without_timings(results[0]) == without_timings(results[1])
    assert results[0]["consistent"] is True


def test_gil_is_released_during_check():
    """While another thread is inside check(), this thread keeps running: the longest pause between
    two of its loop iterations stays far below the duration of one check."""
    checker = zcheck.Checker(zcheck.Scene.from_file("builtin:terrain?n=200"))
    # (800x600 became too quick to tell, at 0.045 s, once the comparison got faster)
    camera = checker.scene.default_camera.replace(width=1600, height=1200)
    start = time.perf_counter()
    checker.check(camera, threads=1)
    duration = time.perf_counter() - start
    assert duration > 0.05, "the workload is too small to tell"

    done = threading.Event()
    worker = threading.Thread(target=lambda: (checker.check(camera, threads=1), done.set()))
    last, longest, iterations = time.perf_counter(), 0.0, 0
    worker.start()  # (measured too: a worker holding the GIL would block start() itself)
    while not done.is_set():
        now = time.perf_counter()
        longest, last = max(longest, now - last), now
        iterations += 1
    worker.join()
    assert iterations > 100
    assert longest < duration / 2, f"this thread stalled {longest:.3f} s of a {duration:.3f} s check"


def test_a_checker_built_for_one_frame_builds_its_bvh_quickly_and_reports_the_same():
    scene = zcheck.Scene.from_file("builtin:terrain?n=300")  # 178,802 triangles
    camera = scene.default_camera.replace(width=320, height=240)
    thorough = zcheck.Checker(scene)
    quick = zcheck.Checker(scene, expected_rays=320 * 240)  # 0.43 rays per triangle
    assert thorough.bvh_build == "thorough" and quick.bvh_build == "quick"
    assert zcheck.Checker(scene, expected_rays=10 * scene.triangle_count).bvh_build == "thorough"
    a, b = quick.check(camera), thorough.check(camera)
    assert a.consistent and b.consistent
    assert without_timings(a.to_dict()) == without_timings(b.to_dict())
    assert np.array_equal(quick.render(camera, "window", route="ray"), thorough.render(camera, "window", route="ray"))
    for bad in [-1.0, float("nan")]:
        with pytest.raises(zcheck.Error, match="expected_rays .* must be a count of rays"):
            zcheck.Checker(scene, expected_rays=bad)
