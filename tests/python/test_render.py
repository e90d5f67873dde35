"""Checker.render and zcheck.unproject on scenes from numpy arrays, against analytic values."""
import json

import numpy as np
import pytest

import zcheck
from helpers import H, W, assert_documents_equal, quad_camera, quad_scene, run_cli, without_timings

D, NEAR, FAR = 5.0, 0.5, 50.0


def test_scene_from_arrays_properties():
    scene = quad_scene(D)
    assert (scene.name, scene.vertex_count, scene.triangle_count) == ("quad", 4, 2)
    assert scene.vertices.dtype == np.float32 and scene.vertices.shape == (4, 3)
    assert scene.triangles.tolist() == [[0, 1, 2], [0, 2, 3]]
    lo, hi = scene.bounds
    assert lo.tolist() == [-10, -10, -D] and hi.tolist() == [10, 10, -D]
    # the default camera frames the bounding sphere as a loaded mesh's does: it sees the whole quad
    report = zcheck.Checker(scene).check()
    assert report.consistent and report.both_hit > 0


def test_scene_from_arrays_is_the_same_mesh_as_a_file(tmp_path):
    """The same triangles from an OBJ file: the same default camera, and check() equals `zcheck check --scene`."""
    rng = np.random.default_rng(7)
    vertices = np.round(rng.uniform(-3, 3, size=(30, 3)) * 8) / 8  # exact in binary32 and in the OBJ text
    triangles = rng.integers(0, 30, size=(40, 3))
    triangles = triangles[[len(set(t)) == 3 for t in triangles]]
    obj = tmp_path / "soup.obj"
    obj.write_text("".join(f"v {x} {y} {z}\n" for x, y, z in vertices) +
                   "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in triangles))
    from_file = zcheck.Scene.from_file(str(obj))
    from_arrays = zcheck.Scene.from_arrays(vertices.astype(np.float32), triangles.astype(np.uint32), name=str(obj))
    assert np.array_equal(from_file.vertices, from_arrays.vertices)
    assert np.array_equal(from_file.triangles, from_arrays.triangles)
    assert from_arrays.default_camera.to_dict() == from_file.default_camera.to_dict()
    rc, out, _ = run_cli("check", "--scene", obj, "--json", "--width", W, "--height", H)
    camera = from_arrays.default_camera.replace(width=W, height=H)
    report = zcheck.Checker(from_arrays).check(camera)
    assert rc == (0 if report.consistent else 1)
    assert_documents_equal(without_timings(report.to_dict()), without_timings(json.loads(out)))


def test_eye_z_of_a_facing_quad_is_its_distance():
    checker, camera = zcheck.Checker(quad_scene(D)), quad_camera(near=NEAR, far=FAR)
    z = checker.render(camera, "eye-z", dtype=np.float64)
    assert z.shape == (H, W) and z.dtype == np.float64
    assert np.all(np.abs(z - D) <= 1e-9)
    z32 = checker.render(camera, "eye-z")
    assert z32.dtype == np.float32 and np.all(z32 == np.float32(D))
    # distance grows away from the centre: sqrt(d^2 + x^2 + y^2) on the plane
    dist = checker.render(camera, "distance", dtype=np.float64)
    points = checker.render(camera, "position-eye", dtype=np.float64)
    assert points.shape == (H, W, 3)
    assert np.allclose(points[..., 2], -D, rtol=0, atol=1e-9)  # OpenGL eye space looks down -z
    assert np.allclose(dist, np.linalg.norm(points, axis=2), rtol=1e-12)
    assert dist.min() > D and dist.max() < D * 1.6


@pytest.mark.parametrize("convention", ["opengl", "vulkan", "direct3d", "opencv"])
def test_window_and_ndc_depth_follow_the_textbook_formula(convention):
    checker, camera = zcheck.Checker(quad_scene(D)), quad_camera(convention, near=NEAR, far=FAR)
    n, f = NEAR, FAR
    if convention == "opengl":  # NDC z in [-1, 1]
        z_ndc = (f + n) / (f - n) - 2 * f * n / ((f - n) * D)
        window = 0.5 * (z_ndc + 1)
    else:  # NDC z in [0, 1] = window depth
        z_ndc = f / (f - n) - f * n / ((f - n) * D)
        window = z_ndc
    assert np.allclose(checker.render(camera, "window", dtype=np.float64), window, rtol=0, atol=1e-12)
    assert np.allclose(checker.render(camera, "ndc", dtype=np.float64), z_ndc, rtol=0, atol=1e-12)
    # the same picture in every convention: eye-z everywhere d
    assert np.all(np.abs(checker.render(camera, "eye-z", dtype=np.float64) - D) <= 1e-9)


@pytest.mark.parametrize("convention", ["opengl", "vulkan", "direct3d", "opencv"])
def test_row_zero_is_the_top_of_the_picture(convention):
    """A quad spanning y >= 0 covers exactly the upper half of the image, in every convention and route."""
    checker, camera = zcheck.Checker(quad_scene(D, upper_half_only=True)), quad_camera(convention)
    for route in ("ray", "raster"):
        z = checker.render(camera, "eye-z", route)
        assert np.all(np.isfinite(z[: H // 2])), route
        assert np.all(np.isinf(z[H // 2:])), route
        assert np.allclose(z[: H // 2], D, rtol=1e-6)
        window = checker.render(camera, "window", route)
        assert np.all(window[H // 2:] == camera.clear_value)
        ids = checker.render(camera, "primitive-id", route)
        assert ids.dtype == np.uint32 and set(np.unique(ids[H // 2:])) == {0xFFFFFFFF}
        assert set(np.unique(ids[: H // 2])) <= {0, 1}
        normal = checker.render(camera, "normal", route)
        assert np.allclose(normal[: H // 2], [0, 0, 1], atol=1e-6) and np.all(np.isnan(normal[H // 2:]))
    assert checker.check(camera).consistent


def test_unproject_puts_points_on_the_plane():
    checker, camera = zcheck.Checker(quad_scene(D, upper_half_only=True)), quad_camera()
    z = checker.render(camera, "eye-z")
    points, pixels = zcheck.unproject(camera, z, "eye-z")
    covered = np.isfinite(z).sum()
    assert covered == W * H // 2
    assert points.shape == (covered, 3) and pixels.shape == (covered, 2)
    assert np.allclose(points[:, 2], -D, rtol=0, atol=1e-6)
    assert np.all(points[:, 1] > 0)  # the upper half of the picture is world y > 0
    cols, rows = pixels[:, 0], pixels[:, 1]
    assert rows.max() == H // 2 - 1 and rows.min() == 0 and cols.min() == 0 and cols.max() == W - 1
    # (col, row): the left half of the columns is world x < 0; points are in scan order
    assert np.all(points[cols < W // 2, 0] < 0) and np.all(points[cols >= W // 2, 0] > 0)
    assert np.all(np.diff(rows * W + cols) > 0)
    # higher rows in the picture (smaller row index) are higher in the world
    assert np.all(np.diff(points[cols == 0, 1]) < 0)
    # every point is on its pixel's ray: the world ray through the pixel centre
    for k in (0, len(points) // 3, len(points) - 1):
        ray = camera.pixel_ray(*pixels[k])["world"]
        v = points[k] - ray["origin"]
        assert np.linalg.norm(v - np.dot(v, ray["direction"]) * ray["direction"]) < 1e-6
    # stride and eye space
    eye_points, eye_pixels = zcheck.unproject(camera, z, "eye-z", space="eye", stride=4)
    assert np.all(eye_pixels % 4 == 0) and len(eye_points) == (W // 4) * (H // 8)
    # miss= marks extra misses; integer maps with scale
    z_mm = np.where(np.isfinite(z), np.round(z * 1000), 0).astype(np.uint16)
    mm_points, _ = zcheck.unproject(camera, z_mm, "eye-z", scale=1000)
    assert np.allclose(mm_points, points, atol=1e-9)
    assert len(zcheck.unproject(camera, np.where(np.isfinite(z), z, -1), "eye-z", miss=-1)[0]) == covered


def test_unproject_equals_the_cli_point_cloud(tmp_path, default_checker, small_camera, small_camera_file):
    """`zcheck export` + `zcheck unproject --ascii` vs read_depth_map + zcheck.unproject."""
    depth = tmp_path / "depth.pfm"
    cloud = tmp_path / "cloud.ply"
    run_cli("export", "--camera", small_camera_file, "--quantity", "distance", "-o", depth, check_rc=0)
    run_cli("unproject", "--camera", small_camera_file, "--depth-map", depth, "--quantity", "distance",
            "--ascii", "--stride", 2, "-o", cloud, check_rc=0)
    text = cloud.read_text().splitlines()
    body = text[text.index("end_header") + 1:]
    cli_points = np.array([[float(v) for v in line.split()] for line in body])
    values = zcheck.read_depth_map(str(depth), small_camera, quantity="distance")
    assert np.array_equal(values, default_checker.render(small_camera, "distance").astype(np.float64), equal_nan=True)
    points, _ = zcheck.unproject(small_camera, values, "distance", stride=2)
    assert points.shape == cli_points.shape and len(points) > 1000
    assert np.allclose(points, cli_points, rtol=1e-6, atol=1e-6)  # the PLY holds float32


def test_render_routes_agree_on_the_default_scene(default_checker, small_camera):
    ray = default_checker.render(small_camera, "eye-z", "ray")
    raster = default_checker.render(small_camera, "eye-z", "raster")
    both = np.isfinite(ray) & np.isfinite(raster)
    assert both.sum() > 0.5 * W * H
    assert np.median(np.abs(ray[both] - raster[both]) / ray[both]) < 1e-5
    world = default_checker.render(small_camera, "position-world")
    assert world.shape == (H, W, 3) and np.all(np.isnan(world[~np.isfinite(ray)]))


def test_release_cached_buffers_gives_the_kept_frames_back(default_scene, default_checker):
    # A 1024x768 check with its pixels keeps buffers of 2 MiB and more; once the report is
    # dropped they are kept for the next check of that size, until released.
    camera = default_scene.default_camera.replace(width=1024, height=768)
    zcheck.release_cached_buffers()
    assert zcheck.cached_buffer_bytes() == 0
    report = default_checker.check(camera)
    assert report.consistent
    del report
    kept = zcheck.cached_buffer_bytes()
    assert kept >= 2 << 20
    zcheck.release_cached_buffers()
    assert zcheck.cached_buffer_bytes() == 0
    # The next check of that size maps fresh buffers and gives the same answer.
    assert default_checker.check(camera).consistent


def test_zcheck_embree_isa_is_read_when_a_checker_is_made_and_a_bad_value_raises(monkeypatch):
    scene = zcheck.Scene.from_file("builtin:default")
    camera = scene.default_camera.replace(width=64, height=48)
    monkeypatch.delenv("ZCHECK_EMBREE_ISA", raising=False)
    by_default = zcheck.Checker(scene).render(camera, "window", route="ray")
    # SSE2 is every x86-64 processor's: Embree's SSE2 kernels find the same hits, so the same
    # depths (a ray through an edge two triangles share may report the other one: 1 in 1,000
    # pixels allowed, none seen on the development machine).
    monkeypatch.setenv("ZCHECK_EMBREE_ISA", "sse2")
    checker = zcheck.Checker(scene)
    assert checker.check(camera).consistent
    by_sse2 = checker.render(camera, "window", route="ray")
    same = (by_sse2 == by_default) | (np.isnan(by_sse2) & np.isnan(by_default))
    assert same.mean() >= 0.999, same.mean()
    for bad in ["SSE2", "avx-512", "isa=avx2"]:
        monkeypatch.setenv("ZCHECK_EMBREE_ISA", bad)
        with pytest.raises(zcheck.Error, match=f"ZCHECK_EMBREE_ISA={bad}: must be auto, sse2, sse4.2, avx, avx2 or avx512"):
            zcheck.Checker(scene)


def test_the_kernel_form_is_the_widest_supported_or_the_one_zcheck_kernels_names(monkeypatch):
    supported = zcheck.kernel_forms_supported()
    assert supported[0] == "baseline" and set(supported) <= {"baseline", "avx2", "avx512"}
    monkeypatch.delenv("ZCHECK_KERNELS", raising=False)
    assert zcheck.kernel_form() == supported[-1]
    scene = zcheck.Scene.from_file("builtin:default")
    checker = zcheck.Checker(scene)
    camera = scene.default_camera.replace(width=64, height=48)
    renders = {}
    for form in supported:
        monkeypatch.setenv("ZCHECK_KERNELS", form)
        assert zcheck.kernel_form() == form
        renders[form] = checker.render(camera, "window", route="raster").tobytes()
    assert len(set(renders.values())) == 1  # bit-identical in every form
    for bad in ["sse2", "AVX2", "avx1024"]:
        monkeypatch.setenv("ZCHECK_KERNELS", bad)
        with pytest.raises(zcheck.Error, match=f"ZCHECK_KERNELS={bad}: must be auto, baseline, avx2 or avx512"):
            zcheck.kernel_form()
        with pytest.raises(zcheck.Error, match=f"ZCHECK_KERNELS={bad}"):
            checker.render(camera, "window", route="raster")
    for form in {"avx2", "avx512"} - set(supported):
        monkeypatch.setenv("ZCHECK_KERNELS", form)
        with pytest.raises(zcheck.Error, match="this processor cannot run"):
            zcheck.kernel_form()
